"""Where the lbm truth's gas lies at a site, against whether a search there acquired the source:
for each site of a stored table, the share of the time-mean gas at the flight height lying
upwind of the release (and more than 5 and 10 m upwind), and how far upwind the time mean
still reaches 1 % of the gas 2-4 m downwind on the plume's axis.

    python studies/site_upwind_gas.py docs/results/wander-release/held-out/searches.csv \\
        --arm "released at the region" --out docs/results/site-upwind-gas/held-out.csv

Beside it, ``model_upwind_share``: the same share for the wall-aware estimator's own time-mean
field of the true release (the wake wind at its default viscosity; the most over its
diffusivity bank, 1, 3 and 10 × ζ1), what the estimator can explain.

The time mean is over 61 frames 5 s apart (the first 300 s of the recording from the search's
own start, seed 0) on a 101 × 101 grid over the area, buildings excluded. Reads the cached
plumes (each site's is computed once, about a minute, where it is not cached).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from dcee.models.site_flow import WAKE_VISCOSITY, site_wind
from dcee.scenarios import load_scenario
from dcee.simulation.lbm import lbm_truth

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:  # run as a script: the studies package sits beside it
    sys.path.insert(0, str(ROOT))

from studies.site_flow_fidelity import model_field  # noqa: E402

FLIGHT_HEIGHT = 4.0
"""m: the sites' studies fly the lbm truth at this height (suites sites-tune, sites-held-out-20)."""


def upwind_gas(name: str, cells: int = 101, frames: int = 61, span: float = 300.0) -> dict:
    """The gas statistics of one site (module doc): shares (0-1), reach (m)."""
    sc = load_scenario(name).with_overrides(
        **{"truth.model": "lbm", "truth.z": FLIGHT_HEIGHT, "estimator.plume": "walls"}
    )
    truth = lbm_truth(sc, 0)
    lo, hi = np.asarray(sc.volume.low), np.asarray(sc.volume.high)
    gx, gy = np.meshgrid(
        np.linspace(lo[0], hi[0], cells), np.linspace(lo[1], hi[1], cells), indexing="ij"
    )
    points = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, FLIGHT_HEIGHT)])
    mean = np.zeros(len(points))
    for t in np.linspace(0.0, span, frames):
        mean += truth.field(points, float(t))
    mean /= frames
    mean[sc.in_obstacle(points[:, :2], no_go=False)] = 0.0
    along = truth.canonical(points)
    total = mean.sum()
    axis = (along[:, 0] > 2.0) & (along[:, 0] < 4.0) & (np.abs(along[:, 1]) < 1.0)
    ref = mean[axis].max() if axis.any() and mean[axis].max() > 0 else mean.max()
    # the wall-aware estimator's own time-mean field for the true release (the wake wind at
    # its default viscosity), at each diffusivity of its bank: how much of its gas it puts
    # upwind, the most of the three
    plume, theta = sc.make_plume(), sc.truth_theta()
    faces = site_wind(plume.fluid, plume.resolution, theta[4], theta[5], "wake", WAKE_VISCOSITY)
    model_share = 0.0
    for factor in (1.0, 3.0, 10.0):
        c = model_field(plume, theta, faces, factor, points)
        c[sc.in_obstacle(points[:, :2], no_go=False)] = 0.0
        model_share = max(model_share, float(c[along[:, 0] < 0].sum() / c.sum()))
    return {
        "model_upwind_share": model_share,
        "upwind_share": float(mean[along[:, 0] < 0].sum() / total),
        "upwind_5m_share": float(mean[along[:, 0] < -5].sum() / total),
        "upwind_10m_share": float(mean[along[:, 0] < -10].sum() / total),
        "upwind_reach_m": float(max(0.0, -along[mean >= 0.01 * ref, 0].min())),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("searches", type=Path, help="a searches.csv of studies/sites_walls_table.py")
    ap.add_argument("--arm", required=True, help="its 'estimator' label to take the searches of")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    if not args.searches.is_file():
        print(f"site_upwind_gas: error: searches: {args.searches} not found", file=sys.stderr)
        return 2
    runs = pd.read_csv(args.searches)
    runs = runs[runs["estimator"] == args.arm]
    if runs.empty:
        print(f"site_upwind_gas: error: --arm: no searches labelled {args.arm!r}", file=sys.stderr)
        return 2
    rows = []
    for _, r in runs.iterrows():
        rows.append(
            {
                "scenario": r["scenario"],
                "strategy": r["strategy"],
                "seed": r["seed"],
                "acquired": bool(r["acquired"]),
                "final_rmse": r["final_rmse"],
                **upwind_gas(r["scenario"]),
                "commit": r["commit"],
            }
        )
        print(*rows[-1].values(), flush=True)
    frame = pd.DataFrame(rows)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(args.out, index=False)
    got = frame["acquired"].to_numpy()
    for col in ("upwind_share", "upwind_5m_share", "upwind_reach_m", "model_upwind_share"):
        a, f = frame.loc[got, col], frame.loc[~got, col]
        p = stats.mannwhitneyu(a, f).pvalue if len(a) and len(f) else float("nan")
        print(f"{col}: acquired median {a.median():.3f}, failed {f.median():.3f} (p = {p:.2g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
