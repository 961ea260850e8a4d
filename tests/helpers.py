"""Small hand-built problems shared by the tests."""

from __future__ import annotations

import numpy as np

from dcee.estimation.priors import Fixed, Gamma, SourcePrior, Uniform

SUMMARY_KEYS = {
    "final_rmse",
    "plume_acquired",
    "source_acquired",
    "time_to_rmse_1m",
    "time_to_rmse_0_5m",
    "steps",
    "path_length",
    "strategy",
    "scenario",
    "seed",
    "longest_stall",
}
"""Keys the issue requires in every run summary."""


def planar_prior(
    x=(0.0, 10.0), y=(0.0, 10.0), q_gamma=(2.0, 1.0), u=2.0, phi=0.0, zeta1=1.0, zeta2=8.0
) -> SourcePrior:
    """x, y, q unknown; source at z = 0; wind and dispersion known."""
    return SourcePrior.from_dict(
        {
            "x": Uniform(*x),
            "y": Uniform(*y),
            "z": Fixed(0.0),
            "q": Gamma(*q_gamma),
            "u": Fixed(u),
            "phi": Fixed(phi),
            "zeta1": Fixed(zeta1),
            "zeta2": Fixed(zeta2),
        }
    )


def theta_at(points, q=5.0, u=0.0, phi=0.0, zeta1=1.0, zeta2=8.0) -> np.ndarray:
    """(N, 8) source terms at the given (N, 3) locations with shared other parameters."""
    points = np.atleast_2d(np.asarray(points, dtype=float))
    n = len(points)
    return np.column_stack(
        [
            points,
            np.full(n, q),
            np.full(n, u),
            np.full(n, phi),
            np.full(n, zeta1),
            np.full(n, zeta2),
        ]
    )


def run_cli(argv, capsys):
    """Run ``dcee argv``; returns (exit code, stdout, stderr)."""
    import pytest

    from dcee.cli import main

    with pytest.raises(SystemExit) as exc:
        main(argv)
    out = capsys.readouterr()
    return exc.value.code, out.out, out.err


def search_that_kills_its_worker_on_seed_1(task):
    """A campaign search that, for repeat 1, kills the worker process running it (as the
    out-of-memory killer would); otherwise the real search. Module-level so that spawned worker
    processes can import it."""
    import os

    from dcee.campaign.runner import run_search

    if task.seed == 1:
        os._exit(9)
    return run_search(task)


def _terms_from_concentrations(conc, dist, sensor):
    """The position terms (loc, log_nd, inv_sigma, det_offset), each (P, N), from raw
    concentrations (P, N) and distances (P, N; None: far), by the NumPy sensor model
    (position_rows computes them from source terms; these tests feed raw concentrations)."""
    conc = np.ascontiguousarray(conc)
    dist = np.full_like(conc, np.inf) if dist is None else np.ascontiguousarray(dist)
    loc, sigma = sensor._loc_sigma(conc, dist)
    with np.errstate(divide="ignore"):
        det_offset = np.log(sensor.detect_prob(dist)) - np.log(sigma)
    return [
        np.ascontiguousarray(a)
        for a in (loc, sensor.log_likelihood(0.0, conc, dist), 1.0 / sigma, det_offset)
    ]


def compiled_predicted_stats(conc, source, weights, task_pos, task_z, sensor, dist=None, **flags):
    """The compiled predicted-posterior statistics with the reference's arguments:
    (log_evidence, mean, trace_cov, kl) for raw concentrations (P, N), distances (P, N; None:
    far) and readings (S, T)."""
    from dcee.planning.predicted_kernels import predicted_posterior_stats

    terms = _terms_from_concentrations(conc, dist, sensor)
    s = len(task_pos)
    out = [np.empty(s), np.empty((s, 3)), np.empty(s), np.empty(s)]
    predicted_posterior_stats(
        *terms,
        np.ascontiguousarray(source),
        weights,
        weights @ source,
        task_pos,
        *sensor.transformed_readings(np.asarray(task_z, dtype=float)),
        sensor.params,
        *out,
        **flags,
    )
    return out


def compiled_location_kl(conc, source, weights, task_pos, task_z, sensor, cell, dist=None):
    """The compiled location-cell KL divergence with the reference's arguments (see
    :func:`compiled_predicted_stats`)."""
    from dcee.planning.location_kl import location_cells, location_kl

    terms = _terms_from_concentrations(conc, dist, sensor)
    tv, tfa, tout, _ = sensor.transformed_readings(np.asarray(task_z, dtype=float))
    out = np.empty(len(task_pos))
    location_kl(
        *terms,
        weights,
        *location_cells(np.ascontiguousarray(source), weights, cell),
        np.ascontiguousarray(task_pos, dtype=np.int64),
        *(np.ascontiguousarray(a, dtype=np.float64) for a in (tv, tfa, tout)),
        sensor.params,
        out,
    )
    return out


