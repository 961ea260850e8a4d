"""How well could any estimator place the source from a slice search's readings? An oracle
posterior on the readings that stored searches of a planar slice took (issue 78, the slice bar).

The oracle knows everything but the release's horizontal position: the plume's own statistics
(the truth's recording: every frame of the turbulent field, held-averaged over the reading's
window exactly as the simulation averages it), the release height, rate, wind speed and
direction, and the instrument's model. For each candidate offset δ of the release from the truth
(along and across the wind, on a ``--step`` m grid inside the search area) the likelihood of a
reading z taken at canonical position c is the stationary mixture over the recording's phases,

    p(z | δ) = (1/T) Σ_t p_sensor(z | A_t(c − δ)),

A_t the hold-averaged field ending at frame t, and the readings are taken as independent given
δ. That independence makes the oracle more certain than the readings allow (successive readings
share a turbulent state), so its RMSE is optimistic: no estimator that knows less (the
reading model's shape, the height, the rate, the wind unknown) can expect to do better on the
same readings. Its final RMSE √(Σ w |δ|²) is horizontal (the height is known to it); the
searches' own RMSE is 3-D with the height unknown.

Two weaker oracles tell where the information lies: ``--phases 0`` knows the plume's exact
time mean only and reads it through the estimator's own fluctuation model (the log-normal
family with its fixed intermittency and spread: ``Scenario.make_estimator_sensor``), the best
any reading model of today's form could do with the true shape; ``--rate-unknown`` does not
know the release rate (nine factors from 1/4 to 4, equally likely, marginalised).

Probes on the same readings: ``--reading-model`` (today's reading model's exact posterior, with
``--meander-mixture``, ``--gaussian`` or ``--gamma`` changing its shape or fluctuations),
``--gamma`` on the exact time mean (a published fluctuation family), ``--known-environment``
(the height, wind and ζ declared known), ``--filter-replay N`` (not an oracle: ``dcee-cl``'s own
filter told the readings, to compare with its model's exact posterior), and two summaries that
are not posteriors, ``--zeros`` and ``--tails``. The recipe ``lbm3d-slice-oracle`` runs them all.

    .venv/bin/python studies/slice_oracle.py results/lbm3d-slice-tune-oracle \\
        --json docs/results/lbm3d-slice-oracle/oracle.json

Diagnostic on a tuning range only: nothing is chosen from it.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import sys
from pathlib import Path

import numpy as np
from scipy.ndimage import map_coordinates
from scipy.special import logsumexp

from dcee.analysis.report import load_campaign
from dcee.provenance import code_version
from dcee.runs import EpisodeResult
from dcee.scenarios import validate_scenario
from dcee.simulation import make_truth

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:  # run as a script: the studies package sits beside it
    sys.path.insert(0, str(ROOT))

from studies.slice_models import (  # noqa: E402
    candidate_grid,
    filter_replay,
    gamma_multipliers,
    grid_summary,
    model_posterior,
)


def _inner(truth):  # type: ignore[no-untyped-def]
    """The lbm3d truth under any wrapper (injected spikes)."""
    while hasattr(truth, "inner"):
        truth = truth.inner
    return truth


def held_averages(truth, average: float, response_time: float) -> np.ndarray:  # type: ignore[no-untyped-def]
    """(T, ny, nx) g/m³: the plane's field at the truth's canonical height, averaged over the
    ``average`` s window ending at each frame (looped), through the first-order response as
    :meth:`dcee.simulation.truth.TruthModel.sensed` applies it, times the truth's scale."""
    rec = truth.recording
    height = truth.plane - truth.ground + truth.lift
    iz = int(np.clip(np.searchsorted(rec.z, height) - 1, 0, len(rec.z) - 2))
    fz = float(np.clip((height - rec.z[iz]) / (rec.z[iz + 1] - rec.z[iz]), 0.0, 1.0))
    plane = (1.0 - fz) * rec.values[..., iz] + fz * rec.values[..., iz + 1]  # (T, ny, nx)
    dt = truth.time_step  # episode s between frames
    n = max(1, round(average / dt)) if average > 0 else 1
    windows = np.stack([np.roll(plane, k, axis=0) for k in range(n - 1, -1, -1)])  # oldest first
    if response_time > 0.0:
        alpha = 1.0 - math.exp(-dt / response_time)
        y = windows[0].copy()
        for k in range(n):
            y += alpha * (windows[k] - y)
            windows[k] = y
    return windows.mean(axis=0) * truth.scale


