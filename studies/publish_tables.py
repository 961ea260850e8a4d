"""Write the result tables of the README and docs/ (index, results, held-out) from the stored
study results in docs/results/ (issue 31, item 5): numbers come from results, not typing.

Every generated table sits between two markers on its page::

    <!-- generated: NAME (studies/publish_tables.py) -->
    | … the table … |
    <!-- end generated -->

and this script rewrites what is between them from the study folders under docs/results/
(each a `dcee report` ``metrics.csv``, optionally a ``paired.csv``, and a README that says
where it came from). ``--check`` rewrites nothing and exits 1 naming every table that
disagrees with its results (tests/test_published_numbers.py runs it).

    python studies/publish_tables.py           # rewrite the tables
    python studies/publish_tables.py --check   # exit 1 if a page disagrees with its results
    bash studies/run.sh publish                # the same as the first
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pandas as pd

from dcee.scenarios import REGION_FLOOR_DEFAULT

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "docs" / "results"
PAGES = (
    "README.md",
    "docs/index.md",
    "docs/results.md",
    "docs/held-out.md",
    "docs/scenarios.md",
    "docs/plumes.md",
    "docs/performance.md",
    "docs/multi-source.md",
)
MARKER = re.compile(
    r"(<!-- generated: (?P<name>[a-z0-9-]+) \(studies/publish_tables\.py\) -->\n)"
    r"(?P<body>.*?)"
    r"(<!-- end generated -->)",
    re.S,
)


def study(name: str) -> pd.DataFrame:
    return pd.read_csv(RESULTS / name / "metrics.csv")


def paired(name: str) -> pd.DataFrame:
    return pd.read_csv(RESULTS / name / "paired.csv")


def matching(frame: pd.DataFrame, strategy: str, **where: object) -> pd.DataFrame:
    """The rows of ``strategy`` where every column equals its value (a dict value: the value
    for this strategy, e.g. :data:`TODAY_DEFAULTS`)."""
    rows = frame[frame["strategy"] == strategy]
    for key, value in where.items():
        if isinstance(value, dict):
            value = value[strategy]
        rows = rows[rows[key] == value]
    return rows


def pick(frame: pd.DataFrame, strategy: str, **where: object) -> pd.Series:
    """The one row of ``strategy`` where every column equals its value (a dict value: the value
    for this strategy, e.g. :data:`TODAY_DEFAULTS`)."""
    rows = matching(frame, strategy, **where)
    if len(rows) != 1:
        raise KeyError(f"{strategy} {where}: {len(rows)} rows")
    return rows.iloc[0]


# --- cell formats --------------------------------------------------------------------------


def count(r: pd.Series) -> str:
    """acquired k/n"""
    n = int(r["searches"])
    return f"{round(r['source_acquired_rate'] * n)}/{n}"


def share(r: pd.Series, key: str) -> str:
    """ "82 % [75, 88]" from a rate and its interval"""
    v, lo, hi = (r[f"{key}_rate"], r[f"{key}_lo"], r[f"{key}_hi"])
    if math.isnan(v):
        return "—"
    return f"{100 * v:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]"


def acquired(r: pd.Series) -> str:
    return f"{count(r)}, {share(r, 'source_acquired')}"


def interval(r: pd.Series, key: str, fmt: str) -> str:
    v, lo, hi = r[key], r.get(f"{key}_lo", math.nan), r.get(f"{key}_hi", math.nan)

    def one(x: float) -> str:
        return "> budget" if math.isinf(x) else format(x, fmt)

    if math.isnan(lo) or math.isnan(hi):
        return one(v)
    return f"{one(v)} [{one(lo)}, {one(hi)}]"


def rmse(r: pd.Series) -> str:
    return interval(r, "median_final_rmse", ".2f")


def time_to_1m(r: pd.Series) -> str:
    if math.isnan(r["reached_1m"]):
        return "—"  # not in the published table the results were transcribed from
    if r["reached_1m"] == 0:
        return "never"
    if math.isinf(r["time_to_1m"]):  # fewer than half got there: no median within the budget
        return f"> budget ({100 * r['reached_1m']:.0f} % got there)"
    v = interval(r, "time_to_1m", ".0f")
    if r["reached_1m"] < 1:
        v += f" ({100 * r['reached_1m']:.0f} % got there)"
    return v


def stall(r: pd.Series) -> str:
    longest, stalled = r.get("longest_stall", math.nan), r.get("stalled", math.nan)
    if math.isnan(stalled):
        return "—"
    if math.isnan(longest):
        return f"{int(stalled)} > 60 s"
    return f"{longest:.0f} ({int(stalled)} > 60 s)"


def table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


# --- the tables ----------------------------------------------------------------------------


HEADLINE_HEADER = [
    "result (held-out: configurations nothing was chosen on)",
    "`dcee-cl`: acquired, median final error",
    "`infotaxis`: acquired, median final error",
    "defaults tuned on this truth (other configurations)",
    "stored in docs/results/",
    "details",
]


def _headline_cell(r: pd.Series | None) -> str:
    """ "120/120, 0.21 m" (a missing row: "—")."""
    if r is None:
        return "—"
    return f"{count(r)}, {r['median_final_rmse']:.2f} m"


def headline_table(docs: str = "docs/") -> str:
    """The README's one table (docs/index.md too, ``docs`` "" for links from there): short
    labels, the study folder and the page that says what each row is, when it was flown and at
    which defaults. Per planner the latest defaults flown on that truth (the linked page says
    which)."""
    rows: list[list[str]] = []

    def add(label: str, cl, info, chosen: str, source: str, page: str) -> None:
        assert len(label) <= 60, label
        rows.append([label, _headline_cell(cl), _headline_cell(info), chosen, f"`{source}`", page])

    paper_source, paper_full = study("paper-source"), study("paper-full")
    results = f"[results]({docs}results.md)"
    for label, frame, name in (
        ("The paper's study: 12 configurations × 10, wind known", paper_source, "paper-source"),
        ("The paper's study, all eight parameters unknown", paper_full, "paper-full"),
    ):
        add(label, pick(frame, "dcee-cl"), pick(frame, "infotaxis"), "yes", name, results)
    today = study("held-out-today")
    held_out = f"[held-out]({docs}held-out.md)"
    for label, name in (
        ("200 held-out configurations, wind known", "wind-known"),
        ("200 held-out configurations, all eight unknown", "full"),
    ):
        add(
            label,
            pick(today, "dcee-cl", study=name),
            pick(today, "infotaxis", study=name),
            "yes",
            "held-out-today",
            held_out,
        )
    turbulent = study("turbulent-held-out-100-today")
    for label, truth in (
        ("100 held-out, turbulent filament plume (ours)", "filament"),
        ("100 held-out, turbulent puff plume (Farrell et al. 2002)", "puffs"),
    ):
        newest = latest_defaults(turbulent, ("dcee-cl", "infotaxis"), truth_model=truth)
        add(
            label,
            pick(turbulent, "dcee-cl", truth_model=truth, defaults=newest),
            pick(turbulent, "infotaxis", truth_model=truth, defaults=newest),
            "yes",
            "turbulent-held-out-100-today",
            f"[turbulent plumes]({docs}turbulent.md)",
        )
    lbm = study("lbm-held-out-100")
    lbm = lbm[(lbm["learn"] == "none") & ~lbm["strategy"].astype(str).str.contains(":")]
    newest = latest_defaults(lbm, ("dcee-cl", "infotaxis"))
    add(
        "100 held-out, a fluid solver's plume (lbmpy)",
        pick(lbm, "dcee-cl", defaults=newest),
        pick(lbm, "infotaxis", defaults=newest),
        "**no**",
        "lbm-held-out-100",
        f"[plumes nobody here wrote]({docs}plumes.md)",
    )
    searches = pd.read_csv(RESULTS / "source-count" / "searches.csv")
    two = searches[searches["campaign"] == "two-source-held-out-100-climb"]
    label = "100 held-out, two releases, their number unknown"
    assert len(label) <= 60
    rows.append(
        [
            label,
            f"count right {int(two['count_correct'].sum())}/{len(two)}, "
            f"median OSPA {two['final_ospa'].median():.2f} m",
            "—",
            "yes",
            "`source-count`",
            f"[several releases]({docs}multi-source.md)",
        ]
    )
    return table(HEADLINE_HEADER, rows)


FULL_HEADER = [
    "planner",
    "n",
    "source acquired (RMSE < 3 m)",
    "truth in 95 % region",
    "median final RMSE (m)",
    "median time to RMSE < 1 m (s)",
    "longest stall (s)",
]


def full_row(label: str, r: pd.Series) -> list[str]:
    return [
        label,
        str(int(r["searches"])),
        acquired(r),
        share(r, "truth_in_95"),
        rmse(r),
        time_to_1m(r),
        stall(r),
    ]


def public_table(name: str) -> Callable[[], str]:
    """The four planners of a public study (12 configurations × 10 seeds)."""

    def make() -> str:
        frame = study(name)
        rows = [
            full_row(f"`{strategy}` (`{name}`)", pick(frame, strategy))
            for strategy in ("dcee-cl", "infotaxis", "dcee", "mpc")
        ]
        return table(FULL_HEADER, rows)

    return make


HELD_OUT = (
    ("wind-known", "wind known, 200"),
    ("full", "all eight unknown, 200"),
    (
        "filament",
        "filament truth, all eight unknown, fluctuation likelihood, `held-out-100`, defaults of "
        "2026-11-23",
    ),
)
PLANNERS = ("dcee-cl", "infotaxis", "dcee-mcts")


def held_out_table() -> str:
    """Today's defaults on the three held-out studies (every planner on the same searches)."""
    rows = []
    frame = study("held-out-today")
    for name, what in HELD_OUT:
        for strategy in PLANNERS:
            r = pick(frame, strategy, study=name)
            rows.append(full_row(f"{what}: `{strategy}` (`held-out-today`)", r))
    return table(FULL_HEADER, rows)


