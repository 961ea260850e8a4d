"""Pair `dcee run` searches of the 3-D plume stored cell by cell with the same configurations of a
stored campaign (the 1 m blocks): per configuration the final RMSE, the final mean's error along
the wind (+ downwind) and whether the truth lay in the 95 % region, each side's code (recipe
lbm3d-store-tune, docs/results/lbm3d-store-tune/).

    python studies/lbm3d_store_pairs.py results/lbm3d-tune results/lbm3d-store-tune \\
        --csv docs/results/lbm3d-store-tune/pairs.csv

The second folder holds one ``rK.json`` (``dcee run --json``) per configuration ``random:K``.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:  # run as a script: the studies package sits beside it
    sys.path.insert(0, str(ROOT))

from studies.lbm3d_table import mean_error  # noqa: E402


def _downwind(mean: list[float], truth: dict) -> float:
    return mean_error(mean, truth)[0]


def _code(summary: dict) -> str:
    code = summary["code"]
    return code["commit"][:9] + ("-dirty" if code["dirty"] else "")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("campaign", type=Path, help="the stored campaign (1 m blocks)")
    ap.add_argument("runs", type=Path, help="folder of rK.json summaries (every cell)")
    ap.add_argument("--csv", type=Path, required=True)
    args = ap.parse_args(argv)
    rows = []
    for path in sorted(args.runs.glob("r*.json"), key=lambda p: int(p.stem[1:])):
        k = path.stem[1:]
        cells = json.loads(path.read_text(encoding="utf-8"))
        run = args.campaign / "runs" / f"config=random%3A{k}" / "strategy=dcee-cl" / "seed=0"
        blocks = json.loads((run / "summary.json").read_text(encoding="utf-8"))
        truth = json.loads((run / "config.json").read_text(encoding="utf-8"))["scenario"]["truth"]
        rows.append(
            {
                "scenario": f"random:{k}",
                "source_z": truth["z"],
                "rmse_blocks_1m": blocks["final_rmse"],
                "rmse_cells_05m": cells["final_rmse"],
                "downwind_blocks_1m": _downwind(blocks["final_mean"], truth),
                "downwind_cells_05m": _downwind(cells["final_mean"], truth),
                "in95_blocks_1m": blocks["truth_in_95"],
                "in95_cells_05m": cells["truth_in_95"],
                "code_blocks_1m": _code(blocks),
                "code_cells_05m": _code(cells),
            }
        )
    args.csv.parent.mkdir(parents=True, exist_ok=True)
    with args.csv.open("w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"{len(rows)} pairs written to {args.csv}")


if __name__ == "__main__":
    main()