def oracle_posterior(
    truth,  # type: ignore[no-untyped-def]
    sensor,  # type: ignore[no-untyped-def]
    fields: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    step: float,
    reach: tuple[float, float, float],
    phases: int,
    scales: tuple[float, ...] = (1.0,),
    gamma_intensity: float = 0.0,
) -> dict[str, float]:
    """The oracle's posterior over the release's horizontal offset δ (along, across the wind)
    given readings (K,) at positions (K, 3); summaries in m. With several ``scales`` (factors
    on the release rate, equally likely) the rate is unknown to it and marginalised."""
    rec = truth.recording
    da, dc, _ = candidate_grid(truth, low, high, step, reach)
    if gamma_intensity > 0.0:  # the time mean times gamma fluctuations (gamma_multipliers)
        sub = fields.mean(axis=0)[None] * gamma_multipliers(gamma_intensity)[1][:, None, None]
    elif phases == 0:  # the time mean alone (the reading model's view: its own fluctuations)
        sub = fields.mean(axis=0, keepdims=True)
    else:
        sub = fields[np.linspace(0, len(fields) - 1, min(phases, len(fields))).round().astype(int)]
    frames = np.arange(len(sub))
    canon = truth.canonical(positions)
    height_gap = float(truth.plane - truth.source[2])  # the plane above the release, m
    x_step = rec.x[1] - rec.x[0]
    y_step = rec.y[1] - rec.y[0]
    log_post = np.zeros((len(scales), len(da)))
    for (cx, cy, _), z in zip(canon, readings, strict=True):
        px, py = cx - da, cy - dc  # the reading relative to each candidate, canonical m
        ix = (px - rec.x[0]) / x_step
        iy = (py - rec.y[0]) / y_step
        coords = np.stack(
            [
                np.repeat(np.arange(len(frames), dtype=np.float64), len(da)),
                np.tile(iy, len(frames)),
                np.tile(ix, len(frames)),
            ]
        )
        c = map_coordinates(sub, coords, order=1, mode="constant", cval=0.0)
        distance = np.tile(np.sqrt(px * px + py * py + height_gap * height_gap), len(frames))
        for k, scale in enumerate(scales):
            ll = sensor.log_likelihood(float(z), scale * c, distance)
            log_post[k] += logsumexp(ll.reshape(len(frames), len(da)), axis=0)
    log_post = logsumexp(log_post, axis=0)  # the rate marginalised (a constant dropped)
    return grid_summary(np.exp(log_post - logsumexp(log_post)), da, dc)


ZERO_BINS = (1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2)
"""g/m³: the time-mean classes of :func:`zero_shares`."""


def zero_shares(scenario, fields: np.ndarray) -> list[dict[str, float]]:  # type: ignore[no-untyped-def]
    """Per class of the plane's time-mean concentration (:data:`ZERO_BINS`): the cells, the
    share of held averages below the threshold (what the truth gives) and the estimator's
    probability of a non-detection at that mean (what its fluctuation model says), over every
    stored cell of the plane."""
    sensor = scenario.make_estimator_sensor()
    mean = fields.mean(axis=0).ravel()
    below = (fields < sensor.threshold).mean(axis=0).ravel()
    out = []
    for lo, hi in itertools.pairwise(ZERO_BINS):
        m = (mean >= lo) & (mean < hi)
        if not m.any():
            continue
        model = np.exp(sensor.log_likelihood(0.0, mean[m], np.inf))
        out.append(
            {
                "low": lo,
                "high": hi,
                "cells": int(m.sum()),
                "truth_zero_share": float(below[m].mean()),
                "model_zero_probability": float(model.mean()),
            }
        )
    return out


PROFILE_DISTANCES = (2.0, 5.0, 10.0, 20.0)
"""m downwind of the release at which :func:`vertical_tails` compares the profiles."""


