"""Do two campaigns hold the same results? (issue 30: a restructuring must change no number.)

Compares every search present in both folders, bit for bit: every summary field but the code
version and the timings, every per-reading record column but the timings, and the saved
posterior sample. Prints one line per campaign pair and every difference found.

    .venv/bin/python studies/same_results.py BEFORE AFTER [BEFORE AFTER ...]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

TIMING = {
    "code",
    "version",
    "wall_seconds",
    "decision_seconds_total",
    "decision_seconds_mean",
    "update_seconds_total",
    "compute_seconds_total",
}
TIMING_COLUMNS = {"update_seconds", "decision_seconds"}


def searches(folder: Path) -> dict[str, Path]:
    return {
        str(p.parent.relative_to(folder)): p.parent for p in folder.glob("runs/*/*/*/summary.json")
    }


def differences(a: Path, b: Path) -> list[str]:
    out = []
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (a, b))
    for key in sorted((set(sa) | set(sb)) - TIMING):
        if sa.get(key) != sb.get(key):
            out.append(f"summary {key}: {sa.get(key)!r} vs {sb.get(key)!r}")
    ra, rb = (pd.read_parquet(d / "steps.parquet") for d in (a, b))
    if list(ra.columns) != list(rb.columns) or len(ra) != len(rb):
        out.append(f"records: columns or rows differ ({ra.shape} vs {rb.shape})")
    else:
        for col in [c for c in ra.columns if c not in TIMING_COLUMNS]:
            if not ra[col].equals(rb[col]):
                out.append(f"records {col} differ")
    with np.load(a / "posterior.npz") as za, np.load(b / "posterior.npz") as zb:
        for key in sorted(set(za) | set(zb)):
            if key not in za or key not in zb or not np.array_equal(za[key], zb[key]):
                out.append(f"posterior {key} differs")
    return out


def main(argv: list[str]) -> int:
    if len(argv) < 2 or len(argv) % 2:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    failed = 0
    for before, after in zip(argv[::2], argv[1::2], strict=True):
        a, b = searches(Path(before)), searches(Path(after))
        common = sorted(set(a) & set(b))
        bad = {k: d for k in common if (d := differences(a[k], b[k]))}
        print(
            f"{before} vs {after}: {len(common)} searches in both, {len(bad)} differ "
            f"({len(a)} and {len(b)} in each)"
        )
        for k, d in bad.items():
            print(f"  {k}: " + "; ".join(d[:5]))
        failed += len(bad)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
