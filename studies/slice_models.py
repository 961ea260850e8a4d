"""Reading models on the slice's readings (issue 78; used by studies/slice_oracle.py): the exact
grid posterior of today's reading model over the release's horizontal position, and probes of
other shapes and fluctuation models on the same readings, all with the height, the wind and (or
not) the rate known. A model that cannot place the source here, where the filter's approximation
and the other unknowns are taken away, will not place it in a search.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import logsumexp


def candidate_grid(
    truth,  # type: ignore[no-untyped-def]
    low: np.ndarray,
    high: np.ndarray,
    step: float,
    reach: tuple[float, float, float],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The candidate offsets (along, across the wind; (N,) m each) of the release from the truth
    on a ``step`` m grid reaching ``reach`` = (upwind, downwind, across) m, inside the search
    area [``low``, ``high``] (the estimator's prior), and their world positions (N, 2)."""
    behind, ahead, side = reach
    along = np.arange(-behind, ahead + step / 2, step)
    across = np.arange(-side, side + step / 2, step)
    da, dc = (g.ravel() for g in np.meshgrid(along, across, indexing="ij"))
    world = truth.source[:2] + np.outer(da, truth.downwind) + np.outer(dc, truth.left)
    inside = np.all((world >= low[:2]) & (world <= high[:2]), axis=1)
    return da[inside], dc[inside], world[inside]


ZETA1 = (0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0)
"""m²/s, the diffusivities the model oracle weighs (the prior's mass lies at 0-4)."""
ZETA2 = (5.0, 8.0, 11.0)
"""s, the particle lifetimes it weighs (the prior: 8 ± 1.4)."""


def model_posterior(
    scenario,  # type: ignore[no-untyped-def]
    truth,  # type: ignore[no-untyped-def]
    positions: np.ndarray,
    readings: np.ndarray,
    step: float,
    reach: tuple[float, float, float],
    scales: tuple[float, ...] = (1.0,),
    meander_mixture: float = 0.0,
    gaussian: bool = False,
    gamma_intensity: float = 0.0,
    zetas: tuple[tuple[float, float], ...] | None = None,
) -> dict[str, float]:
    """The exact grid posterior of the estimator's own reading model (its plume and its
    fluctuation model, ``Scenario.make_plume`` and ``make_estimator_sensor``) over the release's
    horizontal offset δ and the model's ζ1, ζ2 (on the grids above, weighted by the prior),
    with the height, rate and wind known (the truth's); summaries as
    :func:`grid_summary`'s. What today's reading model could do with the search's readings
    if the filter found its exact posterior and the other parameters were known.

    With ``meander_mixture`` = i_z > 0, a probe of a fluctuating plume (Gifford 1959): the
    plume's centre height meanders, Gaussian with the standard deviation i_z · d at d m
    downwind (Taylor's short-range law), and a reading's likelihood is the mixture over it
    (five Gauss-Hermite nodes; heights below the ground reflected) instead of the likelihood
    at the time mean: a reading at the plume's upper fringe is then a rare burst, not a
    reliable weak signal.

    With ``gaussian``, the plume's shape is instead the Gaussian plume of the dispersion
    literature with Taylor's near-field growth, reflected at the ground (:func:`gaussian_plume`),
    its two intensities weighed on :data:`GAUSSIAN_IY` × :data:`GAUSSIAN_IZ` (equally likely):
    a shape chosen from textbooks, not from this plume.

    With ``gamma_intensity`` = i > 0, a probe of the fluctuation model: the reading is the
    instrument's model (``make_sensor``) given the held-averaged concentration, itself the
    model's time mean times a unit-mean gamma variate of standard deviation i
    (:func:`gamma_multipliers`), in place of the log-normal family with its fixed intermittency:
    the share of zero readings then grows where the mean is weak.

    ``zetas``: the (ζ1, ζ2) pairs weighed (None: :data:`ZETA1` × :data:`ZETA2`); one pair
    declares them known."""
    da, dc, world = candidate_grid(truth, scenario.volume.low, scenario.volume.high, step, reach)
    plume, sensor, prior = (
        scenario.make_plume(),
        scenario.make_sensor() if gamma_intensity > 0.0 else scenario.make_estimator_sensor(),
        scenario.make_prior(),
    )
    fluctuation = (
        list(zip(*gamma_multipliers(gamma_intensity), strict=True))
        if gamma_intensity > 0.0
        else [(1.0, 1.0)]
    )
    base = scenario.truth_theta()
    theta = np.tile(base, (len(da), 1))
    theta[:, :2] = world
    distance = np.linalg.norm(positions[None, :, :] - theta[:, None, :3], axis=2)
    log_post = []
    if zetas is None:
        zetas = tuple((z1, z2) for z1 in ZETA1 for z2 in ZETA2)
    for log_weight, per_node in _shapes(
        plume, prior, theta, positions, truth, meander_mixture, gaussian, zetas
    ):
        for scale in scales:  # the rate's factors, equally likely
            ll = logsumexp(
                [
                    math.log(wj * wg)
                    + sensor.log_likelihood(readings[None, :], scale * g * c, distance)
                    for wj, c in per_node
                    for wg, g in fluctuation
                ],
                axis=0,
            ).sum(axis=1)
            log_post.append(ll + log_weight)
    lp = np.stack(log_post)  # (combinations, N)
    w_all = np.exp(lp - logsumexp(lp))
    w = w_all.sum(axis=0)
    return grid_summary(w, da, dc)


