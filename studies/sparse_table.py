"""Issue 78, item 4: where gas is rare, which change shrinks the spread. Reads campaigns given as
LABEL=FOLDER (the first is the reference, ``today``), pairs every arm's ``dcee-cl`` searches
with the reference's on the same configuration, and writes OUT/sparse.json: per arm and planner
the searches, median detections, median final spread (√tr of the location covariance, m),
median final RMSE, acquired and truth in the 95 % region, and the paired change of the spread
and the RMSE against the reference's ``dcee-cl`` (median difference, Wilcoxon p).

    python studies/sparse_table.py today=results/lbm3d-sparse-today \\
        weak-zeros=results/lbm3d-sparse-weak-zeros --out docs/results/lbm3d-sparse-tune
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from scipy import stats

from dcee.analysis.results import load_summaries
from dcee.provenance import code_version

KEYS = ("final_spread", "final_rmse")


def arm_rows(label: str, runs, reference) -> list[dict]:
    rows = []
    for strategy, group in runs.groupby("strategy"):
        row = {
            "arm": label,
            "strategy": strategy,
            "searches": len(group),
            "median_detections": float(group["detections"].median()),
            "sparse_searches": int((group["detections"] < 60).sum()),
            "median_final_spread": float(group["final_spread"].median()),
            "median_final_rmse": float(group["final_rmse"].median()),
            "acquired": int(group["source_acquired"].sum()),
            "truth_in_95": int(group["truth_in_95"].sum()),
        }
        ref = reference[reference["strategy"] == "dcee-cl"].set_index("scenario")
        mine = group.set_index("scenario")
        common = sorted(set(ref.index) & set(mine.index))
        if reference is not runs or strategy != "dcee-cl":
            for key in KEYS:
                diff = mine.loc[common, key].to_numpy() - ref.loc[common, key].to_numpy()
                p = float(stats.wilcoxon(diff).pvalue) if np.any(diff != 0) else 1.0
                row[f"paired_{key}"] = {
                    "pairs": len(common),
                    "median_difference": float(np.median(diff)),
                    "wilcoxon_p": p,
                }
        rows.append(row)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("arms", nargs="+", help="LABEL=FOLDER, the reference first")
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    arms = [a.split("=", 1) for a in args.arms]
    reference = load_summaries(arms[0][1])
    rows = []
    for label, folder in arms:
        runs = reference if label == arms[0][0] else load_summaries(folder)
        rows += arm_rows(label, runs, reference)
    args.out.mkdir(parents=True, exist_ok=True)
    doc = {"arms": dict(arms), "rows": rows, "code": code_version()}
    (args.out / "sparse.json").write_text(json.dumps(doc, indent=1) + "\n")
    for r in rows:
        print(
            r["arm"],
            r["strategy"],
            r["median_detections"],
            round(r["median_final_spread"], 2),
            round(r["median_final_rmse"], 2),
            r.get("paired_final_spread"),
        )


if __name__ == "__main__":
    main()
