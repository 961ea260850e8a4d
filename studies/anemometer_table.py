"""What a measured wind buys (issue 32): the same searches with and without the anemometer,
paired by (configuration, seed): source acquired, median final RMSE, the Kaplan–Meier median
time to RMSE < 1 m, and the paired difference in that time (searches that never got there
count at the budget; Wilcoxon signed-rank), with the share of searches in which the
anemometer made it sooner / later.

    python studies/anemometer_table.py results/anemometer-off results/anemometer-on \\
        [--csv docs/results/anemometer/anemometer.csv]
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


def arm(folder: Path) -> pd.DataFrame:
    s = load_summaries(folder)
    return s.set_index(["scenario", "seed"]).sort_index()


def compare(off_dir: Path, on_dir: Path, prior: str) -> tuple[list[dict], dict]:
    """The two arms' rows and the paired comparison, labelled with the wind-direction prior."""
    off, on = arm(off_dir), arm(on_dir)
    common = off.index.intersection(on.index)
    off, on = off.loc[common], on.loc[common]
    rows = []
    for label, g in (("without anemometer", off), ("with anemometer", on)):
        n = len(g)
        t = pd.to_numeric(g["time_to_rmse_1m"], errors="coerce").to_numpy()
        budget = g["budget"].to_numpy(dtype=float)
        tm = censored_median_time(t, budget)
        acq = wilson(int(g["source_acquired"].sum()), n)
        med = median_ci(g["final_rmse"].to_numpy())
        rows.append(
            {
                "prior": prior,
                "arm": label,
                "searches": n,
                "source_acquired_rate": acq[0],
                "source_acquired_lo": acq[1],
                "source_acquired_hi": acq[2],
                "median_final_rmse": med[0],
                "median_final_rmse_lo": med[1],
                "median_final_rmse_hi": med[2],
                "time_to_1m": tm[0],
                "time_to_1m_lo": tm[1],
                "time_to_1m_hi": tm[2],
                "reached_1m": float(np.isfinite(t).mean()),
            }
        )
    t_off = pd.to_numeric(off["time_to_rmse_1m"], errors="coerce").fillna(off["budget"]).to_numpy()
    t_on = pd.to_numeric(on["time_to_rmse_1m"], errors="coerce").fillna(on["budget"]).to_numpy()
    diff = t_on - t_off
    p = float(stats.wilcoxon(diff).pvalue) if np.any(diff != 0) else 1.0
    rmse_diff = on["final_rmse"].to_numpy() - off["final_rmse"].to_numpy()
    p_rmse = float(stats.wilcoxon(rmse_diff).pvalue) if np.any(rmse_diff != 0) else 1.0
    paired = {
        "prior": prior,
        "pairs": len(common),
        "time_to_1m_difference": float(np.median(diff)),
        "time_wilcoxon_p": p,
        "sooner": int((diff < 0).sum()),
        "later": int((diff > 0).sum()),
        "final_rmse_difference": float(np.median(rmse_diff)),
        "rmse_wilcoxon_p": p_rmse,
    }
    return rows, paired


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("off", type=Path)
    ap.add_argument("on", type=Path)
    ap.add_argument(
        "--vague",
        nargs=2,
        type=Path,
        metavar=("OFF", "ON"),
        help="the same pair with no prior on the wind direction",
    )
    ap.add_argument("--csv", type=Path)
    args = ap.parse_args(argv)
    pairs = [(args.off, args.on, "paper's prior on phi")]
    if args.vague:
        pairs.append((*args.vague, "no prior on phi"))
    rows, paired = [], []
    for off_dir, on_dir, prior in pairs:
        r, pr = compare(off_dir, on_dir, prior)
        rows += r
        paired.append(pr)
    print("| prior | arm | n | acquired | median final RMSE (m) | median time to RMSE < 1 m (s) |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        n = r["searches"]
        print(
            f"| {r['prior']} | {r['arm']} | {n} | {round(r['source_acquired_rate'] * n)}/{n} "
            f"| {r['median_final_rmse']:.2f} | {r['time_to_1m']:.0f} "
            f"({100 * r['reached_1m']:.0f} % got there) |"
        )
    for pr in paired:
        print(
            f"\n{pr['prior']}, paired ({pr['pairs']}): time to 1 m with − without, median "
            f"{pr['time_to_1m_difference']:+.0f} s (Wilcoxon p = {pr['time_wilcoxon_p']:.2g}; "
            f"sooner in {pr['sooner']}, later in {pr['later']}); final RMSE "
            f"{pr['final_rmse_difference']:+.3f} m (p = {pr['rmse_wilcoxon_p']:.2g})"
        )
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        pd.DataFrame(rows).to_csv(args.csv, index=False, float_format="%.6g")
        pd.DataFrame(paired).to_csv(args.csv.with_name("paired.csv"), index=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
