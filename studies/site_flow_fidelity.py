"""How well the wall-aware plume's time-mean field matches the lbm truth's, per wind model
(issue 44; a check beside the tuning, on the tuning sites only).

For each site ``random-site:K`` (lbm truth at the flight height, as the suite ``sites-tune``
flies it): the truth's mean concentration over 600 s (121 frames) on a 1 m grid over the search
area, and the wall-aware plume's prediction for the true release with each wind model
(``wake``, ``potential``) and each diffusivity of the estimator's bank (1, 3, 10 × ζ1). Over the
air points where either is above the sensor's threshold: the correlation of log10
concentrations and the RMS of their difference after the best common shift (the estimator
learns q, so only the shape counts). Writes one row per site, wind, eddy viscosity (the wake
wind's ν_t, ``--viscosities``; the potential wind has none) and K.

    python studies/site_flow_fidelity.py --sites 1-8 \
        --out docs/results/sites-walls-tune/fidelity.csv
    python studies/site_flow_fidelity.py --sites 1-8 --viscosities 0.25,0.5,1,2,4 \
        --out docs/results/sites-walls-tune/viscosity/fidelity.csv
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pandas as pd

from dcee.models.site_flow import WAKE_VISCOSITY, site_wind
from dcee.models.site_plume import SitePlume
from dcee.provenance import code_version, describe
from dcee.scenarios import load_scenario
from dcee.simulation import make_truth

OVERRIDES = {
    "truth.model": "lbm",
    "truth.z": 4.0,
    "estimator.likelihood": "fluctuation",
    "estimator.plume": "walls",
}


def model_field(
    plume: SitePlume, theta: np.ndarray, faces: object, factor: float, points: np.ndarray
) -> np.ndarray:
    """(M,) g/m³: the wall-aware plume's time-mean field of the release ``theta`` (8,) at
    ``points`` (M, 3) m, in the wind ``faces`` (:func:`site_wind`), its diffusivity ``factor``
    × ζ1 and no decay (the bank's members)."""
    model = SitePlume(
        plume.fluid,
        plume.origin,
        plume.resolution,
        theta[4],
        theta[5],
        factor * theta[6],
        math.inf,
        wind=faces,
    )
    return model.concentration(theta[None], points)[0]


def site_rows(k: int, viscosities: tuple[float, ...] = (WAKE_VISCOSITY,)) -> list[dict]:
    sc = load_scenario(f"random-site:{k}").with_overrides(**OVERRIDES)
    truth = make_truth(sc, 0)
    plume = sc.make_plume()
    theta = sc.truth_theta()
    lo, hi = sc.volume.low, sc.volume.high
    gx, gy = np.meshgrid(np.arange(lo[0], hi[0] + 1e-9, 1.0), np.arange(lo[1], hi[1] + 1e-9, 1.0))
    pos = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, theta[2])])
    mean = np.mean([truth.field(pos, t) for t in np.linspace(0.0, 600.0, 121)], axis=0)
    air = ~sc.in_obstacle(pos[:, :2], no_go=False)
    threshold = sc.sensor.threshold
    rows = []
    winds = [("wake", nu) for nu in viscosities] + [("potential", math.nan)]
    for wind, nu in winds:
        faces = site_wind(plume.fluid, plume.resolution, theta[4], theta[5], wind, nu)
        for factor in (1.0, 3.0, 10.0):
            c = model_field(plume, theta, faces, factor, pos)
            keep = air & ((mean > threshold) | (c > threshold))
            a = np.log10(np.maximum(mean[keep], threshold / 10))
            b = np.log10(np.maximum(c[keep], threshold / 10))
            shift = np.median(a - b)
            rows.append(
                {
                    "site": f"random-site:{k}",
                    "wind": wind,
                    "viscosity": nu,
                    "K_factor": factor,
                    "points": int(keep.sum()),
                    "log_correlation": float(np.corrcoef(a, b)[0, 1]),
                    "log_rms_error": float(np.sqrt(np.mean((a - b - shift) ** 2))),
                }
            )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sites", default="1-4", help="K range of random-site:K, e.g. 1-4")
    parser.add_argument(
        "--viscosities",
        default=str(WAKE_VISCOSITY),
        help="the wake wind's eddy viscosities ν_t, m²/s, comma-separated",
    )
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    first, last = (int(v) for v in args.sites.split("-"))
    viscosities = tuple(float(v) for v in args.viscosities.split(","))
    rows = [r for k in range(first, last + 1) for r in site_rows(k, viscosities)]
    table = pd.DataFrame(rows).assign(code=describe(code_version()))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out, index=False, float_format="%.4g")
    table["model"] = [
        w if w == "potential" else f"wake {v:g}"
        for w, v in zip(table["wind"], table["viscosity"], strict=True)
    ]
    best = table.groupby(["site", "model"])["log_rms_error"].min().unstack()
    print(best.round(2).to_string())
    print(best.mean().round(3).to_string())


if __name__ == "__main__":
    main()
