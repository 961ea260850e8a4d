"""The lab-experiment table (issue 15): the paper's indoor search in simulation with the
unicycle robot against the idealised grid agent, per start and planner, paired by seed.

    .venv/bin/python studies/lab_table.py results/lab-robot=robot-isotropic \
        results/lab-grid=grid-isotropic [results/lab-robot-filament=robot-filament-50m …] \
        [--out docs/results/lab]

prints the per-start table (robot against grid, paired: the first two campaigns) and a compact
one pooled over both starts with one column group per campaign given (``=SETTING`` names it);
``--out`` writes the pooled rows (metrics.csv) and one row per search (searches.csv).

"Source acquired" is the lab scenarios' criterion (final RMSE < 0.5 m). Rates carry Wilson 95 %
intervals, medians distribution-free intervals, times Kaplan-Meier medians (searches that never
get there censored at the 450 s budget); robot vs grid: exact McNemar on acquired and Wilcoxon
signed-rank on the final RMSE over the same (start, seed).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.results import load_summaries
from dcee.analysis.statistics import censored_median_time, median_ci, wilson


def table(robot_dir: str, grid_dir: str) -> str:
    robot, grid = load_summaries(robot_dir), load_summaries(grid_dir)
    lines = [
        "| start | planner | robot | n | source acquired (RMSE < 0.5 m) | median final RMSE (m) "
        "| time to RMSE < 0.5 m (s) | readings | robot vs grid: acquired (only grid / only "
        "robot, McNemar p), final RMSE (median diff., Wilcoxon p) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scenario in sorted(robot.scenario.unique()):
        for planner in sorted(robot.strategy.unique()):
            rows = {}
            for name, runs in (("unicycle", robot), ("grid", grid)):
                g = runs[(runs.scenario == scenario) & (runs.strategy == planner)]
                rows[name] = g.set_index("seed").sort_index()
            common = rows["unicycle"].index.intersection(rows["grid"].index)
            for name in ("unicycle", "grid"):
                g = rows[name].loc[common]
                n = len(g)
                if n == 0:
                    continue
                k = int(g.source_acquired.sum())
                rate = wilson(k, n)
                med = median_ci(g.final_rmse.to_numpy())
                t = censored_median_time(
                    g.time_to_rmse_0_5m.to_numpy(dtype=float), g.budget.to_numpy(dtype=float)
                )
                tfmt = f"{t[0]:.0f} [{t[1]:.0f}, {t[2]:.0f}]".replace("inf", "> 450")
                test = "—"
                if name == "unicycle":
                    a = rows["grid"].loc[common]
                    only_grid = int((a.source_acquired & ~g.source_acquired).sum())
                    only_robot = int((~a.source_acquired & g.source_acquired).sum())
                    b = only_grid + only_robot
                    p_mc = stats.binomtest(only_grid, b).pvalue if b else 1.0
                    diff = (g.final_rmse - a.final_rmse).dropna()
                    p_w = stats.wilcoxon(diff).pvalue if np.any(diff != 0) else 1.0
                    test = (
                        f"{only_grid} / {only_robot}, p = {p_mc:.2g}; "
                        f"{np.median(diff):+.3f} m, p = {p_w:.2g}"
                    )
                lines.append(
                    f"| {scenario.removeprefix('lab:')} | {planner} | {name} | {n} | "
                    f"{k}/{n} ({100 * rate[0]:.0f} [{100 * rate[1]:.0f}, {100 * rate[2]:.0f}]%) | "
                    f"{med[0]:.2f} [{med[1]:.2f}, {med[2]:.2f}] | {tfmt} | "
                    f"{int(np.median(g.readings))} | {test} |"
                )
    return "\n".join(lines)


def _split(arg: str) -> tuple[str, str]:
    """``DIR=SETTING`` (or ``DIR``: the folder's name) into (folder, setting)."""
    folder, _, setting = arg.partition("=")
    return folder, setting or folder.rstrip("/").split("/")[-1]


def pooled_rows(args: list[str]) -> list[dict[str, object]]:
    """Per campaign (``DIR=SETTING``) and planner, both starts pooled: the columns of
    docs/results/lab/metrics.csv."""
    out: list[dict[str, object]] = []
    for arg in args:
        folder, setting = _split(arg)
        runs = load_summaries(folder)
        for planner in sorted(runs.strategy.unique()):
            g = runs[runs.strategy == planner]
            k, n = int(g.source_acquired.sum()), len(g)
            row: dict[str, object] = {"strategy": planner, "setting": setting, "searches": n}
            t = censored_median_time(
                g.time_to_rmse_0_5m.to_numpy(dtype=float), g.budget.to_numpy(dtype=float)
            )
            for key, suffixes, found in (
                ("source_acquired", ("_rate", "_lo", "_hi"), wilson(k, n)),
                ("median_final_rmse", ("", "_lo", "_hi"), median_ci(g.final_rmse.to_numpy())),
                ("time_to_0_5m", ("", "_lo", "_hi"), t),
            ):
                row |= {key + suffix: v for suffix, v in zip(suffixes, found, strict=True)}
            row["readings"] = int(np.median(g.readings))
            out.append(row)
    return out


def pooled(args: list[str]) -> str:
    """Per planner, both starts pooled (20 searches), one column group per campaign."""
    found = pooled_rows(args)
    settings = list(dict.fromkeys(r["setting"] for r in found))
    head = "| planner | " + " | ".join(
        f"{s}: acquired, median RMSE (m), time to 0.5 m (s), readings" for s in settings
    )
    lines = [head + " |", "|---|" + "---|" * len(settings)]
    for planner in sorted({r["strategy"] for r in found}):
        cells = []
        for setting in settings:
            r = next(
                (r for r in found if r["strategy"] == planner and r["setting"] == setting), None
            )
            if r is None:
                cells.append("—")
                continue
            n = r["searches"]
            t = f"{r['time_to_0_5m']:.0f}".replace("inf", "> 450")
            k = round(r["source_acquired_rate"] * n)
            cells.append(f"{k}/{n}, {r['median_final_rmse']:.2f}, {t}, {r['readings']}")
        lines.append(f"| {planner} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaigns", nargs="+", help="DIR[=SETTING]; the first two: robot, grid")
    ap.add_argument("--out", help="a study folder to write metrics.csv and searches.csv into")
    args = ap.parse_args(argv)
    print(table(_split(args.campaigns[0])[0], _split(args.campaigns[1])[0]))
    print()
    print(pooled(args.campaigns))
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        pd.DataFrame(pooled_rows(args.campaigns)).to_csv(out / "metrics.csv", index=False)
        frames = []
        for arg in args.campaigns:
            folder, setting = _split(arg)
            runs = load_summaries(folder)
            runs.insert(0, "setting", setting)
            frames.append(runs)
        keep = ["setting", "scenario", "seed", "strategy", "source_acquired", "final_rmse"]
        keep += ["time_to_rmse_0_5m", "readings"]
        pd.concat(frames).reindex(columns=keep).to_csv(out / "searches.csv", index=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
