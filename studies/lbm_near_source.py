"""The solver plume near its release, as the replayed truth sees it (docs/plumes.md): the time
mean and the share of frames above a fraction of the peak along the centreline, from 3 m upwind
to 3 m downwind, sampled the way the playback truth samples (bilinear between the stored
blocks). A property of the truth, measured on the truth; nothing is chosen from it.

    .venv/bin/python studies/lbm_near_source.py [--set truth.model.KEY=VALUE ...] \\
        [--csv docs/results/lbm-plume/near_source.csv]
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np
from lbm_statistics import lbm_spec

from dcee.simulation.lbm import cached_recording, load_canonical

ALONG = [-3.0, -2.0, -1.5, -1.0, -0.75, -0.5, -0.25, 0.0, 0.5, 1.0, 2.0, 3.0]
"""m along the mean wind from the release centre (< 0 upwind)."""
LEVELS = (1e-3, 1e-2)
"""Fractions of the peak time mean: the share of frames above them."""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", dest="settings", action="append", default=[])
    ap.add_argument("--csv", type=Path, default=Path("docs/results/lbm-plume/near_source.csv"))
    args = ap.parse_args()
    truth = load_canonical(cached_recording(lbm_spec(args.settings), announce=print))
    c, x, y = truth.values, truth.x, truth.y  # (T, Y, X), canonical frame: wind along +x

    def bilinear(px: float, py: float) -> np.ndarray:
        i = int(np.clip(np.searchsorted(x, px, side="right") - 1, 0, len(x) - 2))
        j = int(np.clip(np.searchsorted(y, py, side="right") - 1, 0, len(y) - 2))
        fx = float(np.clip((px - x[i]) / (x[i + 1] - x[i]), 0.0, 1.0))
        fy = float(np.clip((py - y[j]) / (y[j + 1] - y[j]), 0.0, 1.0))
        return (
            (1 - fx) * (1 - fy) * c[:, j, i]
            + fx * (1 - fy) * c[:, j, i + 1]
            + (1 - fx) * fy * c[:, j + 1, i]
            + fx * fy * c[:, j + 1, i + 1]
        )

    series = {d: bilinear(d, 0.0) for d in ALONG}
    peak = max(float(s.mean()) for s in series.values())
    rows = []
    for d, s in series.items():
        row = {"along_m": d, "mean_over_peak": float(s.mean()) / peak}
        for level in LEVELS:
            row[f"above_{level:g}_peak"] = float(np.mean(s > level * peak))
        rows.append(row)
    args.csv.parent.mkdir(parents=True, exist_ok=True)
    with open(args.csv, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("| along the wind (m) | time mean / peak | " + " | ".join(
        f"frames above {level:g} × peak" for level in LEVELS) + " |")  # fmt: skip
    print("|---|---|" + "---|" * len(LEVELS))
    for r in rows:
        shares = " | ".join(f"{100 * r[f'above_{level:g}_peak']:.0f} %" for level in LEVELS)
        print(f"| {r['along_m']:+.2f} | {r['mean_over_peak']:.3f} | {shares} |")
    print(f"wrote {args.csv}")


if __name__ == "__main__":
    main()