def vertical_tails(truth) -> dict:  # type: ignore[no-untyped-def]
    """How much gas the plane holds above the release against a Gaussian profile of the same
    spread: at each of :data:`PROFILE_DISTANCES` on the time mean's centreline (y = 0), the
    ratio of the plane's concentration to the release height's, the section's centroid z̄ and
    spread σ_z about it (m), and the ratio a Gaussian profile of that centroid and spread gives,
    exp(−(z_p − z̄)² / 2σ_z²) / exp(−(h − z̄)² / 2σ_z²). A plume whose tail above it is heavier
    than a Gaussian's sends gas to the plane near the release, where a Gaussian reading model
    sends none and explains it by a release further upwind."""
    rec = truth.recording
    mean = rec.values.mean(axis=0)  # (ny, nx, nz)
    iy = int(np.argmin(np.abs(rec.y)))
    release = truth.source[2] - truth.ground + truth.lift  # canonical m (the cell's centre)
    plane = truth.plane - truth.ground + truth.lift
    rows = []
    for d in PROFILE_DISTANCES:
        ix = int(np.argmin(np.abs(rec.x - d)))
        column = mean[iy, ix, :]
        zbar = float(column @ rec.z / column.sum())
        sz = float(math.sqrt(column @ (rec.z - zbar) ** 2 / column.sum()))
        at_plane, at_release = np.interp([plane, release], rec.z, column)
        gauss = math.exp(-0.5 * ((plane - zbar) / sz) ** 2 + 0.5 * ((release - zbar) / sz) ** 2)
        rows.append(
            {
                "distance": d,
                "centroid": zbar,
                "sigma_z": sz,
                "plane_over_release": float(at_plane / at_release),
                "gaussian_plane_over_release": gauss,
            }
        )
    return {"release": float(release), "plane": float(plane), "sections": rows}


REACH = (30.0, 15.0, 10.0)
"""m: the candidates reach this far upwind of the release, downwind of it and across the wind."""


