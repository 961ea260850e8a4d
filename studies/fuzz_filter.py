"""Fuzz the particle filter: N random streams per reading model, count dead filters.

    .venv/bin/python studies/fuzz_filter.py [--streams 1000]

A filter is dead when a weight is not finite, a live particle's history likelihood is not
finite, or (for the models with an outlier component) every live particle is identical.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.test_robust_estimation import FUZZ_SENSORS, filter_is_alive, fuzz_stream


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--streams", type=int, default=1000)
    args = ap.parse_args()
    for name, sensor in FUZZ_SENSORS.items():
        t0 = time.perf_counter()
        dead = sum(
            not filter_is_alive(fuzz_stream(sensor, s), name != "paper")
            for s in range(args.streams)
        )
        print(f"{name}: {dead} dead of {args.streams} streams ({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