def paired_table() -> str:
    """`dcee-cl` against infotaxis, and both against the tree search, search by search."""
    frame = paired("held-out-today")
    rows = []
    for name, _ in HELD_OUT:
        for variant, reference in (
            ("dcee-cl", "infotaxis"),
            ("dcee-cl", "dcee-mcts"),
            ("infotaxis", "dcee-mcts"),
        ):
            p = pick(frame, variant, study=name, reference=reference)
            diff, dr = p["time_to_1m_difference"], p["final_rmse_difference"]
            rows.append(
                [
                    f"{name}: `{variant}` − `{reference}`",
                    str(int(p["pairs"])),
                    f"{int(p['acquired_variant_only'])} / {int(p['acquired_reference_only'])}",
                    f"{p['mcnemar_p']:.2g}",
                    "—" if math.isnan(diff) else f"{diff:+.0f} s (p = {p['time_wilcoxon_p']:.2g})",
                    "—" if math.isnan(dr) else f"{dr:+.2f} m (p = {p['rmse_wilcoxon_p']:.2g})",
                ]
            )
    return table(
        [
            "study: first − second planner",
            "pairs",
            "acquired only by the first / only by the second",
            "McNemar p",
            "median paired difference in time to RMSE < 1 m, Wilcoxon p",
            "median paired difference in final RMSE, Wilcoxon p",
        ],
        rows,
    )


def others_table() -> str:
    """The rest of the DCEE family on the held-out wind-known study, paired with infotaxis."""
    frame, pairs = study("held-out-today"), paired("held-out-today")
    rows = []
    for strategy in ("dcee", "mpc", "dcee-ms"):
        r = pick(frame, strategy, study="wind-known")
        p = pick(pairs, strategy, study="wind-known", reference="infotaxis")
        rows.append(
            [
                f"`{strategy}`",
                str(int(r["searches"])),
                acquired(r),
                rmse(r),
                f"{int(p['acquired_variant_only'])} / {int(p['acquired_reference_only'])} "
                f"(p = {p['mcnemar_p']:.2g})",
                time_to_1m(r),
                stall(r),
            ]
        )
    return table(
        [
            "planner",
            "n",
            "source acquired (RMSE < 3 m)",
            "median final RMSE (m)",
            "acquired only by it / only by infotaxis (McNemar p)",
            "median time to RMSE < 1 m (s)",
            "longest stall (s)",
        ],
        rows,
    )


