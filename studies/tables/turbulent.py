"""The turbulent truths: the studies on both truths and the cross-truth table (recipes
turbulent*, cross-truth); the tuning rounds are studies/tables/tuning.py."""

from __future__ import annotations

import pandas as pd

from studies.tables.common import (
    TODAY_DEFAULTS,
    acquired,
    earlier_defaults,
    pick,
    rmse,
    share,
    small_sample,
    study,
    table,
    time_to_1m,
)
from studies.tables.paper import FULL_HEADER, full_row

TURBULENT_HEADER = [
    "truth",
    "configurations",
    "flown at",
    "planner (stored in docs/results/)",
    *FULL_HEADER[1:],
]


def turbulent_table() -> str:
    """Both turbulent truths, all eight unknown, the fluctuation likelihood: the public
    configurations (12 × 5, 10,000 particles) and the held-out ones, at each round's defaults
    (the truth, the configurations and the defaults in columns of their own)."""
    rows = []
    for name, how in (
        ("turbulent-public-defaults", "the third round's defaults"),
        # flown 2026-11-26 (the folder's name is of that day): a 2.5 m near-source fall, repeat
        # power 1/4, no learned member, dcee-cl one move ahead
        ("turbulent-public-today", "the fourth round's defaults (2026-11-26, one move ahead)"),
    ):
        frame = study(name)
        for truth in ("filament", "puffs"):
            for strategy in ("dcee-cl", "infotaxis"):
                r = pick(frame, strategy, truth_model=truth)
                where = [truth, "12 public × 5", how, f"`{strategy}` (`{name}`)"]
                rows.append(where + full_row("", r)[1:])
    frame = study("turbulent-held-out-100")
    settings = (
        (0.0, 5.0, 0.0, 0, 0, "a fixed 4 m altitude (before the climb)"),
        (1.0, 2.5, 1.0, 0, 0, "the third round's defaults"),
        (1.0, 2.5, 1.0, 1, 0, "the mean-conserving intermittency"),
        (1.0, 2.5, 1.0, 1, 2, "the defaults of 2026-11-23"),
    )
    for climb, near, reach, conserve, repeat, how in settings:
        for truth in ("puffs", "filament"):
            for strategy in ("dcee-cl", "infotaxis"):
                r = pick(
                    frame,
                    strategy,
                    truth_model=truth,
                    climb=climb,
                    near_source_length=near,
                    vertical_reach=reach,
                    conserve_mean=conserve,
                    repeat_radius=repeat,
                )
                n = int(r["searches"])
                where = [truth, f"{n} held-out", how, f"`{strategy}` (`turbulent-held-out-100`)"]
                rows.append(where + full_row("", r)[1:])
    return table(TURBULENT_HEADER, rows)


CROSS_HEADER = [
    "truth (held-out configurations)",
    "defaults chosen on it",
    "planner (stored in docs/results/)",
    "flown at the defaults of",
    "variant",
    "n",
    "source acquired (RMSE < 3 m)",
    "median final RMSE (m)",
    "truth in 95 % region",
    "median time to RMSE < 1 m (s)",
]


def cross_truth_table(latest_only: bool = False) -> str:
    """Every truth family, all eight unknown, at today's defaults, with the rows flown at the
    defaults before marked: which defaults were chosen on it (docs/plumes.md;
    dcee.scenarios.defaults.DEFAULTS). ``latest_only`` (docs/index.md's): per truth and planner
    only the latest defaults flown, and no options. Each row names the defaults it was flown
    at by date (a legend below the table says what each was) and what it varies, so that the
    first column is the truth alone."""
    today = study("held-out-today")
    turbulent_today = study("turbulent-held-out-100-today")
    lbm = study("lbm-held-out-100")
    rows = []
    dates: set[str] = set()

    def add(truth: str, chosen: str, r: pd.Series, source: str, flown: str, how: str) -> None:
        if flown != "today":
            dates.add(flown)
        rows.append(
            [
                truth,
                chosen,
                f"`{r['strategy']}` (`{source}`)",
                "today's" if flown == "today" else flown,
                how or "—",
                str(int(r["searches"])),
                acquired(r),
                rmse(r),
                share(r, "truth_in_95"),
                time_to_1m(r),
            ]
        )

    def flown(defaults: str, strategy: str) -> str:
        return "today" if defaults == TODAY_DEFAULTS.get(strategy) else defaults

    for strategy in ("dcee-cl", "infotaxis", "dcee-mcts"):
        add(
            "isotropic, paper's likelihood",
            "outlier weight, stall guard, stop rule",
            pick(today, strategy, study="full"),
            "held-out-today",
            "today",
            "",
        )
    for truth, chosen in (
        (
            "filament",
            "**yes**: the fluctuation model's settings, climb, hold, backflow and disc members",
        ),
        ("puffs", "**yes**: climb, near-source fall, repeat discount, backflow and disc members"),
    ):
        generations = sorted(set(turbulent_today["defaults"].astype(str)), reverse=True)
        latest: set[str] = set()  # planners already given a row (latest_only: one each)
        for defaults in generations:
            for strategy in ("dcee-cl", "infotaxis"):
                part = turbulent_today[turbulent_today["defaults"].astype(str) == defaults]
                if not ((part["strategy"] == strategy) & (part["truth_model"] == truth)).any():
                    continue
                if latest_only and strategy in latest:
                    continue
                latest.add(strategy)
                r = pick(part, strategy, truth_model=truth)
                add(
                    f"{truth}, fluctuation likelihood",
                    chosen,
                    r,
                    "turbulent-held-out-100-today",
                    flown(defaults, strategy),
                    small_sample(r).removeprefix(", "),
                )
        if truth == "filament" and not latest_only:
            add(
                "filament, fluctuation likelihood",
                chosen,
                pick(today, "dcee-mcts", study="filament"),
                "held-out-today",
                "2026-11-23",
                "",
            )
    # newest generation first (the tags sort by date, as latest_defaults reads them)
    lbm = lbm.assign(order=lbm["defaults"].astype(str)).sort_values(
        "order", ascending=False, kind="stable"
    )
    option = lbm["strategy"].astype(str).str.contains(":")  # a planner's option, e.g. horizon=2
    if latest_only:  # per planner, the latest defaults flown, no options
        lbm = lbm[(lbm["learn"] == "none") & ~option].drop_duplicates("strategy", keep="first")
    for _, r in lbm.iterrows():
        how = [] if r["learn"] == "none" else [f"`estimator.learn` {r['learn']} (an option)"]
        strategy, defaults = str(r["strategy"]), str(r["defaults"])
        if ":" in strategy:
            how.append("a planner option (chosen on the tuning range, measured here)")
        if strategy == "dcee-cl:horizon=2" and defaults == "2026-11-27c":
            how.append("`dcee-cl` at the defaults of 2026-11-29, flown before they were")
        if int(r.get("particles", 10000)) != 10000:
            how.append(f"{int(r['particles']):,} particles (measured, not chosen on)")
        if small_sample(r):
            how.append(small_sample(r).removeprefix(", "))
        add(
            "**lbm** (fluid solver), fluctuation likelihood",
            "none",
            r,
            "lbm-held-out-100",
            flown(defaults, strategy),
            "; ".join(how),
        )
    legend = [f"* **{tag}**: the {earlier_defaults(tag, 'dcee-cl')}" for tag in sorted(dates)[::-1]]
    today_words = "* **today's**: `dcee-cl` three moves ahead, the region's floor 0.25 m"
    return (
        table(CROSS_HEADER, rows)
        + "\nFlown at the defaults of:\n\n"
        + "\n".join([today_words, *legend])
        + "\n"
    )
