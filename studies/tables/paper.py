"""The paper's public study and the studies on its configurations: the four planners, teams of
robots, the lab experiment, the stop rule, the anemometer (recipes paper-source, paper-full,
team, lab, stop-rule, anemometer)."""

from __future__ import annotations

import math
from collections.abc import Callable

import pandas as pd

from studies.tables.common import (
    RESULTS,
    acquired,
    count,
    interval,
    pick,
    rmse,
    share,
    stall,
    study,
    table,
    time_to_1m,
)

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