def turbulent_table() -> str:
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
                label = f"{truth}, 12 public × 5, {how}, 10,000 particles: `{strategy}` (`{name}`)"
                rows.append(full_row(label, r))
    frame = study("turbulent-held-out-100")
    settings = (
        (0.0, 5.0, 0.0, 0, 0, "fixed 4 m altitude (before)"),
        (1.0, 2.5, 1.0, 0, 0, "the third round's defaults"),
        (1.0, 2.5, 1.0, 1, 0, "mean-conserving intermittency"),
        (1.0, 2.5, 1.0, 1, 2, "**today's defaults**"),
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
                label = f"{truth}, {n} held-out, {how}: `{strategy}` (`turbulent-held-out-100`)"
                rows.append(full_row(label, r))
    return table(FULL_HEADER, rows)


def team_table() -> str:
    frame = study("team")
    rows = []
    for strategy in ("infotaxis", "dcee-cl"):
        for k in (1, 2, 3):
            r = pick(frame, strategy, robots=k)
            d = r["rmse_difference_to_one_robot"]
            rows.append(
                [
                    f"`{strategy}`",
                    str(k),
                    count(r),
                    rmse(r),
                    interval(r, "time_to_1m", ".0f"),
                    interval(r, "time_to_0_5m", ".0f"),
                    "—" if math.isnan(d) else f"{d:+.3f} m, p = {r['wilcoxon_p']:.2g}",
                ]
            )
    return table(
        [
            "planner",
            "robots",
            "source acquired",
            "median final RMSE (m)",
            "median time to RMSE < 1 m (s)",
            "to < 0.5 m (s)",
            "final RMSE vs 1 robot: median paired difference, Wilcoxon p",
        ],
        rows,
    )


def lab_table() -> str:
    frame = study("lab")
    settings = {
        "robot-isotropic": "unicycle robot, isotropic truth",
        "grid-isotropic": "grid agent (the paper's idealisation), same seeds",
        "robot-filament-room": "unicycle robot, turbulent filament truth, fluctuation "
        "likelihood fitted at the room's scale",
        "robot-filament-50m": "the same with the fluctuation parameters of the 50 m plume",
    }
    rows = []
    for strategy in sorted(frame["strategy"].unique()):
        cells = [f"`{strategy}`"]
        for setting in settings:
            r = pick(frame, strategy, setting=setting)
            t = r["time_to_0_5m"]
            when = "> 450 s" if math.isinf(t) else f"{t:.0f} s"
            cells.append(
                f"{count(r)}, {r['median_final_rmse']:.2f} m, {when}, {int(r['readings'])}"
            )
        rows.append(cells)
    return table(["planner", *settings.values()], rows)


def stop_rule_table() -> str:
    frame = pd.read_csv(RESULTS / "stop-rule" / "stop_rule.csv")
    rows = []
    labels = {
        "stop-held-out-wind-known": "isotropic, wind known",
        "stop-held-out-full": "isotropic, all eight unknown",
        "stop-held-out-filament": "filament, all eight unknown, fluctuation likelihood",
    }
    for _, r in frame.iterrows():
        rows.append(
            [
                labels.get(r["folder"], r["folder"]),
                str(int(r["searches"])),
                f"{100 * r['stopped']:.0f} % [{100 * r['stopped_lo']:.0f}, "
                f"{100 * r['stopped_hi']:.0f}]",
                f"{r['stop_time']:.0f} [{r['stop_time_lo']:.0f}, {r['stop_time_hi']:.0f}]",
                f"{r['saved_mean']:.0f}",
                f"{r['rmse_at_stop']:.2f} (whole budget: {r['rmse_full']:.2f})",
                f"{round(r['acquired'] * r['searches']):.0f}/{int(r['searches'])} "
                f"(whole budget: {int(r['acquired_full'])})",
                f"{int(r['early'])}/{int(r['early_of'])}",
            ]
        )
    return table(
        [
            "held-out study (`dcee-cl`, reporting range)",
            "searches",
            "stopped before the budget",
            "median stop time (s)",
            "mean time saved (s)",
            "median RMSE at the stop (m)",
            "acquired at the stop",
            "stopped with RMSE ≥ 1 m / stopped",
        ],
        rows,
    )


def sites_table() -> str:
    frame = pd.read_csv(RESULTS / "sites" / "sites.csv")
    rows = []
    for _, r in frame.iterrows():
        rows.append(
            [
                f"`{r['scenario']}`",
                f"`{r['strategy']}`",
                str(r["motion"]),
                acquired(r),
                rmse(r),
                f"{r['straight']:.0f} / {r['round']:.0f}",
                "never"
                if r["reached_near"] == 0
                else f"{r['to_near']:.0f} ({100 * r['reached_near']:.0f} % got there)",
                f"{int(r['positions_inside'])} / {int(r['drives_into_obstacles'])}",
                f"{r['longest_stall']:.0f}",
            ]
        )
    return table(
        [
            "site",
            "planner",
            "motion",
            "source acquired",
            "median final RMSE (m)",
            "start → source: straight / round the obstacles (m)",
            "median way flown until within 8 m of it (m)",
            "positions / drives inside an obstacle",
            "longest stall (s)",
        ],
        rows,
    )


def sites_walls_table(name: str, all_only: bool = False) -> Callable[[], str]:
    """Issue 44's tables (studies/sites_walls_table.py): per site and estimator, then the
    estimators paired search by search."""

    def make() -> str:
        frame = pd.read_csv(RESULTS / name / "summary.csv")
        if all_only:  # one search per configuration: only the pooled rows say anything
            frame = frame[frame["scenario"] == "all sites"]
        rows = []
        for _, r in frame.iterrows():
            n = int(r["searches"])
            lo, hi = 100 * r["acquired_lo"], 100 * r["acquired_hi"]
            t1 = r["median_time_to_1m"]
            rows.append(
                [
                    f"`{r['scenario']}`" if ":" in r["scenario"] else r["scenario"],
                    f"`{r['strategy']}`, {r['estimator']}",
                    f"{int(r['acquired'])}/{n}, "
                    f"{100 * r['acquired_rate']:.0f} % [{lo:.0f}, {hi:.0f}]",
                    interval(r, "median_final_rmse", ".2f"),
                    "never"
                    if math.isnan(t1)
                    else f"{t1:.0f} ({100 * r['reached_1m']:.0f} % got there)",
                    f"{100 * r['truth_in_95']:.0f} %",
                    f"{r['longest_wander']:.0f} ({int(r['wandered'])} > 120 s)",
                    f"{r['decision_ms']:.0f}",
                ]
            )
        head = table(
            [
                "site",
                "planner, estimator",
                "source acquired",
                "median final RMSE (m)",
                "median time to RMSE < 1 m (s)",
                "truth in 95 % region",
                "longest wander (s)",
                "decision (ms, 2 workers)",
            ],
            rows,
        )
        pairs = pd.read_csv(RESULTS / name / "paired.csv")
        prow = [
            [
                f"`{r['scenario']}`" if ":" in r["scenario"] else r["scenario"],
                f"`{r.get('strategy', 'dcee-cl')}`: {r['a']} − {r['b']}",
                str(int(r["pairs"])),
                f"{int(r['acquired_a_only'])} / {int(r['acquired_b_only'])}",
                f"{r['mcnemar_p']:.2g}",
                f"{r['median_rmse_difference']:+.2f}",
                f"{r['wilcoxon_p']:.2g}",
            ]
            for _, r in pairs.iterrows()
            if r["pairs"] >= 5 and not (all_only and r["scenario"] != "all sites")
        ]
        return (
            head
            + "\n"
            + table(
                [
                    "site",
                    "paired",
                    "searches",
                    "acquired by the first only / the second only",
                    "McNemar p",
                    "median final RMSE difference (m)",
                    "Wilcoxon p",
                ],
                prow,
            )
        )

    return make


def moves_ahead(n: int) -> str:
    """'one move ahead', 'two moves ahead', ..."""
    return f"{('one', 'two', 'three')[n - 1]} move{'s' if n > 1 else ''} ahead"


def sites_walls_timing_table() -> str:
    """Issue 44: decision and update time on a site against open terrain, one pinned core, idle
    (studies/site_timing.py)."""
    frame = pd.read_csv(RESULTS / "sites-walls" / "timing.csv")
    rows = [
        [
            f"`{r['site']}`",
            f"{r['way']}, {moves_ahead(int(r['lookahead']))}",
            f"{r['decision_ms_mean']:.1f}",
            f"{r['decision_ratio']:.2f}×",
            f"{r['update_ms_mean']:.1f}",
            f"{r['update_ratio']:.2f}×",
            f"{r['load_before']:.2f}",
        ]
        for _, r in frame.iterrows()
    ]
    return table(
        [
            "site",
            "search",
            "mean decision (ms)",
            "× open terrain",
            "mean update per reading (ms)",
            "× open terrain",
            "load before",
        ],
        rows,
    )


def anemometer_table() -> str:
    frame = pd.read_csv(RESULTS / "anemometer" / "anemometer.csv")
    pairs = pd.read_csv(RESULTS / "anemometer" / "paired.csv").set_index("prior")
    rows = []
    for _, r in frame.iterrows():
        rows.append([str(r["prior"]), str(r["arm"]), acquired(r), rmse(r), time_to_1m(r)])
    out = table(
        [
            "wind-direction prior",
            "`dcee-cl`, all eight unknown",
            "source acquired",
            "median final RMSE (m)",
            "median time to RMSE < 1 m (s)",
        ],
        rows,
    )
    for prior, p in pairs.iterrows():
        out += (
            f"\n{prior}, paired over {int(p['pairs'])} searches (with − without): time to 1 m "
            f"{p['time_to_1m_difference']:+.0f} s median (Wilcoxon p = "
            f"{p['time_wilcoxon_p']:.2g}; sooner in {int(p['sooner'])}, later in "
            f"{int(p['later'])}); final RMSE {p['final_rmse_difference']:+.3f} m (p = "
            f"{p['rmse_wilcoxon_p']:.2g}).\n"
        )
    return out


def lbm_statistics_table() -> str:
    """The solver plume's statistics downwind (studies/lbm_statistics.py's stored table)."""
    frame = pd.read_csv(RESULTS / "lbm-plume" / "statistics.csv")
    rows = [
        [
            f"{r['x']:.0f}",
            f"{r['sigma_y']:.2f}",
            f"{r['briggs_D']:.1f} … {r['briggs_A']:.1f}",
            f"{r['flux']:.2f}",
            f"{r['intensity']:.2f}",
            f"{r['intermittency']:.2f}",
        ]
        for _, r in frame.iterrows()
    ]
    header = [
        "x downwind (m)",
        "σ_y of the mean (m)",
        "Briggs D … A (m)",
        "flux ∫C̄ dy · U",
        "centreline σc/C̄",
        "intermittency (c > C̄/10)",
    ]
    return table(header, rows)


CROSS_HEADER = [
    "truth (held-out configurations)",
    "defaults chosen on it",
    "planner",
    "n",
    "source acquired (RMSE < 3 m)",
    "median final RMSE (m)",
    "truth in 95 % region",
    "median time to RMSE < 1 m (s)",
]


TODAY_DEFAULTS = {"dcee-cl": "2026-12-02", "infotaxis": "2026-12-02", "dcee-mcts": "2026-12-02"}
"""Per planner, the ``defaults`` tag of rows flown at today's defaults (a 0.5 m near-source
fall, repeat power 1/2, the backflow member and the disc member at prior odds 9 : 1 learned, the
95 % region the members' mixture's; ``dcee-cl`` looks three moves ahead in a turbulent plume
since 2026-11-29 (b) (two on 2026-11-29), ``search.lookahead``, which changed no other planner;
the region widened by the model-discrepancy floor, ``estimator.region_floor`` = 0.25 m, since
2026-12-02, for every planner: rows flown before it report the particles' own region)."""
EARLIER_DEFAULTS = {
    "2026-11-29b": "defaults of 2026-11-29 (b) (`dcee-cl` three moves ahead), the particles' "
    "own 95 % region",
    "2026-11-29": "defaults of 2026-11-29 (`dcee-cl` two moves ahead), the particles' own 95 % "
    "region",
    "2026-11-27c": "defaults of 2026-11-27 (c) (`dcee-cl` one move ahead), the particles' own "
    "95 % region",
    "2026-11-27b": "defaults of 2026-11-27 (b): the backflow member alone, the selected "
    "member's region",
    "2026-11-27": "defaults of 2026-11-27 before the backflow member",
    "2026-11-23": "defaults of 2026-11-23 (2.5 m fall, repeat power 1/4, no backflow member)",
}
"""How a row flown before today's defaults says so, by its ``defaults`` tag."""
OLD_DEFAULTS = EARLIER_DEFAULTS["2026-11-23"]


def earlier_defaults(tag: str, strategy: str) -> str:
    """How a row of ``strategy`` flown at the earlier defaults ``tag`` says so: the words of
    :data:`EARLIER_DEFAULTS`, without the parenthesis on how far ``dcee-cl`` looked ahead on a
    row of another planner (``search.lookahead`` changed no other planner)."""
    words = EARLIER_DEFAULTS[tag]
    if strategy != "dcee-cl":
        words = re.sub(r" \(`dcee-cl` \w+ moves? ahead\)", "", words)
    return words


def small_sample(r: pd.Series) -> str:
    """ ", N configurations (small sample)" for a row of fewer than the 100 held-out ones."""
    n = int(r["searches"])
    return f", {n} configurations (small sample)" if n < 100 else ""


def latest_defaults(frame: pd.DataFrame, strategies: tuple[str, ...], **where: object) -> dict:
    """Per planner, the newest ``defaults`` tag among its rows where every column equals its
    value (the tags sort by date)."""
    return {s: max(matching(frame, s, **where)["defaults"].astype(str)) for s in strategies}


def defaults_words(tags: dict) -> str:
    """ "today's defaults" when every planner's newest rows are today's, else which of them."""
    if all(tag == TODAY_DEFAULTS.get(s) for s, tag in tags.items()):
        return "today's defaults (`dcee-cl` three moves ahead, the region's floor 0.25 m)"
    parts = [
        f"`{s}` at "
        + ("today's" if tag == TODAY_DEFAULTS.get(s) else f"the {earlier_defaults(tag, s)}")
        for s, tag in tags.items()
    ]
    return ", ".join(parts)


def cross_truth_table(latest_only: bool = False) -> str:
    """Every truth family, all eight unknown, at today's defaults, with the rows flown at the
    defaults before marked: which defaults were chosen on it (docs/plumes.md;
    dcee.scenarios.defaults.DEFAULTS). ``latest_only`` (the README's): per truth and planner
    only the latest defaults flown, and no options."""
    today = study("held-out-today")
    turbulent_today = study("turbulent-held-out-100-today")
    lbm = study("lbm-held-out-100")
    rows = []

    def add(truth: str, chosen: str, r: pd.Series, source: str) -> None:
        rows.append(
            [
                truth,
                chosen,
                f"`{r['strategy']}` (`{source}`)",
                str(int(r["searches"])),
                acquired(r),
                rmse(r),
                share(r, "truth_in_95"),
                time_to_1m(r),
            ]
        )

    def flown(defaults: str, strategy: str) -> str:
        if defaults == TODAY_DEFAULTS.get(strategy):
            return ""
        if strategy == "dcee-cl:horizon=2" and defaults == "2026-11-27c":
            return (
                ", the same planner as `dcee-cl` at the defaults of 2026-11-29, flown before "
                "they were the defaults"
            )
        return f", {earlier_defaults(defaults, strategy)}"

    for strategy in ("dcee-cl", "infotaxis", "dcee-mcts"):
        add(
            "isotropic, paper's likelihood",
            "outlier weight, stall guard, stop rule",
            pick(today, strategy, study="full"),
            "held-out-today",
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
                small = small_sample(r)
                add(
                    f"{truth}, fluctuation likelihood{flown(defaults, strategy)}{small}",
                    chosen,
                    r,
                    "turbulent-held-out-100-today",
                )
        if truth == "filament" and not latest_only:
            add(
                f"filament, fluctuation likelihood, {OLD_DEFAULTS}",
                chosen,
                pick(today, "dcee-mcts", study="filament"),
                "held-out-today",
            )
    # newest generation first (the tags sort by date, as latest_defaults reads them)
    lbm = lbm.assign(order=lbm["defaults"].astype(str)).sort_values(
        "order", ascending=False, kind="stable"
    )
    option = lbm["strategy"].astype(str).str.contains(":")  # a planner's option, e.g. horizon=2
    if latest_only:  # per planner, the latest defaults flown, no options
        lbm = lbm[(lbm["learn"] == "none") & ~option].drop_duplicates("strategy", keep="first")
    for _, r in lbm.iterrows():
        how = "" if r["learn"] == "none" else f", `estimator.learn` {r['learn']} (an option)"
        if ":" in str(r["strategy"]):
            how += ", a planner option (chosen on the tuning range, measured here)"
        if int(r.get("particles", 10000)) != 10000:
            how += f", {int(r['particles']):,} particles (measured, not chosen on)"
        how += flown(str(r["defaults"]), str(r["strategy"])) + small_sample(r)
        add(f"**lbm** (fluid solver), fluctuation likelihood{how}", "none", r, "lbm-held-out-100")
    return table(CROSS_HEADER, rows)


def learn_tuning_table() -> str:
    """Reading-model candidates against the defaults before 2026-11-27 (a 2.5 m near-source
    fall, repeat power 1/4) on the tuning range (filament and puffs only: the truths defaults may
    be chosen on), paired by search (studies/precision_variants.py's rows in
    docs/results/tuning-*-13-40; the old defaults ran in the first two, reading for reading the
    same). The last candidate was the default until the backflow member joined it."""
    frame = pd.concat(
        pd.read_csv(RESULTS / folder / "variants.csv")
        for folder in (
            "tuning-learn-13-40",
            "tuning-log-sd-13-40",
            "tuning-near-sd-13-40",
            "tuning-nsl05-13-40",
            "tuning-nsl05-rp05-13-40",
        )
    )
    names = {
        "base": "defaults before 2026-11-27 (2.5 m fall, repeat power 1/4)",
        "decay": "`learn = {decay = [1, 0.5]}`",
        "both": "`learn = {meander = [0.15, 0.3, 0.6], log_sd = [1.3, 2]}`",
        "nsl": "`learn = {near_source_length = [2.5, 0]}`",
        "sd": "`learn = {log_sd = [1.3, 2, 3]}`",
        "nearsd": "`learn = {log_sd_near = [0, 3, 6]}`, `log_sd_length = 1.5`",
        "nsl05": "`near_source_length = 0.5` (fixed, not learned)",
        "nsl05rp05": "the defaults of 2026-11-27 (before the backflow member): "
        "`near_source_length = 0.5`, `repeat_power = 0.5`",
    }
    order = ("base", "decay", "both", "nsl", "sd", "nearsd", "nsl05", "nsl05rp05")
    return _variant_table(frame, names, order, "the defaults before 2026-11-27")


def backflow_tuning_table() -> str:
    """Gas upwind of the release, learned, against today's defaults on the tuning range, both
    flown in one run (docs/results/tuning-backflow-13-40; the rule in its README)."""
    frame = pd.read_csv(RESULTS / "tuning-backflow-13-40" / "variants.csv")
    names = {
        "base": "defaults of 2026-11-27 before the backflow member",
        "backflow": "**today's defaults**: `learn = {backflow = [0, 0.05]}`",
    }
    return _variant_table(frame, names, ("base", "backflow"), "the defaults before it")


def lbm_near_source_table() -> str:
    """The lbm truth near its release as the playback samples it (studies/lbm_near_source.py,
    docs/results/lbm-plume/near_source.csv)."""
    frame = pd.read_csv(RESULTS / "lbm-plume" / "near_source.csv")
    rows = [
        [
            f"{r['along_m']:+.2f}",
            f"{r['mean_over_peak']:.3f}",
            f"{100 * r['above_0.001_peak']:.0f} %",
            f"{100 * r['above_0.01_peak']:.0f} %",
        ]
        for _, r in frame.iterrows()
    ]
    header = [
        "along the mean wind from the release centre (m; < 0 upwind)",
        "time mean / peak",
        "frames above 0.1 % of the peak",
        "frames above 1 % of the peak",
    ]
    return table(header, rows)


def lbm_endgame_table() -> str:
    """Where each planner reads last and ends on the lbm plume (studies/lbm_endgame.py,
    docs/results/lbm-plume/endgame.csv; a lab note on eight tuning configurations)."""
    frame = pd.read_csv(RESULTS / "lbm-plume" / "endgame.csv")
    rows = []
    for strategy, g in frame.groupby("strategy", sort=False):
        m = g.median(numeric_only=True)
        rows.append(
            [
                f"`{strategy}`",
                str(len(g)),
                f"{m['late_along_median_m']:+.2f}",
                f"{100 * m['late_detections_upwind_share']:.0f} %",
                f"{m['final_along_m']:+.2f}",
                f"{m['final_spread_m']:.2f}",
                f"{m['final_rmse_m']:.2f}",
                f"{int(g['truth_in_95'].sum())}/{len(g)}",
            ]
        )
    header = [
        "planner",
        "searches",
        "last 300 s: median reading along the wind (m; < 0 upwind)",
        "last 300 s: detections upwind",
        "final mean along the wind (m)",
        "final spread √tr P (m)",
        "final RMSE (m)",
        "truth in 95 %",
    ]
    return table(header, rows)


def source_radius_tuning_table() -> str:
    """A release spread over a disc, learned, against the defaults it was measured against (the
    backflow rows of docs/results/tuning-backflow-13-40: the same searches), on the tuning
    range (docs/results/tuning-source-radius-13-40; the rule in its README)."""
    before = pd.read_csv(RESULTS / "tuning-backflow-13-40" / "variants.csv")
    before = before[before["variant"] == "backflow"].assign(variant="base")
    frame = pd.concat(
        [before, pd.read_csv(RESULTS / "tuning-source-radius-13-40" / "variants.csv")]
    )
    names = {
        "base": "`learn = {backflow = [0, 0.05]}` (the defaults it was measured against)",
        "radius": "`learn = {backflow = [0, 0.05], source_radius = [0, 1]}`",
    }
    return _variant_table(frame, names, ("base", "radius"), "the defaults it was measured against")


def radius_prior_table(release: str) -> str:
    """Disc members on the tuning range, each search paired with today's defaults on the same
    configuration: on the point releases (``release="point"``; today's defaults: the backflow
    rows of docs/results/tuning-backflow-13-40) or on the releases over an area (``"area"``,
    ``puff_radius`` 0.5 m; today's defaults: the ``area`` rows of
    docs/results/tuning-area-release-13-40). The rule: docs/results/tuning-radius-prior-13-40."""
    if release == "point":
        base = pd.read_csv(RESULTS / "tuning-backflow-13-40" / "variants.csv")
        base = base[base["variant"] == "backflow"]
        radius = pd.read_csv(RESULTS / "tuning-source-radius-13-40" / "variants.csv")
        prior, label = "prior", "point releases"
    else:
        area = pd.read_csv(RESULTS / "tuning-area-release-13-40" / "variants.csv")
        base = area[area["variant"] == "area"]
        radius = area[area["variant"] == "area-radius"].assign(variant="radius")
        prior, label = "area-prior", "releases over an area (`puff_radius = 0.5`)"
    candidate = pd.read_csv(RESULTS / "tuning-radius-prior-13-40" / "variants.csv")
    candidate = candidate[candidate["variant"] == prior].assign(variant="prior")
    frame = pd.concat([base.assign(variant="base"), radius, candidate])
    names = {
        "base": f"the defaults of 2026-11-27 (b), {label}",
        "radius": "`learn = {backflow = [0, 0.05], source_radius = [0, 1]}` (equal priors)",
        "prior": "the same with `learn_prior = {source_radius = [0.9, 0.1]}`",
    }
    return _variant_table(
        frame, names, ("base", "radius", "prior"), "the defaults of 2026-11-27 (b)"
    )


def horizon_tuning_table() -> str:
    """``dcee-cl:horizon=2`` on the tuning range, each search paired with ``dcee-cl`` one move
    ahead at the defaults of 2026-11-27 (c) (the ``prior`` rows of
    docs/results/tuning-radius-prior-13-40, their 95 % region the mixture's, as
    docs/results/mixture-region-prior-13-40 recomputed it). The rule, by which two moves became
    the default of 2026-11-29 (``search.lookahead``): docs/results/tuning-horizon-13-40."""
    key = ["truth", "scenario", "seed"]
    base = pd.read_csv(RESULTS / "tuning-radius-prior-13-40" / "variants.csv")
    base = base[base["variant"] == "prior"].drop(columns="truth_in_95")
    region = pd.read_csv(RESULTS / "mixture-region-prior-13-40" / "searches.csv")
    region = region[region["variant"] == "prior"][[*key, "mixture_in_95"]]
    base = base.merge(region, on=key).rename(columns={"mixture_in_95": "truth_in_95"})
    candidate = pd.read_csv(RESULTS / "tuning-horizon-13-40" / "variants.csv")
    frame = pd.concat([base.assign(variant="base"), candidate.assign(variant="horizon2")])
    names = {
        "base": "`dcee-cl` one move ahead (the defaults of 2026-11-27 (c))",
        "horizon2": "`dcee-cl:horizon=2` (two moves ahead: the default of 2026-11-29)",
    }
    return _variant_table(frame, names, ("base", "horizon2"), "`dcee-cl` one move ahead", "planner")


def lookahead3_tuning_table() -> str:
    """``search.lookahead = 3`` on the tuning range, each search paired with ``dcee-cl`` two moves
    ahead (the default of 2026-11-29: the ``horizon2`` rows of docs/results/tuning-horizon-13-40,
    the same planner decision for decision). The rule, by which three moves became the default:
    docs/results/tuning-lookahead3-13-40."""
    base = pd.read_csv(RESULTS / "tuning-horizon-13-40" / "variants.csv")
    candidate = pd.read_csv(RESULTS / "tuning-lookahead3-13-40" / "variants.csv")
    frame = pd.concat([base.assign(variant="base"), candidate.assign(variant="lookahead3")])
    names = {
        "base": "`dcee-cl` two moves ahead (the default of 2026-11-29)",
        "lookahead3": "`search.lookahead = 3` (three moves ahead: today's default)",
    }
    return _variant_table(
        frame, names, ("base", "lookahead3"), "`dcee-cl` two moves ahead", "planner"
    )


def region_floor_table(path: str, chosen: float | None = None) -> str:
    """The share of searches with the truth in the 95 % region at each model-discrepancy floor
    (studies/region_floor.py's table at ``path`` under docs/results), one column per truth, and
    the floored region's median RMS radius; the ``chosen`` floor in bold."""
    frame = pd.read_csv(RESULTS / path)
    truths = list(dict.fromkeys(frame["truth"]))
    rows = []
    for f, part in frame.groupby("floor", sort=True):
        cells = []
        for t in truths:
            r = part[part["truth"] == t].iloc[0]
            cells.append(
                f"{int(r['inside'])}/{int(r['n'])}, {100 * r['share']:.0f} % "
                f"[{100 * r['lo']:.0f}, {100 * r['hi']:.0f}]"
            )
        radius = part[part["truth"] == truths[-1]].iloc[0]["median_radius"]
        label = f"{f:.2f}"
        if chosen is not None and abs(f - chosen) < 1e-9:
            label = f"**{label}** (the default)"
        rows.append([label, *cells, f"{radius:.2f}"])
    names = {"all": "both truths"}
    header = [
        "floor σ (m)",
        *[f"{names.get(t, t)}: truth in 95 % region" for t in truths],
        f"median RMS radius of the region, {names.get(truths[-1], truths[-1])} (m)",
    ]
    return table(header, rows)


def _by_truth(rows: pd.DataFrame) -> Iterator[tuple[str, pd.DataFrame]]:
    """(truth, rows) for the filament, the puffs and both together (the last only when both
    are there: one truth's own row says it all); truths without rows are skipped."""
    for truth in ("filament", "puffs", "both truths"):
        part = rows if truth == "both truths" else rows[rows["truth"] == truth]
        if truth == "both truths" and rows["truth"].nunique() < 2:
            continue
        if not part.empty:
            yield truth, part


def _gained_lost(new: pd.Series, old: pd.Series) -> tuple[int, int, float]:
    """Paired yes/no outcomes (bool Series, aligned): (new only, old only, exact binomial
    p of the discordant pairs, McNemar's exact test; 1 when there are none)."""
    from scipy.stats import binomtest

    gained, lost = int((new & ~old).sum()), int((old & ~new).sum())
    return gained, lost, binomtest(gained, gained + lost).pvalue if gained + lost else 1.0


def mixture_region_table() -> str:
    """The truth in the selected member's 95 % region and in the reading models' mixture's, on
    the same searches (docs/results/mixture-region-13-40, studies/mixture_region.py)."""

    frame = pd.read_csv(RESULTS / "mixture-region-13-40" / "searches.csv")
    releases = {"radius": "point", "area-radius": "area (`puff_radius = 0.5`)"}
    rows = []
    for variant, release in releases.items():
        for truth, part in _by_truth(frame[frame["variant"] == variant]):
            sel, mix = part["truth_in_95"].astype(bool), part["mixture_in_95"].astype(bool)
            gained, lost, p = _gained_lost(mix, sel)
            rows.append(
                [
                    release,
                    truth,
                    str(len(part)),
                    f"{100 * sel.mean():.0f} %",
                    f"{100 * mix.mean():.0f} %",
                    f"+{gained} / −{lost} (p = {p:.2g})",
                ]
            )
    header = [
        "releases",
        "truth",
        "n",
        "truth in the selected member's 95 % region",
        "in the mixture's",
        "mixture against selected, gained / lost (exact binomial)",
    ]
    return table(header, rows)


def mixture_prior_table() -> str:
    """The default since 2026-11-27 (c), disc members at prior odds 9 : 1 with the mixture's
    region, against the defaults before it on the same configurations, point and area releases
    (docs/results/mixture-region-prior-13-40; the rule in its README)."""
    from scipy.stats import wilcoxon

    frame = pd.read_csv(RESULTS / "mixture-region-prior-13-40" / "searches.csv")
    before = pd.read_csv(RESULTS / "tuning-backflow-13-40" / "variants.csv")
    area = pd.read_csv(RESULTS / "tuning-area-release-13-40" / "variants.csv")
    bases = {
        "prior": ("point", before[before["variant"] == "backflow"]),
        "area-prior": ("area (`puff_radius = 0.5`)", area[area["variant"] == "area"]),
    }
    rows = []
    for variant, (release, base) in bases.items():
        both = frame[frame["variant"] == variant].merge(
            base, on=["truth", "scenario", "seed"], suffixes=("", "_before")
        )
        for truth, part in _by_truth(both):
            old, new = part["truth_in_95_before"].astype(bool), part["mixture_in_95"].astype(bool)
            gained, lost, p = _gained_lost(new, old)
            diff = part["final_rmse"] - part["final_rmse_before"]
            p_rmse = wilcoxon(diff).pvalue if (diff != 0).any() else 1.0
            acquired = part["acquired"].astype(bool).sum()
            rows.append(
                [
                    release,
                    truth,
                    str(len(part)),
                    f"{acquired} / {part['acquired_before'].astype(bool).sum()}",
                    f"{100 * old.mean():.0f} %",
                    f"{100 * part['truth_in_95'].astype(bool).mean():.0f} %",
                    f"**{100 * new.mean():.0f} %**",
                    f"+{gained} / −{lost} (p = {p:.2g})",
                    f"{diff.median():+.2f} m (p = {p_rmse:.2g})",
                ]
            )
    header = [
        "releases",
        "truth",
        "n",
        "acquired (today's / before)",
        "truth in 95 %, before",
        "today's, selected member's region",
        "today's, the mixture's region",
        "region against before, gained / lost (exact binomial)",
        "final RMSE against before, paired median (Wilcoxon)",
    ]
    return table(header, rows)


def release_area_table() -> str:
    """Today's defaults (since 2026-11-27 (c)) on the tuning range released at a point, over
    0.5 m and over 1 m (``truth.model.puff_radius``): is the lbm failure an area-release one?
    (docs/results/mixture-region-prior-13-40, whose point and 0.5 m searches are today's
    defaults', and docs/results/tuning-area-release-1m-13-40)."""
    today = pd.read_csv(RESULTS / "mixture-region-prior-13-40" / "searches.csv")
    today = today.assign(truth_in_95=today["mixture_in_95"])  # the region every summary now has
    # the same searches, flown first by tuning-radius-prior, which recorded the along-wind error
    first = pd.read_csv(RESULTS / "tuning-radius-prior-13-40" / "variants.csv")
    today = today.merge(first[["variant", "truth", "scenario", "along"]], how="left")
    wide = pd.read_csv(RESULTS / "tuning-area-release-1m-13-40" / "variants.csv")
    releases = {
        "point (`puff_radius = 0.1`)": today[today["variant"] == "prior"],
        "over 0.5 m (`puff_radius = 0.5`)": today[today["variant"] == "area-prior"],
        "over 1 m (`puff_radius = 1.0`)": wide[wide["variant"] == "area1"],
    }
    rows = []
    for release, frame in releases.items():
        for truth, part in _by_truth(frame):
            n = len(part)
            rows.append(
                [
                    release,
                    truth,
                    str(n),
                    f"{int(part['acquired'].astype(bool).sum())}/{n}",
                    f"{part['final_rmse'].median():.2f}",
                    f"{100 * part['truth_in_95'].astype(bool).mean():.0f} %",
                    f"{part['along'].median():+.2f}",
                ]
            )
    header = [
        "released",
        "truth",
        "n",
        "acquired",
        "median final RMSE (m)",
        "truth in 95 % (the mixture's region)",
        "median along-wind error (m)",
    ]
    return table(header, rows)


def _variant_table(
    frame: pd.DataFrame, names: dict, order: tuple, base_name: str, kind: str = "reading model"
) -> str:
    """Rows per variant and truth (and both truths), each variant paired by search with the
    variant ``base``: acquisition, median final RMSE, share in the 95 % region, along-wind
    error; Wilcoxon on the final RMSE, exact binomial on the region gained / lost."""
    from scipy.stats import wilcoxon

    key = ["truth", "scenario", "seed"]
    frame = frame.drop_duplicates(["variant", *key])
    base = frame[frame["variant"] == "base"]
    rows = []
    for variant in order:
        for truth, part in _by_truth(frame[frame["variant"] == variant]):
            n = len(part)
            paired = "—"
            if variant != "base":
                joined = part.merge(base, on=key, suffixes=("", "_base"))
                diff = joined["final_rmse"] - joined["final_rmse_base"]
                p_rmse = wilcoxon(diff).pvalue if (diff != 0).any() else 1.0
                gained, lost, p_cov = _gained_lost(
                    joined["truth_in_95"], joined["truth_in_95_base"]
                )
                paired = (
                    f"{diff.median():+.2f} m (Wilcoxon p = {p_rmse:.2g}); 95 % region "
                    f"+{gained} / −{lost} (p = {p_cov:.2g}), {len(joined)} pairs"
                )
            rows.append(
                [
                    names[variant],
                    truth,
                    str(n),
                    f"{int(part['acquired'].sum())}/{n}",
                    f"{part['final_rmse'].median():.2f}",
                    f"{100 * part['truth_in_95'].mean():.0f} %",
                    f"{part['along'].median():+.2f}",
                    paired,
                ]
            )
    header = [
        kind,
        "truth",
        "n",
        "acquired",
        "median final RMSE (m)",
        "truth in 95 %",
        "median along-wind error (m)",
        f"paired with {base_name}: final RMSE, median difference; 95 % region gained / lost",
    ]
    return table(header, rows)


def _perf(name: str) -> dict:
    return json.loads((RESULTS / "perf" / f"{name}.json").read_text(encoding="utf-8"))


def _timed(record: dict) -> str:
    """When and how a stored timing was taken: date, cores, and the load beside it."""
    load, machine = record["load"], record["machine"]
    when = (load.get("started") or "")[:10]
    other = load.get("other_cores")
    if load.get("idle") is True:
        state = "idle"
    elif other is None:
        state = "load unknown"
    else:
        state = f"**shared** (other processes {other:.1f} cores)"
    commit = (machine.get("code", {}).get("commit") or "")[:7]
    return f"{when}, {machine['cpus']} CPUs, {state}, `{commit}`"


def _repeats_text(result: dict) -> str:
    """How many runs of the alternation a comparison's figures are the median of."""
    n = result.get("repeats", 1)
    return f"; the median of {n} such runs in one process" if n > 1 else ""


def speed_table() -> str:
    """Speed, from the stored `dcee perf` outputs of docs/results/perf/ (bash studies/run.sh
    perf): every ratio's two sides timed in the same run."""
    ste, mcts, work = _perf("stonesoup-ste"), _perf("stonesoup-mcts"), _perf("workloads")
    by_name = {w["name"]: w for w in work["workloads"]}
    rows = [
        [
            "our `infotaxis` decision vs Stone Soup's KL planner on Stone Soup's own STE "
            f"workload, {ste['stonesoup']['decisions']} decisions each, in alternation"
            + _repeats_text(ste["stonesoup"]),
            f"{ste['stonesoup']['speedup']:.1f}× faster"
            + (
                " (runs {:.1f}-{:.1f}×)".format(*ste["stonesoup"]["speedup_range"])
                if ste["stonesoup"].get("repeats", 1) > 1
                else ""
            ),
            f"{ste['stonesoup']['dcee_infotaxis_median_ms']:.2f} ms vs "
            f"{ste['stonesoup']['stonesoup_median_ms']:.1f} ms",
            "≥ 50×",  # TARGET_SPEEDUP of dcee.perf.stonesoup_compare (older runs stored 20)
            _timed(ste),
        ],
        [
            f"our tree search (`{mcts['strategy']}`) vs Stone Soup's "
            f"`MCTSRolloutSensorManager` on its MCTS STE example, seeds 0-{mcts['seeds'] - 1}",
            f"{mcts['speedup']:.1f}× faster at the median decision"
            + (
                f" ({mcts['first10_speedup']:.0f}× over each search's first ten, before Stone "
                "Soup's growing track history slows its decisions)"
                if "first10_speedup" in mcts
                else ""
            )
            + "; final x-y RMSE "
            f"{mcts['dcee_median_final_rmse']:.2f} m vs {mcts['stonesoup_median_final_rmse']:.2f}"
            f" m (lower in {mcts['dcee_lower_rmse']}/{mcts['seeds']})",
            f"{mcts['dcee_median_ms']:.0f} ms vs {mcts['stonesoup_median_ms']:.0f} ms",
            "≥ 50×, lower RMSE",
            _timed(mcts),
        ],
    ]
    work_rows = (
        ("dcee-decision-20k", "floor", "a paper-scale `dcee` decision (20,000 particles, 8 moves "
         "× 40 readings) vs the plain compiled loop computing the same statistics exactly",
         "≤ 1.5×"),
        ("infotaxis-decision-20k", "floor", "the same for `infotaxis`", "≤ 1.5×"),
        ("dcee-mcts-decision-20k", "dcee-cl-decision", "a `dcee-mcts` decision vs a `dcee-cl` "
         "decision computed exactly, 20,000 particles, in alternation", "≤ 3×"),
        ("resample-mcmc-500-readings-20k", "filter-update", "resample + MCMC move over 500 "
         "readings vs one filter update, 20,000 particles", "≤ 76×"),
    )  # fmt: skip
    for name, reference, label, target in work_rows:
        w = by_name[name]
        ratio = w["ratio_to"][reference]
        rows.append([label, f"{ratio:.2f}×", f"{w['median']:.3g} ms", target, _timed(work)])
    move_path = RESULTS / "perf" / "move-speedup.json"
    if move_path.exists():  # studies/move_speedup.py: what moved the move / update ratio
        move = _perf("move-speedup")
        rows.append(
            [
                "the same move and one filter update vs commit "
                f"`{move['before']}` (the move / update ratio "
                f"{move['before_ratio']:.0f}× there), each side in a fresh process, in "
                "alternation",
                f"move {move['move_speedup']:.2f}× faster, update "
                f"{move['update_speedup']:.2f}× faster (ratio {move['after_ratio']:.0f}× today)",
                f"{move['after_move_ms']:.3g} ms vs {move['before_move_ms']:.3g} ms",
                "the move no slower",
                _timed(move),
            ]
        )
    # issue 46: the default (interpolated sums) and precision=single against the exact decision
    for name, label in (
        ("dcee-cl-decision-20k", "the default (`precision=interpolated`)"),
        ("dcee-cl-single-decision-20k", "`precision=single`"),
    ):
        w = by_name[name]
        if "dcee-cl-double-decision" not in w["ratio_to"]:
            continue  # runs stored before the interpolated sums
        rows.append(
            [
                f"a paper-scale `dcee-cl` decision with {label} vs the same computed exactly in "
                "double precision, in alternation",
                f"{w['ratio_to']['dcee-cl-double-decision']:.2f}×",
                f"{w['median']:.3g} ms",
                "—",
                _timed(work),
            ]
        )
    demo_path = RESULTS / "perf" / "demo-decision.json"
    if demo_path.exists():  # studies/demo_decision.py (issue 46)
        demo = _perf("demo-decision")
        rows.append(
            [
                "the demo's search (`paper:1`, `dcee-cl`, seed 0, 20,000 particles): mean "
                f"decision on one pinned core, against commit `{demo['before']}` in alternation"
                + ("" if demo["same_search"] else " (**the two flew different searches**)"),
                f"{demo['speedup']:.2f}× faster",
                f"{demo['after_ms']:.1f} ms vs {demo['before_ms']:.1f} ms",
                f"≤ {demo['target_ms']:.0f} ms",
                _timed(demo),
            ]
        )
    cl = by_name["dcee-cl-decision-20k"]
    rows.append(
        [
            "a paper-scale `dcee-cl` decision (20,000 particles, 8 moves × 40 readings), "
            f"{work['machine']['numba_threads']} threads",
            "—",
            f"{cl['median']:.3g} ms",
            "—",
            _timed(work),
        ]
    )
    return table(["comparison (both sides in the same run)", "ratio", "absolute", "target",
                  "timed (date, machine, load, code)"], rows)  # fmt: skip


def kernel_speedup_table(name: str = "kernel-speedup") -> str:
    """The predicted-posterior kernel before and after issue 46's changes, in alternation in one
    run (studies/kernel_speedup.py, docs/results/perf/kernel-speedup.json; the second round,
    the sums as matrix products: kernel-speedup-blas.json)."""
    record = _perf(name)
    rows = [
        [
            w["workload"],
            f"{w['tasks']} × {w['particles']:,}",
            f"{w['before_ms']:.1f} ms",
            f"{w['after_ms']:.1f} ms",
            f"**{w['speedup']:.2f}×**",
            f"{w['max_abs_difference']:.0e}",
        ]
        for w in record["workloads"]
    ]
    rows.append(["timed", _timed(record), f"before: `{record['before']}`", "", "", ""])
    return table(
        ["workload", "tasks × particles", "before", "after", "speed-up", "largest difference"],
        rows,
    )


def precision_single_table(
    name: str = "precision-single",
    double: str = "dcee-cl",
    single: str = "dcee-cl:precision=single",
    label: str = "single",
) -> str:
    """`dcee-cl` in single and double precision on the public study's 120 searches, paired
    (bash studies/run.sh precision-single; docs/results/precision-single); with the other
    arguments the interpolated sums against exact double precision
    (docs/results/precision-interpolated)."""
    metrics, pairs = study(name), paired(name)
    searches = pd.read_csv(RESULTS / name / "searches.csv")
    ms = {k: 1e3 * g["decision_seconds_mean"] for k, g in searches.groupby("strategy")}
    rows = []
    for strategy in (double, single):
        r = pick(metrics, strategy)
        rows.append(
            [
                f"`{strategy}`",
                acquired(r),
                share(r, "truth_in_95"),
                rmse(r),
                time_to_1m(r),
                f"{ms[strategy].mean():.1f}",
            ]
        )
    p = pick(pairs, single)
    both = searches.pivot_table(index=["scenario", "seed"], columns="strategy",
                                values="decision_seconds_mean")  # fmt: skip
    ratio = float((both[single] / both[double]).median())
    final = searches.pivot_table(index=["scenario", "seed"], columns="strategy",
                                 values="final_rmse")  # fmt: skip
    same = int((abs(final[single] - final[double]) < 1e-9).sum())
    time_diff, time_p = p["time_to_1m_difference"], p["time_wilcoxon_p"]
    reach = searches.pivot_table(index=["scenario", "seed"], columns="strategy",
                                 values="time_to_rmse_1m")  # fmt: skip
    if not math.isnan(time_diff):
        time_cell = f"{time_diff:+.0f} s (p = {time_p:.2g})"
    elif (reach[single] == reach[double]).all():  # no nonzero difference for a test to use
        time_cell = "0 s in every pair"
    else:
        time_cell = "—"
    rows.append(
        [
            f"paired, {label} − double ({same}/{len(final)} searches end at the same final RMSE "
            "to 1e-9 m)",
            f"{int(p['acquired_variant_only'])} / {int(p['acquired_reference_only'])} acquired "
            f"only by one (McNemar p = {p['mcnemar_p']:.2g})",
            "",
            f"{p['final_rmse_difference']:+.3f} m "
            + (
                "(equal in every pair)"
                if math.isnan(p["rmse_wilcoxon_p"])  # no nonzero difference for a test to use
                else f"(Wilcoxon p = {p['rmse_wilcoxon_p']:.2g})"
            ),
            time_cell,
            f"{ratio:.2f}× per search (median of {len(both)} pairs)",
        ]
    )
    return table(
        ["planner", "source acquired (RMSE < 3 m)", "truth in 95 % region",
         "median final RMSE (m)", "median time to RMSE < 1 m (s)", "mean decision (ms)"],
        rows,
    )  # fmt: skip


def agreement_single_table(name: str = "agreement-single", whole: str | None = None) -> str:
    """Decisions with ``precision=single`` against today's double-precision full computation,
    per planner (studies/decision_agreement.py, docs/results/perf/agreement-single.json); with
    ``name="agreement-interpolated"`` the interpolated sums, and the whole searches of
    ``whole`` (the same check over every decision of longer searches) in a last row."""
    record = _perf(name)
    settings = record["settings"]
    rows = []
    for strategy in settings["strategies"]:
        mine = [r for r in record["searches"] if r["strategy"] == strategy]
        decisions = sum(r["decisions"] for r in mine)
        same = sum(r["same_choice"] for r in mine)
        worst = max(r["max_cost_diff_over_spread"] for r in mine)
        rows.append([f"`{strategy}`", f"{same}/{decisions}", f"{worst:.0e}"])
    rows.append(
        [
            "**all**",
            f"**{record['same_choice']}/{record['decisions']}** "
            f"({100 * record['same_choice'] / record['decisions']:.1f} %)",
            f"{record['max_cost_diff_over_spread']:.0e}",
        ]
    )
    commit = (record["machine"].get("code", {}).get("commit") or "")[:7]
    rows.append(
        [
            "settings",
            f"{', '.join(settings['configs'])}; seeds 0-{settings['seeds'] - 1}; "
            f"{settings['steps']} decisions per search; {settings['particles']:,} particles",
            f"`{commit}`",
        ]
    )
    if whole is not None and (RESULTS / "perf" / f"{whole}.json").exists():
        full = _perf(whole)
        fs = full["settings"]
        rows.append(
            [
                f"whole searches: `{'`, `'.join(fs['strategies'])}`, {', '.join(fs['configs'])}, "
                f"seed 0, up to {fs['steps']} decisions each",
                f"**{full['same_choice']}/{full['decisions']}** "
                f"({100 * full['same_choice'] / full['decisions']:.1f} %)",
                f"{full['max_cost_diff_over_spread']:.0e}",
            ]
        )
    return table(
        ["planner", "same choice as exact double precision", "largest cost difference / spread"],
        rows,
    )


def search_speed_table() -> str:
    """Whole searches of the public study's five planners on one pinned core, two code
    versions in alternation (studies/search_speed.py, docs/results/perf/search-speed.json)."""
    record = _perf("search-speed")
    rows = []
    total = {"before": 0.0, "after": 0.0}
    for planner, row in record["summary"].items():
        c, d, u = row["wall_s"], row["decision_s"], row["update_s"]
        for side in total:
            total[side] += c[side]
        rows.append(
            [
                f"`{planner}`",
                f"{c['before']:.2f} → **{c['after']:.2f}** ({c['before'] / c['after']:.2f}×)",
                f"{d['before']:.2f} → {d['after']:.2f}",
                f"{u['before']:.2f} → {u['after']:.2f}",
                "yes" if row["same_search"] else "no (last-digit differences diverge)",
            ]
        )
    rows.append(
        [
            "**all five** (one search each)",
            f"{total['before']:.1f} → **{total['after']:.1f}** "
            f"({total['before'] / total['after']:.2f}×)",
            "",
            "",
            "",
        ]
    )
    study = {side: 120 * total[side] / 2 / 60 for side in total}
    rows.append(
        [
            "the 600-search study on 2 workers at these costs (a projection, not a measurement: "
            "120 × the sum / 2)",
            f"{study['before']:.0f} → {study['after']:.0f} min",
            "",
            "",
            _timed(record) + f", against `{record['before']}`",
        ]
    )
    # studies/study_wall.py: the campaign itself, measured; every stored run (the machine's
    # speed differs from day to day: the same code took 25.1 and 13.5 min), the latest last
    for study_path in sorted(
        (RESULTS / "perf").glob("study-600*.json"), key=lambda p: (p.stem == "study-600", p.stem)
    ):
        run = _perf(study_path.stem)
        means = ", ".join(f"{k} {v['mean_wall_s']:.1f} s" for k, v in run["per_planner"].items())
        rows.append(
            [
                f"the study measured: `dcee bench --suite paper --repeats 10 --workers 2`, "
                f"{run['searches']} searches (mean per search: {means})",
                f"**{run['wall_seconds'] / 60:.1f} min** (bar ≤ {run['target_minutes']:.0f} min)",
                "",
                "",
                f"{run['campaign_code'].get('commit', '')[:7]}, 2 workers, nothing else run",
            ]
        )
    for extra in sorted((RESULTS / "perf").glob("search-speed-*.json")):
        # the code of an earlier study run against today's, in one run: how much of a change in
        # the study's wall time is the code's and how much the machine's day
        rec = _perf(extra.stem)
        sums = {
            side: sum(row["wall_s"][side] for row in rec["summary"].values())
            for side in ("before", "after")
        }
        same = all(v["same_search"] for v in rec["summary"].values())
        rows.append(
            [
                f"the five searches with the code of `{rec['before']}` and of today, in one run "
                "(`studies/search_speed.py`): the two study rows above differ by the machine's "
                "day, not the code",
                f"{sums['before']:.1f} → {sums['after']:.1f} s "
                f"({sums['before'] / sums['after']:.2f}×)",
                "",
                "",
                ("yes" if same else "no") + "; " + _timed(rec),
            ]
        )
    return table(["planner (`paper:1`, seed 0, 20,000 particles, 450 readings)",
                  "wall per search (s)", "decisions (s)", "filter updates (s)",
                  "same search"], rows)  # fmt: skip


def _source_count(kind: str) -> str:
    """Issue 45's unknown-count study: studies/source_count_table.py's tables of the stored
    searches (``kind`` "table", "table_latest", "paired", "observable" or "worst")."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "source_count_table", ROOT / "studies" / "source_count_table.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    frame = pd.read_csv(RESULTS / "source-count" / "searches.csv")
    return getattr(module, kind)(frame) + "\n"


def source_count_timing_table() -> str:
    """Decision and update time with the count unknown (studies/source_count_timing.py)."""
    frame = pd.read_csv(RESULTS / "source-count" / "timing.csv")
    rows = [
        [
            str(r["truth"]),
            str(int(r["max_sources"])),
            f"{r['decision_ms_mean']:.1f} ({r['decision_ratio']:.2f}×)",
            f"{r['update_ms_mean']:.1f} ({r['update_ratio']:.2f}×)",
            f"{r['load_before']:.2f}",
        ]
        for _, r in frame.iterrows()
    ]
    return table(
        [
            "truth (dcee-cl, seed 0, 10,000 particles, one pinned core)",
            "estimator.max_sources",
            "mean decision (ms) (× one release)",
            "mean update per reading (ms) (× one release)",
            "load before",
        ],
        rows,
    )


TABLES: dict[str, Callable[[], str]] = {
    "source-count": lambda: _source_count("table"),
    "source-count-latest": lambda: _source_count("table_latest"),
    "source-count-worst": lambda: _source_count("worst"),
    "source-count-paired": lambda: _source_count("paired"),
    "source-count-observable": lambda: _source_count("observable"),
    "source-count-timing": source_count_timing_table,
    "learn-tuning": learn_tuning_table,
    "backflow-tuning": backflow_tuning_table,
    "source-radius-tuning": source_radius_tuning_table,
    "lbm-near-source": lbm_near_source_table,
    "lbm-endgame": lbm_endgame_table,
    "horizon-tuning": horizon_tuning_table,
    "lookahead3-tuning": lookahead3_tuning_table,
    "region-floor-tuning": lambda: region_floor_table(
        "tuning-region-floor-13-40/coverage.csv", REGION_FLOOR_DEFAULT["fluctuation"]
    ),
    "region-floor-lbm": lambda: region_floor_table(
        "lbm-held-out-100/region_floor.csv", REGION_FLOOR_DEFAULT["fluctuation"]
    ),
    "region-floor-lbm-infotaxis": lambda: region_floor_table(
        "lbm-held-out-100/region_floor_infotaxis.csv", REGION_FLOOR_DEFAULT["fluctuation"]
    ),
    "cross-truth": cross_truth_table,
    "cross-truth-latest": lambda: cross_truth_table(latest_only=True),
    "radius-prior-point": lambda: radius_prior_table("point"),
    "radius-prior-area": lambda: radius_prior_table("area"),
    "mixture-region": mixture_region_table,
    "mixture-prior": mixture_prior_table,
    "release-area": release_area_table,
    "lbm-statistics": lbm_statistics_table,
    "headline": headline_table,
    "headline-docs": lambda: headline_table(""),
    "wind-known": public_table("paper-source"),
    "full-unknown": public_table("paper-full"),
    "held-out": held_out_table,
    "held-out-paired": paired_table,
    "held-out-others": others_table,
    "turbulent": turbulent_table,
    "team": team_table,
    "lab": lab_table,
    "stop-rule": stop_rule_table,
    "anemometer": anemometer_table,
    "sites": sites_table,
    "sites-walls": sites_walls_table("sites-walls"),
    "sites-walls-tune": sites_walls_table("sites-walls-tune", all_only=True),
    "sites-walls-planners": sites_walls_table("sites-walls-planners", all_only=True),
    "sites-walls-lookahead": sites_walls_table("sites-walls-lookahead"),
    "sites-walls-timing": sites_walls_timing_table,
    "speed": speed_table,
    "search-speed": search_speed_table,
    "kernel-speedup": kernel_speedup_table,
    "kernel-speedup-blas": lambda: kernel_speedup_table("kernel-speedup-blas"),
    "agreement-single": agreement_single_table,
    "precision-single": precision_single_table,
    "agreement-interpolated": lambda: agreement_single_table(
        "agreement-interpolated", "agreement-interpolated-full"
    ),
    "precision-interpolated": lambda: precision_single_table(
        "precision-interpolated",
        "dcee-cl:precision=double",
        "dcee-cl:precision=interpolated",
        "interpolated",
    ),
}


def render(text: str) -> tuple[str, list[str]]:
    """``text`` with every generated region rewritten, and the names of those that changed."""
    changed: list[str] = []

    def one(m: re.Match[str]) -> str:
        name = m.group("name")
        if name not in TABLES:
            raise KeyError(f"unknown generated table {name!r} (studies/publish_tables.py)")
        body = TABLES[name]()
        if body != m.group("body"):
            changed.append(name)
        return m.group(1) + body + m.group(4)

    return MARKER.sub(one, text), changed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if a page disagrees")
    args = ap.parse_args(argv)
    stale = []
    for page in PAGES:
        path = ROOT / page
        text = path.read_text(encoding="utf-8")
        new, changed = render(text)
        stale += [f"{page}: {name}" for name in changed]
        if changed and not args.check:
            path.write_text(new, encoding="utf-8")
    if args.check and stale:
        print("pages disagree with the stored results (run python studies/publish_tables.py):")
        print("\n".join(f"  {s}" for s in stale))
        return 1
    print(("checked" if args.check else "wrote") + f" the generated tables of {', '.join(PAGES)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
