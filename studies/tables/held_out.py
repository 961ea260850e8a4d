"""The held-out studies at today's defaults (recipes held-out, held-out-today)."""

from __future__ import annotations

import math

from studies.tables.common import (
    PLANNERS,
    acquired,
    paired,
    pick,
    rmse,
    stall,
    study,
    table,
    time_to_1m,
)
from studies.tables.paper import FULL_HEADER, full_row

HELD_OUT = (
    ("wind-known", "wind known", "200", "today's"),
    ("full", "all eight unknown", "200", "today's"),
    ("filament", "filament truth, all eight unknown, fluctuation", "`held-out-100`", "2026-11-23"),
)
"""(study, what is unknown and the truth, configurations, defaults flown at) of each study."""


def held_out_table() -> str:
    """The three held-out studies of ``held-out-today``, every planner on the same searches
    (the study, its configurations and the defaults it flew in columns of their own)."""
    rows = []
    frame = study("held-out-today")
    for name, what, configurations, flown in HELD_OUT:
        for strategy in PLANNERS:
            r = pick(frame, strategy, study=name)
            where = [what, configurations, flown, f"`{strategy}` (`held-out-today`)"]
            rows.append(where + full_row("", r)[1:])
    header = ["study", "configurations", "defaults of", "planner (stored in docs/results/)"]
    return table([*header, *FULL_HEADER[1:]], rows)


def paired_table() -> str:
    """`dcee-cl` against infotaxis, and both against the tree search, search by search."""
    frame = paired("held-out-today")
    rows = []
    for name, *_ in HELD_OUT:
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