def random_theta(n: int, rng: np.random.Generator) -> np.ndarray:
    """(n, 8) source terms spread over a 50 × 50 × 5 m area and plausible environments."""
    return np.column_stack(
        [
            rng.uniform(0, 50, n),
            rng.uniform(0, 50, n),
            rng.uniform(0, 5, n),
            rng.gamma(2, 5, n),
            rng.uniform(0, 8, n),
            rng.uniform(-4, 4, n),
            rng.uniform(0.1, 3, n),
            rng.uniform(0.5, 15, n),
        ]
    )


def spike_ess_share(estimator, scenario, seed: int = 0) -> float:
    """One 10⁶ × reading through ``estimator`` (a filter or a model bank, as an entry point
    built it): 20 clean readings of ``scenario``'s truth on a fixed crosswind zigzag below the
    source, then a reading of 10⁶ × the threshold 40 m away from the plume. Returns the ESS
    share the spike left: near 1 where the outlier safety holds, 1/N where one particle took
    all the weight (the paper's exact likelihood)."""
    from dcee.simulation import make_truth

    truth, instrument = make_truth(scenario, seed), scenario.make_sensor()
    rng = np.random.default_rng(seed)
    for k in range(20):
        p = np.array([12.0 + k, 12.5 + 5.0 * np.sin(k), 1.0])
        estimator.update(p, float(instrument.simulate(truth.concentration(p, float(k)), rng)))
    info = estimator.update(np.array([5.0, 45.0, 1.0]), 1e6 * scenario.sensor.threshold)
    return info.ess / estimator.n


def stratified_readings_reference(ctx, pos_idx):
    """The stratified hypotheses of one sequence of cached positions (T,), one sequence at a
    time as PredictionContext drew them before its batched pass: ((J', T) readings, (J',)
    probabilities), the reference its batch is tested against bit for bit."""
    t_count = len(pos_idx)
    j_count = ctx._n
    weights = ctx.belief.weights
    log_nd = ctx.terms.log_nd[pos_idx]  # (T, N)
    log_nd_all = log_nd.sum(axis=0)
    p_detect_i = weights * -np.expm1(log_nd_all)  # w_i P(≥ 1 detection | Θ_i)
    p_detect = float(p_detect_i.sum())
    z = np.zeros((j_count + 1, t_count))
    prob = np.zeros(j_count + 1)
    prob[0] = max(1.0 - p_detect, 0.0)
    if not p_detect > 1e-300:
        prob[0] = 1.0
        return z, prob
    prob[1:] = p_detect / j_count
    cumulative = np.cumsum(p_detect_i) / p_detect
    cumulative[-1] = 1.0
    idx = np.searchsorted(cumulative, (ctx._offset + np.arange(j_count)) / j_count, "right")
    idx = idx.clip(0, len(weights) - 1)
    # first detecting stage t: P ∝ Π_{t'<t} P(nd_t') (1 − P(nd_t)), by inversion
    nd = np.exp(log_nd[:, idx]).T  # (J, T)
    before = np.cumprod(np.column_stack([np.ones(j_count), nd[:, :-1]]), axis=1)
    first_cdf = np.cumsum(before * (1.0 - nd), axis=1)
    target = ctx._first_u * first_cdf[:, -1]
    first = (first_cdf <= target[:, None]).sum(axis=1).clip(0, t_count - 1)
    conc = ctx.conc[pos_idx][:, idx].T  # (J, T)
    dist = ctx.terms.dist[pos_idx][:, idx].T
    rows = np.arange(j_count)
    z[1:] = ctx.sensor.simulate_from(conc, ctx.noise[:, :t_count], dist)
    stage = np.arange(t_count)[None, :]
    z[1:][stage < first[:, None]] = 0.0
    z[1:][rows, first] = ctx.sensor.simulate_detection(
        conc[rows, first], ctx._detect_u, dist[rows, first]
    )
    return z, prob


def search_that_sleeps(task):
    """A stand-in search that takes a minute (for the driver's signal handling); it leaves a
    file ``started`` in its folder first, so that a test knows it is running."""
    import time

    task.folder.mkdir(parents=True, exist_ok=True)
    (task.folder / "started").touch()
    time.sleep(60)
    return {"status": "done", "task": task}


def run_with_numba_threads(threads: int, module: str, call: str) -> None:
    """Run ``module.call`` (``call`` a Python call expression, say ``"_check('single')"``) in a
    fresh interpreter whose numba pool holds ``threads`` threads, and fail with its error output
    if it fails. For the checks that need more threads than the suite's processes have
    (tests/conftest.py gives each one)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    proc = subprocess.run(
        [sys.executable, "-c", f"import {module}; {module}.{call}"],
        cwd=Path(__file__).resolve().parent.parent,
        env={**os.environ, "NUMBA_NUM_THREADS": str(threads)},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