GAUSSIAN_IY = (0.1, 0.15, 0.2, 0.3)
"""σ_y / d weighed by the Gaussian-plume probe (σ_v / u of a neutral to unstable surface layer)."""
GAUSSIAN_IZ = (0.05, 0.08, 0.12, 0.18)
"""σ_z / d weighed by it (σ_w / u near the ground: about 0.66 of the horizontal)."""
GAUSSIAN_SIGMA0 = 0.3
"""m, the spread at the release (a release of some size)."""


def gaussian_plume(
    theta: np.ndarray, positions: np.ndarray, downwind: np.ndarray, i_y: float, i_z: float
) -> np.ndarray:
    """(N, K) g/m³ of the Gaussian plume (Pasquill; Taylor's near field σ = √(σ0² + (i d)²))
    from sources θ (N, 8: x, y, z, q, u, …) at positions (K, 3), the wind blowing along
    ``downwind`` (2,), reflected at the ground z = 0; zero upwind of the source."""
    rel = positions[None, :, :2] - theta[:, None, :2]  # (N, K, 2)
    d = rel @ downwind
    y = rel @ np.array([-downwind[1], downwind[0]])
    dd = np.maximum(d, 0.0)
    sy = np.sqrt(GAUSSIAN_SIGMA0**2 + (i_y * dd) ** 2)
    sz = np.sqrt(GAUSSIAN_SIGMA0**2 + (i_z * dd) ** 2)
    h = theta[:, None, 2]
    z = positions[None, :, 2]
    vertical = np.exp(-0.5 * ((z - h) / sz) ** 2) + np.exp(-0.5 * ((z + h) / sz) ** 2)
    c = theta[:, None, 3] / (2 * np.pi * theta[:, None, 4] * sy * sz)
    return np.where(d > 0, c * np.exp(-0.5 * (y / sy) ** 2) * vertical, 0.0)


def _shapes(plume, prior, theta, positions, truth, meander_mixture: float, gaussian: bool, zetas):  # type: ignore[no-untyped-def]
    """Yield (log prior weight, [(node weight, (N, K) concentrations)]) for each shape setting
    the model posterior weighs (see :func:`model_posterior`)."""
    if gaussian:
        for i_y in GAUSSIAN_IY:
            for i_z in GAUSSIAN_IZ:
                yield 0.0, [(1.0, gaussian_plume(theta, positions, truth.downwind, i_y, i_z))]
        return
    for z1, z2 in zetas:
        th = theta.copy()
        th[:, 6], th[:, 7] = z1, z2
        if meander_mixture > 0.0:
            per_node = _meander_nodes(plume, th, positions, truth, meander_mixture)
        else:
            per_node = [(1.0, plume.concentration(th, positions))]  # (N, K)
        weight = float(prior.log_density(th[:1])[0]) if len(zetas) > 1 else 0.0
        yield weight, per_node


HERMITE_NODES = (0.0, -1.355626179974266, 1.355626179974266, -2.856970013872806, 2.856970013872806)
HERMITE_WEIGHTS = (0.5333333333333333, 0.2220759220056126, 0.2220759220056126,
                   0.011257411327720691, 0.011257411327720691)  # fmt: skip
