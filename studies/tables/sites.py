"""Sites with walls, no-go zones and gas round buildings (recipes sites, sites-walls*)."""

from __future__ import annotations

import math
from collections.abc import Callable

import pandas as pd

from studies.tables.common import (
    RESULTS,
    acquired,
    interval,
    rmse,
    table,
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
        single = frame["scenario"].nunique() == 2  # one site: its pooled rows are its own
        if single:
            frame = frame[frame["scenario"] != "all sites"]
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
            if r["pairs"] >= 5
            and not (all_only and r["scenario"] != "all sites")
            and not (single and r["scenario"] == "all sites")
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


WANDER_RELEASE = {
    "held-out": "`random-site:101-120` (flown once)",
    "fontvieille": "`area:fontvieille` (where the fault was found)",
}
"""docs/results/wander-release's folders and the range each flew (recipe wander-release)."""


def wander_release_table() -> str:
    """The wander guard's release (recipe wander-release): per range and planner, the searches
    the change altered, acquisition and median final error before and after, the median change
    over the altered searches (an exact Wilcoxon test over them, ``changed_wilcoxon_p``) and
    the decisions the wander guard steered, from each folder's ``searches.csv`` and
    ``paired.csv``
    (studies/sites_walls_table.py; ``a`` is the release at the region, ``b`` the code before)."""
    rows = []
    for folder, label in WANDER_RELEASE.items():
        runs = pd.read_csv(RESULTS / "wander-release" / folder / "searches.csv")
        pairs = pd.read_csv(RESULTS / "wander-release" / folder / "paired.csv")
        for _, p in pairs[pairs["scenario"] == "all sites"].iterrows():
            mine = runs[runs["strategy"] == p["strategy"]]
            after, before = (mine[mine["estimator"] == p[k]] for k in ("a", "b"))
            rows.append(
                [
                    label,
                    f"`{p['strategy']}`",
                    f"{int(p['changed'])} of {int(p['pairs'])}",
                    f"{int(before.acquired.sum())} → {int(after.acquired.sum())}",
                    f"{before.final_rmse.median():.2f} → {after.final_rmse.median():.2f}",
                    f"{p['median_changed_difference']:+.2f} (p = {p['changed_wilcoxon_p']:.2g})",
                    f"{int(before.wander_guard_fired.sum())} → "
                    f"{int(after.wander_guard_fired.sum())}",
                ]
            )
    return table(
        [
            "range",
            "planner",
            "searches changed",
            "acquired, before → after",
            "median final RMSE (m), before → after",
            "median change where changed (m; exact Wilcoxon over those)",
            "decisions the wander guard steered",
        ],
        rows,
    )


LEE_VISCOSITY = {
    "tuning": "`random-site:101-120` (tuning; chosen on it)",
    "held-out": "`random-site:201-220` (never flown before; flown once)",
    "fontvieille": "`area:fontvieille`, seeds 0-9 (a tuning site; flown a third time, after it)",
}
"""docs/results/lee-viscosity's folders and the range each flew (recipe lee-viscosity)."""


def lee_viscosity_table() -> str:
    """The wake's eddy viscosity learned (recipe lee-viscosity): per range, acquisition, median
    final error [95 % CI], the truth in the 95 % region and the median decision time of each
    arm (the mean over searches of each one's mean decision; two campaign workers, not an idle
    timing), the searches acquired by one arm only and the median paired change of the final error
    (exact Wilcoxon), from each folder's ``summary.csv`` and ``paired.csv``
    (studies/sites_walls_table.py; ``a`` the learned viscosity, ``b`` the one wake before)."""
    rows = []
    for folder, label in LEE_VISCOSITY.items():
        path = RESULTS / "lee-viscosity" / folder
        if not path.exists():
            continue
        summary = pd.read_csv(path / "summary.csv")
        pairs = pd.read_csv(path / "paired.csv")
        for _, p in pairs[pairs["scenario"] == "all sites"].iterrows():
            everything = summary[
                (summary["scenario"] == "all sites") & (summary["strategy"] == p["strategy"])
            ]
            rows += _lee_rows(everything.set_index("estimator"), p, label)
    return table(
        [
            "range",
            "planner, wall-aware estimator",
            "acquired",
            "median final RMSE (m) [95 % CI]",
            "truth in 95 % region",
            "mean decision (ms; in the campaign)",
            "paired: acquired by one only; median change of the final error (Wilcoxon)",
        ],
        rows,
    )


def _lee_rows(arms: pd.DataFrame, p: pd.Series, label: str) -> list[list[str]]:
    """The before and the learned arm of one planner's pairs ``p`` (``a`` learned, ``b``
    before) as table rows, the range's ``label`` on the first."""
    rows = []
    for arm in (p["b"], p["a"]):
        r = arms.loc[arm]
        n = int(r["searches"])
        paired = (
            f"+{int(p['acquired_a_only'])} / −{int(p['acquired_b_only'])} "
            f"(McNemar p = {p['mcnemar_p']:.2g}); {p['median_rmse_difference']:+.2f} m "
            f"(p = {p['wilcoxon_p']:.2g})"
            if arm == p["a"]
            else ""
        )
        rows.append(
            [
                label if arm == p["b"] else "",
                f"`{p['strategy']}`, {arm}",
                f"{int(r['acquired'])}/{n}",
                f"{r['median_final_rmse']:.2f} [{r['median_final_rmse_lo']:.2f}, "
                f"{r['median_final_rmse_hi']:.2f}]",
                f"{round(r['truth_in_95'] * n)}/{n}",
                f"{r['decision_ms']:.0f}",
                paired,
            ]
        )
    return rows


SITE_UPWIND = {
    "tuning.csv": "`random-site:1-20` (tuning; three moves ahead, code 47b92ab)",
    "held-out.csv": "`random-site:101-120` (flown once; code 338317f)",
}
"""docs/results/site-upwind-gas's tables and the range of each (recipe site-upwind-gas)."""


def site_upwind_table() -> str:
    """Per range, the acquired and the failed `dcee-cl` searches: how many, the share of the
    lbm truth's time-mean gas upwind of the release (median and range), how far upwind it
    reaches 1 % of the near-axis gas, and the share the wall-aware estimator's own model puts
    upwind for the same release (studies/site_upwind_gas.py)."""
    rows = []
    for name, label in SITE_UPWIND.items():
        path = RESULTS / "site-upwind-gas" / name
        if not path.exists():
            continue
        frame = pd.read_csv(path)
        for got, g in ((True, frame[frame.acquired]), (False, frame[~frame.acquired])):
            share, reach = 100 * g.upwind_share, g.upwind_reach_m
            model = 100 * g.model_upwind_share
            rows.append(
                [
                    label,
                    "acquired" if got else "not acquired",
                    str(len(g)),
                    f"{share.median():.1f} ({share.min():.1f}-{share.max():.1f})",
                    f"{100 * g.upwind_5m_share.median():.1f}",
                    f"{reach.median():.1f} ({reach.min():.1f}-{reach.max():.1f})",
                    f"{model.median():.0f} ({model.min():.0f}-{model.max():.0f})",
                ]
            )
    return table(
        [
            "sites",
            "`dcee-cl`",
            "searches",
            "truth's time-mean gas upwind of the release, % (range)",
            "more than 5 m upwind, % (median)",
            "upwind reach of 1 % of the axis's gas, m (range)",
            "the estimator's model, upwind, % (range)",
        ],
        rows,
    )
