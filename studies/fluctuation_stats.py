"""Statistics of hold-averaged readings on the filament truth, to choose the fluctuation
likelihood's parameters by measurement (docs/scenarios.md quotes its output).

For ``paper:1`` (source (37.5, 12.5, 1), wind from +x at 4 m/s, sensor at 4 m) it samples the
truth at points downwind of the source and across the mean plume, averages over a hold of
``--hold`` seconds (as ``dcee`` readings do by default), applies the instrument (threshold and
random misses), and reports per point: the isotropic mean C, the time mean of the averages, the
share of non-detections, and the log-sd of the detected readings about ln C. It then fits the
fluctuation likelihood's intermittency γ(r) = γ∞ (1 − exp(−r / r_γ)) by maximum likelihood, then
the same with a log-sd that grows near the source, s(r) = s∞ + s_near exp(−r / r_s).

    .venv/bin/python studies/fluctuation_stats.py [--hold 5] [--seconds 1800] [--seeds 3]
    .venv/bin/python studies/fluctuation_stats.py --scenario lab:upwind --hold 4
    .venv/bin/python studies/fluctuation_stats.py --hold 4 --pd 1   # no random misses

Another scenario (``--scenario``) gets the same pattern of points scaled to its area (the
distances above × area width / 50 m) at its sensor height.
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy import optimize, stats

from dcee.models.plume import isotropic_concentration
from dcee.scenarios import load_scenario
from dcee.simulation import make_truth


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--hold", type=float, default=5.0)
    ap.add_argument("--seconds", type=float, default=1800.0)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--meander", type=float, default=0.15, help="the model's meander intensity")
    ap.add_argument("--scenario", default="paper:1")
    ap.add_argument("--pd", type=float, help="the instrument's Pd (default: the scenario's)")
    args = ap.parse_args()
    overrides = {"truth.model": "filament"}
    if args.pd is not None:
        overrides["sensor.pd"] = args.pd
    scenario = load_scenario(args.scenario).with_overrides(**overrides)
    theta = scenario.truth_theta()
    sensor = scenario.make_sensor()
    scale = (scenario.volume.high[0] - scenario.volume.low[0]) / 50.0
    down = scale * np.array([1.0, 2.0, 3.0, 5.0, 8.0, 12.0, 20.0, 30.0])
    cross = scale * np.array([0.0, 1.5, 3.0])
    height = scenario.agent.start[2]
    wind = -np.array([np.cos(theta[5]), np.sin(theta[5])])  # where the plume goes
    normal = np.array([-wind[1], wind[0]])
    pts = np.array([[*(theta[:2] + d * wind + c * normal), height] for d in down for c in cross])
    lo, hi = np.array(scenario.volume.low), np.array(scenario.volume.high)
    pts = pts[np.all((pts >= lo) & (pts <= hi), axis=1)]  # inside the area
    mean_c = isotropic_concentration(theta, pts, meander=args.meander)[0]
    rng = np.random.default_rng(0)
    readings = []
    for seed in range(args.seeds):
        truth = make_truth(scenario, seed)
        dt = truth.time_step
        n = round(args.hold / dt)
        t = 0.0
        while t + args.hold <= args.seconds:
            c = np.mean([truth.field(pts, t + dt * (k + 1)) for k in range(n)], axis=0)
            readings.append(sensor.simulate(c, rng))
            t += args.hold
    z = np.array(readings)  # (windows, points)
    det = z >= sensor.threshold
    r = np.linalg.norm(pts - theta[:3], axis=1)
    print(
        f"model meander {args.meander:g}, hold {args.hold:g} s, {len(z)} readings per point, "
        f"instrument Pd {sensor.pd}"
    )
    print("down  cross  r      C_iso      mean/C_iso  nd share  logsd(det)  P(nd) iso-model")
    for k, p in enumerate(pts):
        d = det[:, k]
        lsd = np.std(np.log(z[d, k] / mean_c[k])) if d.sum() > 2 else float("nan")
        along, across = (p[:2] - theta[:2]) @ wind, (p[:2] - theta[:2]) @ normal
        print(
            f"{along:5.1f} {across:6.1f} {r[k]:6.2f} {mean_c[k]:10.3g} "
            f"{z[:, k].mean() / sensor.pd / mean_c[k]:10.2f} {1 - d.mean():9.2f} {lsd:10.2f} "
            f"{float(sensor.likelihood(0.0, mean_c[k])):10.2f}"
        )

    # Fit γ∞, r_γ and s of the fluctuation likelihood to every reading by maximum likelihood
    # (readings are the instrument's; the likelihood's γ absorbs its random misses).
    thr = sensor.threshold

    with np.errstate(divide="ignore"):
        lz = np.log(np.where(det, z, thr))

    def neg_log_lik(g: np.ndarray, s: np.ndarray) -> float:
        """−log p(readings) for intermittency g and log-sd s per point (arrays over points)."""
        mu = np.log(mean_c) - 0.5 * s * s
        p_nd = 1 - g + g * stats.norm.cdf((np.log(thr) - mu) / s)
        ll_det = np.log(g) + stats.norm.logpdf(lz, mu, s) - lz
        return -float(np.where(det, ll_det, np.log(p_nd)).sum())

    def intermittency(par: np.ndarray) -> np.ndarray:
        return 1 / (1 + np.exp(-par[0])) * (1 - np.exp(-r / np.exp(par[1])))

    def nll(par: np.ndarray) -> float:
        return neg_log_lik(intermittency(par), np.full_like(r, np.exp(par[2])))

    def nll_spread(par: np.ndarray) -> float:
        """The same with the spread growing near the source: s(r) = s∞ + s_near e^(−r/r_s)."""
        s = np.exp(par[2]) + np.exp(par[3]) * np.exp(-r / np.exp(par[4]))
        return neg_log_lik(intermittency(par), s)

    spread = optimize.minimize(
        nll_spread,
        np.array([0.5, 1.7, 0.0, 0.5, 1.0]),
        method="Nelder-Mead",
        options={"maxfev": 4000},
    )
    spread = optimize.minimize(nll_spread, spread.x, method="Nelder-Mead", options={"maxfev": 4000})
    best = optimize.minimize(nll, np.array([0.0, 0.0, 0.0]), method="Nelder-Mead")
    g_inf, r_g, s = 1 / (1 + np.exp(-best.x[0])), np.exp(best.x[1]), np.exp(best.x[2])
    flat = optimize.minimize(
        lambda q: nll(np.array([q[0], -10.0, q[1]])), np.array([0.0, 0.0]), method="Nelder-Mead"
    )
    print(f"fit: gamma_inf {g_inf:.3f}  r_gamma {r_g:.2f} m  log_sd {s:.3f}  (nll {best.fun:.1f})")
    x = spread.x
    print(
        f"spread fit: gamma_inf {1 / (1 + np.exp(-x[0])):.3f}  r_gamma {np.exp(x[1]):.2f} m  "
        f"log_sd {np.exp(x[2]):.3f}  log_sd_near {np.exp(x[3]):.2f}  log_sd_length "
        f"{np.exp(x[4]):.2f} m  (nll {spread.fun:.1f}; 2 Δnll = {2 * (best.fun - spread.fun):.1f} "
        "for two parameters)"
    )
    print(
        f"constant gamma: gamma {1 / (1 + np.exp(-flat.x[0])):.3f}  log_sd {np.exp(flat.x[1]):.3f}"
        f"  (nll {flat.fun:.1f}; 2 Δnll = {2 * (flat.fun - best.fun):.1f} for one parameter)"
    )


if __name__ == "__main__":
    main()