"""Five-point Gauss-Hermite rule for a standard normal (probabilists')."""


def _meander_nodes(plume, theta: np.ndarray, positions: np.ndarray, truth, i_z: float):  # type: ignore[no-untyped-def]
    """[(weight, (N, K) concentrations)] with the release height moved by i_z · d · ξ at each
    node ξ, d the downwind distance from each candidate to each reading (0 upwind)."""
    out = []
    rel = positions[None, :, :2] - theta[:, None, :2]  # (N, K, 2)
    d = np.maximum(rel @ truth.downwind, 0.0)  # (N, K)
    for xi, wj in zip(HERMITE_NODES, HERMITE_WEIGHTS, strict=True):
        c = np.empty(d.shape)
        for k in range(len(positions)):
            th = theta.copy()
            th[:, 2] = np.abs(theta[:, 2] + i_z * d[:, k] * xi)  # the ground reflects
            c[:, k] = plume.concentration(th, positions[k : k + 1])[:, 0]
        out.append((wj, c))
    return out


GAMMA_NODES = 48
"""Equal-probability nodes of the unit-mean gamma distribution in :func:`gamma_multipliers`."""


def gamma_multipliers(intensity: float) -> tuple[np.ndarray, np.ndarray]:
    """(weights, multipliers) of a fluctuating concentration: the instantaneous (held-averaged)
    value is the time mean times a gamma variate of mean 1 and standard deviation
    ``intensity`` (the fluctuation intensity σ_c / C̄; Hanna 1984's exponential at 1, the
    clipped-gamma family of Yee & Chan 1997 without its clipping), discretised at
    :data:`GAMMA_NODES` mid-quantiles (equal weights)."""
    from scipy.stats import gamma

    shape = 1.0 / (intensity * intensity)
    q = (np.arange(GAMMA_NODES) + 0.5) / GAMMA_NODES
    return np.full(GAMMA_NODES, 1.0 / GAMMA_NODES), gamma.ppf(q, shape, scale=1.0 / shape)


def grid_summary(w: np.ndarray, da: np.ndarray, dc: np.ndarray) -> dict[str, float]:
    """Posterior summaries of grid weights ``w`` over offsets (``da``, ``dc``) m."""
    mean_a, mean_c = float(w @ da), float(w @ dc)
    order = np.argsort(-w)
    region = order[: int(np.searchsorted(np.cumsum(w[order]), 0.95)) + 1]
    truth_cell = int(np.argmin(da * da + dc * dc))
    return {
        "truth_in_95": bool(truth_cell in set(region.tolist())),
        "rmse": float(math.sqrt(w @ (da * da + dc * dc))),
        "error_along": mean_a,
        "error_across": mean_c,
        "sd_along": float(math.sqrt(max(w @ (da - mean_a) ** 2, 0.0))),
        "sd_across": float(math.sqrt(max(w @ (dc - mean_c) ** 2, 0.0))),
        "candidates": len(da),
    }


def filter_replay(scenario, truth, records: list[dict], particles: int, seed: int) -> dict:  # type: ignore[no-untyped-def]
    """The scenario's own filter (:func:`dcee.runs.make_searcher`, no planner) told a search's
    readings (``records``: x, y, z, reading, time) in order with ``particles`` particles;
    its final posterior over the release's horizontal offset summarised as
    :func:`grid_summary`'s (the 95 % region the Gaussian ellipse of its covariance)."""
    from dcee.estimation.summaries import weighted_moments
    from dcee.runs import make_searcher, streams

    scenario = scenario.with_overrides(**{"search.particles": particles})
    _, filter_rng, planner_rng, _ = streams(seed)
    searcher = make_searcher(scenario, None, filter_rng, planner_rng, on_robot=False)
    for r in records:
        searcher.tell(np.array([r["x"], r["y"], r["z"]]), float(r["reading"]), float(r["time"]))
    theta, w = searcher.filter.theta, searcher.filter.weights
    rel = theta[:, :2] - truth.source[:2]
    da, dc = rel @ truth.downwind, rel @ truth.left
    mean, cov = weighted_moments(np.column_stack([da, dc]), w)
    inside = float(mean @ np.linalg.solve(cov, mean)) <= 5.991  # χ²(2) at 95 %
    return grid_summary(w, da, dc) | {"truth_in_95": inside}
