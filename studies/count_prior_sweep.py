"""The final count each count prior P(K) ∝ r^K would have given, from stored searches (issue 45).

Each search's stored posterior over the count, P(K | z) under the equal prior, is reweighted by
r^K and its most probable count compared with the truth. The searches' paths are kept as they
were (a search's target reads P(K), so a different prior could also have moved the robot
differently): a screen, not a campaign. Run on the tuning range only.

    python studies/count_prior_sweep.py results/two-source-tune-60-bridge \
        results/three-source-tune-60-bridge
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

RATIOS = (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 10.0)


def right_counts(folder: Path, ratio: float) -> tuple[int, int]:
    """(searches whose reweighted most probable count is the true one, searches)."""
    right = total = 0
    for path in sorted(folder.glob("runs/*/*/*/summary.json")):
        s = json.loads(path.read_text())
        p = np.asarray(s["count_probabilities"], dtype=float) * ratio ** np.arange(
            len(s["count_probabilities"])
        )
        right += int(np.argmax(p)) == s["true_sources"]
        total += 1
    return right, total


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path)
    args = ap.parse_args(argv)
    missing = [str(f) for f in args.folders if not any(f.glob("runs/*/*/*/summary.json"))]
    if missing:
        print(f"count_prior_sweep: no finished searches in {', '.join(missing)}", file=sys.stderr)
        return 2
    print("| P(K) ∝ r^K | " + " | ".join(f.name for f in args.folders) + " |")
    print("|---|" + "---|" * len(args.folders))
    for r in RATIOS:
        cells = [f"{a}/{b}" for a, b in (right_counts(f, r) for f in args.folders)]
        print(f"| r = {r:g} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