def _row(run, result, post: dict[str, float]) -> dict:  # type: ignore[no-untyped-def]
    s = result.summary
    print(
        f"{s['scenario']:>12} {run['strategy']}: search {s['final_rmse']:.2f} m, oracle "
        f"{post['rmse']:.2f} m (sd along {post['sd_along']:.2f}, across "
        f"{post['sd_across']:.2f}; error along {post['error_along']:+.2f} m), "
        f"{s['detections']} detections",
        flush=True,
    )
    return {
        "scenario": s["scenario"],
        "strategy": run["strategy"],
        "seed": int(run["seed"]),
        "readings": len(result.records),
        "detections": int(s["detections"]),
        "search_final_rmse": float(s["final_rmse"]),
        "oracle": post,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign", help="a bench folder of planar lbm3d slice searches")
    ap.add_argument("--json", required=True, help="where to write the per-search results")
    ap.add_argument("--step", type=float, default=0.25, help="m, the candidates' grid")
    ap.add_argument(
        "--phases",
        type=int,
        default=120,
        help="recording phases in the mixture; 0: the time-mean field read through the "
        "estimator's own fluctuation model instead (the reading model's noise, the true shape)",
    )
    ap.add_argument(
        "--rate-unknown",
        action="store_true",
        help="the release rate unknown to the oracle: 9 factors from 1/4 to 4, equally likely",
    )
    ap.add_argument(
        "--reading-model",
        action="store_true",
        help="the exact grid posterior of today's reading model instead (model_posterior)",
    )
    ap.add_argument(
        "--meander-mixture",
        type=float,
        default=0.0,
        help="with --reading-model: the vertical meander's intensity i_z of a fluctuating-plume "
        "likelihood (model_posterior); 0: today's likelihood at the time mean",
    )
    ap.add_argument(
        "--gaussian",
        action="store_true",
        help="with --reading-model: a Gaussian plume with Taylor's near-field growth in place "
        "of today's plume (gaussian_plume)",
    )
    ap.add_argument(
        "--gamma",
        type=float,
        default=0.0,
        help="a probe of the fluctuation model: the time mean (the exact one, or with "
        "--reading-model the model's) times gamma fluctuations of this intensity σ_c / C̄, read "
        "through the instrument's model (gamma_multipliers)",
    )
    ap.add_argument(
        "--known-environment",
        action="store_true",
        help="the source height, the wind and ζ1, ζ2 declared known (the scenario's values: "
        "unknown = source, dimensions = 2); with --reading-model its ζ grid is the one pair",
    )
    ap.add_argument(
        "--filter-replay",
        type=int,
        default=0,
        help="instead of an oracle: the scenario's own filter with this many particles told "
        "each search's readings (filter_replay); with --known-environment the filter's too",
    )
    ap.add_argument(
        "--replay-set",
        action="append",
        default=[],
        metavar="PATH=VALUE",
        help="with --filter-replay: a scenario setting for the replayed filter (a number), e.g. "
        "estimator.reading_weight=1; repeatable",
    )
    ap.add_argument(
        "--tails",
        action="store_true",
        help="instead of posteriors: the plane's gas against a Gaussian profile's, once per "
        "recording (vertical_tails)",
    )
    ap.add_argument(
        "--zeros",
        action="store_true",
        help="instead of posteriors: the share of zero readings by time-mean class, the truth's "
        "against the estimator's fluctuation model (zero_shares)",
    )
    args = ap.parse_args()
    scales = (
        tuple(np.exp(np.linspace(math.log(0.25), math.log(4.0), 9)).tolist())
        if args.rate_unknown
        else (1.0,)
    )
    _, runs = load_campaign(Path(args.campaign))
    rows = []
    for _, run in runs.sort_values(["scenario", "strategy"]).iterrows():
        config = json.loads((Path(run["run_dir"]) / "config.json").read_text())
        scenario = validate_scenario(config["scenario"])
        truth = _inner(make_truth(scenario, int(run["seed"])))
        if getattr(truth, "plane", None) is None:
            raise SystemExit(f"{run['run_dir']}: not a planar lbm3d slice")
        if args.tails:
            tails = vertical_tails(truth)
            if all(tails["release"] != r["release"] for r in rows):
                rows.append(tails)
            continue
        result = EpisodeResult.load(run["run_dir"])
        rec = result.records
        positions = np.array([[r["x"], r["y"], r["z"]] for r in rec])
        readings = np.array([r["reading"] for r in rec])
        if args.known_environment:
            scenario = scenario.with_overrides(unknown="source", dimensions=2)
        if args.filter_replay:
            changes = {k: float(v) for k, v in (s.split("=", 1) for s in args.replay_set)}
            replayed = scenario.with_overrides(**changes)
            post = filter_replay(replayed, truth, rec, args.filter_replay, int(run["seed"]))
            rows.append(_row(run, result, post))
            continue
        if args.reading_model:
            theta0 = scenario.truth_theta()
            post = model_posterior(
                scenario,
                truth,
                positions,
                readings,
                args.step,
                REACH,
                scales,
                args.meander_mixture,
                args.gaussian,
                args.gamma,
                ((float(theta0[6]), float(theta0[7])),) if args.known_environment else None,
            )
            rows.append(_row(run, result, post))
            continue
        fields = held_averages(truth, scenario.average, scenario.sensor.response_time)
        if args.zeros:
            rows.append({"scenario": run["scenario"], "zeros": zero_shares(scenario, fields)})
            continue
        post = oracle_posterior(
            truth,
            scenario.make_sensor()
            if args.phases > 0 or args.gamma > 0
            else scenario.make_estimator_sensor(),
            fields,
            positions,
            readings,
            scenario.volume.low,
            scenario.volume.high,
            args.step,
            REACH,
            args.phases,
            scales,
            args.gamma,
        )
        rows.append(_row(run, result, post))
    if args.zeros or args.tails:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        what = (zero_shares if args.zeros else vertical_tails).__doc__
        key = "searches" if args.zeros else "recordings"
        doc = {"what": what, "code": code_version(), key: rows}
        Path(args.json).write_text(json.dumps(doc, indent=1))
        return
    oracle = np.array([r["oracle"]["rmse"] for r in rows])
    out = {
        "what": __doc__.split("\n\n")[0],
        "campaign": str(args.campaign),
        "step": args.step,
        "phases": args.phases,
        "rate_unknown": bool(args.rate_unknown),
        "reading_model": bool(args.reading_model),
        "meander_mixture": args.meander_mixture,
        "gaussian": bool(args.gaussian),
        "gamma": args.gamma,
        "known_environment": bool(args.known_environment),
        "filter_replay": args.filter_replay,
        "replay_set": args.replay_set,
        "code": code_version(),
        "median_oracle_rmse": float(np.median(oracle)),
        "oracle_within_1m": int((oracle <= 1.0).sum()),
        "median_search_rmse": float(np.median([r["search_final_rmse"] for r in rows])),
        "searches": rows,
    }
    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    Path(args.json).write_text(json.dumps(out, indent=1))
    print(
        f"median oracle RMSE {out['median_oracle_rmse']:.2f} m ({out['oracle_within_1m']}/"
        f"{len(rows)} within 1 m); the searches' {out['median_search_rmse']:.2f} m"
    )


if __name__ == "__main__":
    main()
