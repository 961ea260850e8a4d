"""Decision and update time on a site against open terrain (issue 44: "a decision on a site
costs at most 3× one on open terrain"), in one run on one pinned core.

For each site with walls (``site:wall``, ``site:passage``, ``site:canyon``) the same search
(``dcee-cl``, seed 0, 10,000 particles, 900 s, the lbm truth at the flight height, the
fluctuation likelihood, as the ``sites-walls`` suite) four ways: in open terrain (the site's
source, wind and start with ``world.obstacles = []``: no walls, no guard), on the site with the
wall-blind estimator, with the wall-aware one (``estimator.plume = "walls"``), and with the
wall-aware one as it was before its wake's eddy viscosity was learned (one wake, three
members). Each in its own
process pinned to core 0 with one thread (``taskset -c 0``, NUMBA/OMP/OPENBLAS threads 1), the
kernels compiled by a first warm-up search; the truths' plumes must be cached (run the suite
first). Run it with nothing else on the machine; the load is recorded beside the times.

All four ways look the same number of moves ahead (``--lookahead``, default the wall-aware
estimator's unset default at a site, :data:`dcee.scenarios.SITE_LOOKAHEAD`): unset, open terrain
would look :data:`~dcee.scenarios.AUTO_LOOKAHEAD` moves ahead and the wall-blind estimator one,
and the ratio would compare planners, not terrain.

    python studies/site_timing.py --out docs/results/sites-walls/timing.csv
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import pandas as pd
from source_count_timing import pinned_search

from dcee.scenarios import SITE_LOOKAHEAD

SITES = ("site:wall", "site:passage", "site:canyon")
COMMON = ["--truth", "lbm", "--likelihood", "fluctuation", "--set", "truth.z=4"]
WAYS = {
    "open terrain": ["--set", "world.obstacles=[]"],
    # an unset estimator.plume is "walls" at a site since issue 84 (2026-12-05): pinned open
    "site, wall-blind": ["--set", 'estimator.plume="open"'],
    "site, wall-aware": ["--set", 'estimator.plume="walls"'],
    # the wall-aware estimator before the wake's eddy viscosity was learned (2026-12-06): one
    # wake, the diffusivity alone weighed (three fluctuation members for six; ζ1 = 1 at every
    # site here)
    "site, wall-aware, one wake": [
        "--set",
        'estimator.plume="walls"',
        "--set",
        "estimator.learn={wall_diffusivity=[1.0,3.0,10.0]}",
    ],
}


def one(site: str, extra: list[str], folder: Path, lookahead: int) -> dict:
    pinned = ["--set", f"search.lookahead={lookahead}"]
    return pinned_search(
        ["--scenario", site, *COMMON, *pinned, *extra, "--particles", "10000"], folder
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument(
        "--lookahead",
        type=int,
        choices=(1, 2, 3),
        default=SITE_LOOKAHEAD,
        help="moves dcee-cl looks ahead, all four ways (default: SITE_LOOKAHEAD)",
    )
    args = ap.parse_args(argv)
    try:
        args.out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(f"site_timing: error: --out: cannot write {args.out} ({exc})", file=sys.stderr)
        return 2
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        # compile the kernels
        one(SITES[0], WAYS["site, wall-aware"], Path(tmp) / "warm-up", args.lookahead)
        for site in SITES:
            for way, extra in WAYS.items():
                load = os.getloadavg()[0]
                s = one(site, extra, Path(tmp) / f"{len(rows)}", args.lookahead)
                rows.append(
                    {
                        "site": site,
                        "way": way,
                        "lookahead": args.lookahead,
                        "decision_ms_mean": 1e3 * s["decision_seconds_mean"],
                        "update_ms_mean": 1e3 * s["update_seconds_total"] / s["readings"],
                        "steps": s["steps"],
                        "final_rmse": s["final_rmse"],
                        "load_before": round(load, 2),
                        "commit": s["code"]["commit"],
                    }
                )
                print(rows[-1], flush=True)
    frame = pd.DataFrame(rows)
    base = frame[frame.way == "open terrain"].set_index("site")
    frame["decision_ratio"] = frame.apply(
        lambda r: r.decision_ms_mean / base.loc[r.site, "decision_ms_mean"], axis=1
    )
    frame["update_ratio"] = frame.apply(
        lambda r: r.update_ms_mean / base.loc[r.site, "update_ms_mean"], axis=1
    )
    frame.to_csv(args.out, index=False)
    print(frame.to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
