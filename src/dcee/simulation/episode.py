"""One simulated search: truth → sensor noise → reading → Searcher.tell → Searcher.ask → move.

Random streams: ``SeedSequence(seed)`` is split into a *truth* stream (sensor noise of the real
readings), an *agent* stream (split again into filter and planner) and a *figures* stream
(particle subsamples for plots only); child 3 of the seed drives a stochastic truth such as the
filament plume (:func:`dcee.simulation.truth.plume_stream`). The truth stream draws the same
numbers at every step whatever the agent does, so two strategies run with the same seed see
identical truth noise (common random numbers).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from dcee.estimation.model_bank import ModelBank
from dcee.estimation.particle_filter import ParticleFilter, UpdateInfo
from dcee.io import write_atomic, write_json
from dcee.models.sensor import Sensor
from dcee.planning import get as get_planner
from dcee.planning.base import Planner, planner_class
from dcee.planning.team import check_team_planner
from dcee.provenance import code_version
from dcee.scenarios.config import Scenario
from dcee.searcher import Searcher
from dcee.simulation.metrics import summarise
from dcee.simulation.truth import TruthModel, make_truth

SNAPSHOT_FRACTIONS = (0.1, 0.3, 0.5, 1.0)
"""When a saved search keeps particle snapshots, as fractions of its budget (the paper's figure 4
shows 90, 270, 450 and 900 s of a 900 s search). Derived from the budget, so a 60 s search has
snapshots too."""
FINAL_SAMPLE = 2000
"""Particles kept from a saved search's final posterior (drawn by weight, every parameter)."""
SNAPSHOT_SAMPLE = 1000
"""Particles kept per saved snapshot (source locations only)."""
RESULT_FILES = ("summary.json", "config.json", "steps.parquet", "posterior.npz")
"""The files of a saved search. ``summary.json`` is written last and marks it complete."""


def snapshot_times(budget: float) -> tuple[float, ...]:
    """The snapshot times (s) of a search with this budget: :data:`SNAPSHOT_FRACTIONS` of it."""
    return tuple(round(f * budget, 6) for f in SNAPSHOT_FRACTIONS)


@dataclass
class EpisodeResult:
    """Per-step records (list of dicts, one per reading), the summary, the final particles
    (N, 8) with every parameter (known ones included) and their weights (N,), and optional
    snapshots of the particles' source locations for figures: list of (time, (n, 3) array)."""

    records: list[dict[str, Any]]
    summary: dict[str, Any]
    final_theta: np.ndarray
    final_weights: np.ndarray
    snapshots: list[tuple[float, np.ndarray]] = field(default_factory=list)
    config: dict[str, Any] | None = None
    """What made it: ``{"scenario": resolved scenario, "strategy", "seed", "planner_options",
    "code"}`` (set by :func:`run_episode` and by :meth:`load`)."""

    def save(self, folder: str | Path, keep_snapshots: bool = True) -> Path:
        """Write the search to ``folder`` (created): ``steps.parquet`` (one row per reading),
        ``posterior.npz`` (``final_particles`` (n, 8) float32, :data:`FINAL_SAMPLE` draws by
        weight from the final posterior with every parameter; with ``keep_snapshots``,
        ``snapshot_times`` (k,) s and ``snapshot_particles`` (k, m, 3) source locations),
        ``config.json`` and ``summary.json`` (last: its presence marks a complete result).
        Every file is written atomically. The same layout serves ``dcee run`` and every search
        of a campaign; :meth:`load` reads it back."""
        import pandas as pd

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "summary.json").unlink(missing_ok=True)  # incomplete until rewritten
        for name in RESULT_FILES:  # temporaries of a writer killed mid-file (dcee.io)
            for leftover in folder.glob(f".{name}.*"):
                leftover.unlink(missing_ok=True)
        config = self.config or {}
        seed = int(self.summary.get("seed", 0))
        records = pd.DataFrame.from_records(self.records)
        w = self.final_weights / self.final_weights.sum()
        idx = np.random.default_rng(seed).choice(len(w), size=min(FINAL_SAMPLE, len(w)), p=w)
        arrays: dict[str, np.ndarray] = {
            "final_particles": self.final_theta[idx].astype(np.float32)
        }
        snapshots = self._standard_snapshots() if keep_snapshots else []
        if snapshots:
            arrays["snapshot_times"] = np.array([t for t, _ in snapshots])
            arrays["snapshot_particles"] = np.stack(
                [p[:SNAPSHOT_SAMPLE].astype(np.float32) for _, p in snapshots]
            )
        write_atomic(folder / "steps.parquet", lambda p: records.to_parquet(p, index=False))
        write_atomic(folder / "posterior.npz", lambda p: _savez(p, arrays))
        write_json(folder / "config.json", config)
        summary = {"code": code_version(), **self.summary}  # run_episode already set it
        summary.update(record_rows=len(records), final_sample=len(idx))
        write_json(folder / "summary.json", summary)
        return folder

    def _standard_snapshots(self) -> list[tuple[float, np.ndarray]]:
        """The snapshots at :func:`snapshot_times` of the budget (the first taken at or after
        each) and the last one: what a saved search keeps, whatever else was taken (an
        animation takes 41), so every saved search has the same comparison-grid columns."""
        if not self.snapshots:
            return []
        budget = float(self.summary.get("budget", self.snapshots[-1][0]))
        keep = {len(self.snapshots) - 1}
        for target in snapshot_times(budget):
            k = next((i for i, (t, _) in enumerate(self.snapshots) if t >= target - 1e-9), None)
            if k is not None:
                keep.add(k)
        return [self.snapshots[i] for i in sorted(keep)]

    @staticmethod
    def is_complete(folder: str | Path) -> bool:
        """True when ``folder`` holds a complete saved search: the summary parses, and the record
        and posterior files exist with the row and particle counts it names."""
        folder = Path(folder)
        try:
            summary = json.loads((folder / "summary.json").read_text())
            import pyarrow.parquet as pq

            rows = pq.ParquetFile(folder / "steps.parquet").metadata.num_rows
            with np.load(folder / "posterior.npz") as z:
                n_final = z["final_particles"].shape[0]
            json.loads((folder / "config.json").read_text())
        except Exception:  # missing, truncated or corrupt
            return False
        return rows == summary.get("record_rows") and n_final == summary.get("final_sample")

    @classmethod
    def load(cls, folder: str | Path) -> EpisodeResult:
        """Read a search written by :meth:`save`. ``final_theta`` is the saved sample of the
        final posterior (equal weights); ``records`` one dict per reading."""
        import pandas as pd

        from dcee.errors import DceeInputError

        folder = Path(folder)
        if not cls.is_complete(folder):
            raise DceeInputError("results", f"{folder} holds no complete dcee search result")
        summary = json.loads((folder / "summary.json").read_text())
        config = json.loads((folder / "config.json").read_text())
        records = pd.read_parquet(folder / "steps.parquet").to_dict("records")
        with np.load(folder / "posterior.npz") as z:
            final = z["final_particles"].astype(np.float64)
            snaps = []
            if "snapshot_times" in z:
                snaps = [
                    (float(t), p.astype(np.float64))
                    for t, p in zip(z["snapshot_times"], z["snapshot_particles"], strict=True)
                ]
        weights = np.full(len(final), 1.0 / len(final))
        return cls(records, summary, final, weights, snaps, config)


def _savez(path: Path, arrays: dict[str, np.ndarray]) -> None:
    with open(path, "wb") as f:  # a file object: np.savez would append .npz to a path
        np.savez_compressed(f, **arrays)


def streams(seed: int) -> tuple[np.random.Generator, ...]:
    """(truth, filter, planner, figures) generators derived from one seed. The figures stream
    only subsamples particles for plots, so plotting never changes a search."""
    truth_ss, agent_ss, figure_ss = np.random.SeedSequence(seed).spawn(3)
    filter_ss, planner_ss = agent_ss.spawn(2)
    return tuple(np.random.default_rng(s) for s in (truth_ss, filter_ss, planner_ss, figure_ss))


MOTION_STREAM = 4
"""Child of the seed that draws the localisation errors (children 0-2 are :func:`streams`, 3 the
stochastic truth's), so adding localisation noise changes no other draw."""


def motion_stream(seed: int) -> np.random.Generator:
    """The generator of the robots' localisation errors for episode ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(MOTION_STREAM,)))


def make_searcher(
    scenario: Scenario,
    planner: Planner | None,
    filter_rng: np.random.Generator,
    planner_rng: np.random.Generator,
) -> Searcher:
    """The scenario's filter (prior, estimator reading model, plume model, scale) and
    ``planner`` in a :class:`~dcee.searcher.Searcher`; the simulation, the ROS node and
    ``dcee replay`` build theirs here (with the generators of :func:`streams`)."""
    search = scenario.search
    models = scenario.reading_models
    # the first (preferred) model draws from filter_rng itself, as a lone filter does; the others
    # from children of it (spawning does not move filter_rng). So a second model changes nothing
    # while it is not selected, and comparisons with and without it are paired exactly.
    rngs = [filter_rng, *filter_rng.spawn(len(models) - 1)]
    filters = [
        ParticleFilter(
            scenario.make_prior(),
            scenario.make_estimator_sensor(model),  # the reading model of filter and planners
            scenario.make_plume(model),
            n_particles=search.particles,
            seed=rng,
            resample_threshold=search.resample_threshold,
            mcmc_steps=search.mcmc_steps,
            global_share=search.global_share,
            diversify=search.diversify,
            max_sweeps=search.max_sweeps,
            reading_weight=scenario.reading_weight,
        )
        for model, rng in zip(models, rngs, strict=True)
    ]
    estimator = (
        filters[0]
        if len(filters) == 1
        else ModelBank(filters, models, scenario.reading_model_priors)
    )
    return Searcher(
        estimator,
        planner,
        scenario.make_agent(),
        planner_rng,
        stall_guard=search.stall_guard,
        guard_spread=search.acquired_rmse,
    )


def reading_record(
    searcher: Searcher,
    info: UpdateInfo,
    *,
    step: int,
    robot: int,
    time: float,
    position: np.ndarray,
    told: np.ndarray,
    reading: float,
    detection: bool,
    true_location: np.ndarray | None,
    heading: float,
    travel_time: float,
    true_concentration: float = math.nan,
) -> dict[str, Any]:
    """One row of a search's per-reading record (``steps.parquet``), made after ``searcher``
    assimilated ``reading`` (g/m³) taken at ``position`` (3,) m (told as ``told``): the
    posterior summary and the filter's diagnostics. ``true_location`` (3,) m gives the RMSE
    and the error of the mean (NaN without one); ``heading`` in °; ``travel_time`` s of the
    drive before the reading. The simulation, the ROS node and ``dcee replay`` all use it."""
    est = searcher.estimate()
    pf = searcher.filter
    if true_location is None:
        rmse = mean_error = math.nan
    else:
        rmse = pf.rmse(true_location)
        mean_error = float(np.linalg.norm(est.mean - true_location))
    return {
        "step": step,
        "robot": robot,
        "time": time,
        "x": position[0],
        "y": position[1],
        "z": position[2],
        "heading": heading,
        "told_x": told[0],
        "told_y": told[1],
        "travel_time": travel_time,
        "true_concentration": true_concentration,
        "reading": reading,
        "detection": detection,
        "mean_x": est.mean[0],
        "mean_y": est.mean[1],
        "mean_z": est.mean[2],
        **{
            f"cov_{a}{b}": est.cov[i, j]
            for i, a in enumerate("xyz")
            for j, b in enumerate("xyz")
            if j >= i
        },
        "spread": est.spread,
        "rmse": rmse,
        "mean_error": mean_error,
        "ess": info.ess,
        "resampled": info.resampled,
        "tempering_stages": info.tempering_stages,
        "acceptance": info.acceptance,
        "move_sweeps": info.move_sweeps,
        "distinct": info.distinct,
        "rejected": info.rejected,
        "update_seconds": searcher.last_update_seconds,
        "decision_seconds": 0.0,
        "log_evidence": pf.log_evidence,
        **(
            {"model": pf.selected_name, "model_probability": pf.selected_probability}
            if isinstance(pf, ModelBank)
            else {}
        ),
    }


class SearchSimulation:
    """One simulated search, a step at a time: the world (truth, instrument, robots' move
    model) and the filter, without a planner. :func:`run_episode` drives it with a planner; the
    Gymnasium and PettingZoo environments (:mod:`dcee.gym`) with a policy's actions. All
    therefore make the same readings and the same records for the same seed and moves.

    ``sense()`` takes every robot's reading at its current position and the current time,
    assimilates them into the one shared filter (robot 0 first) and appends one record per
    reading (:attr:`records`, with its ``robot``); ``move(waypoints)`` drives the robots to
    their next waypoints (:attr:`motion`), the readings follow one hold after the slowest has
    settled; ``finished`` says when no further move fits the budget (or the scenario's
    ``stop_spread`` is reached). The scenario's ``agent.count``
    sets the number of robots (:meth:`~dcee.scenarios.config.Scenario.starts`).
    """

    def __init__(
        self,
        scenario: Scenario,
        seed: int,
        planner: Planner | None = None,
        truth: TruthModel | None = None,
    ) -> None:
        self.scenario = scenario
        self.seed = int(seed)
        truth_rng, filter_rng, planner_rng, self.figure_rng = streams(seed)
        self._truth_rng = truth_rng
        self.sensor: Sensor = scenario.make_sensor()  # the instrument: makes the real readings
        self.truth = truth or make_truth(scenario, seed)
        self.true_location = scenario.truth_theta()[:3]
        self.searcher = make_searcher(scenario, planner, filter_rng, planner_rng)
        self.agent = self.searcher.agent
        self.filter = self.searcher.filter
        self.motion = scenario.make_motion()
        self._motion_rng = motion_stream(seed)
        self.positions = scenario.starts()  # (K, 3) true positions
        self.headings = np.full(len(self.positions), math.radians(scenario.agent.heading))
        self.time = self.agent.dwell  # the first reading is taken at the start after one dwell
        self.travel_time = 0.0  # s, the last move's drive (the slowest robot's)
        self.records: list[dict[str, Any]] = []
        self.path_length = 0.0

    @property
    def position(self) -> np.ndarray:
        """(3,) robot 0's position, m (the only robot's, in a single-robot search)."""
        return self.positions[0]

    def sense(self) -> list[dict[str, Any]]:
        """Take, assimilate and record every robot's reading at the current time; returns the
        step's records, one per robot."""
        return [self._sense_one(k) for k in range(len(self.positions))]

    def _sense_one(self, robot: int) -> dict[str, Any]:
        scenario, t = self.scenario, self.time
        position = self.positions[robot].copy()
        # the same count of noise draws per step, whatever the positions
        noise = self.sensor.draw_noise(self._truth_rng, ())
        conc = self.truth.sensed(position, t, scenario.average, scenario.sensor.response_time)
        reading = self.truth.reported(float(self.sensor.simulate_from(conc, noise)), conc, t)
        told = position.copy()  # where the robot believes it is
        sd = self.scenario.agent.localisation_sd
        if sd > 0:
            told[:2] += sd * self._motion_rng.standard_normal(2)
            told[:2] = np.clip(
                told[:2], self.scenario.volume.low[:2], self.scenario.volume.high[:2]
            )
        info = self.searcher.tell(told, reading, t)
        rec = reading_record(
            self.searcher,
            info,
            step=len(self.records) // len(self.positions),
            robot=robot,
            time=t,
            position=position,
            told=told,
            reading=reading,
            detection=bool(self.sensor.is_detection(reading)),
            true_location=self.true_location,
            heading=math.degrees(self.headings[robot]),
            travel_time=self.travel_time,
            true_concentration=conc,
        )
        self.records.append(rec)
        return rec

    @property
    def finished(self) -> bool:
        """True when no further move can fit the budget (the fastest possible drive plus the
        hold), or the posterior spread fell below the scenario's ``stop_spread``."""
        search = self.scenario.search
        shortest = self.motion.shortest_move_time(self.agent.step) + self.agent.dwell
        return self.time + shortest > search.budget + 1e-9 or (
            search.stop_spread > 0
            and bool(self.records)
            and self.records[-1]["spread"] < search.stop_spread
        )

    @property
    def over_budget(self) -> bool:
        """True when the last move ended after the budget (a drive slower than the fastest
        possible one): its readings are not taken."""
        return self.time > self.scenario.search.budget + 1e-9

    def move(self, waypoints: np.ndarray) -> None:
        """Drive the robots to ``waypoints`` (K, 3) m (a (3,) waypoint for one robot) with the
        scenario's motion model (:mod:`dcee.models.motion`); they move together and the next
        readings are taken when the slowest has settled and held ``agent.dwell`` s."""
        waypoints = np.asarray(waypoints, dtype=np.float64).reshape(self.positions.shape)
        new = waypoints.copy()
        durations = []
        for k, (p, goal) in enumerate(zip(self.positions, waypoints, strict=True)):
            travel = self.motion.travel((p[0], p[1], self.headings[k]), goal)
            new[k, 0], new[k, 1], self.headings[k] = travel.pose
            durations.append(travel.duration)
            steps = np.diff(travel.path[:, 1:3], axis=0)
            self.path_length += float(np.hypot(steps[:, 0], steps[:, 1]).sum())
        self.positions = new
        self.travel_time = max(durations)
        self.time += self.travel_time + self.agent.dwell

    def summary(self, strategy: str) -> dict[str, Any]:
        """The search's summary (:func:`search_summary`) under the name ``strategy``."""
        return search_summary(
            self.records, self.scenario, strategy, self.seed, self.path_length, self.searcher
        )


def search_summary(
    records: list[dict[str, Any]],
    scenario: Scenario,
    strategy: str,
    seed: int,
    path_length: float,
    searcher: Searcher,
) -> dict[str, Any]:
    """A search's summary: :func:`dcee.simulation.metrics.summarise` of its ``records``, the
    planner's options and the filter's diagnostics (recoveries, calibration against the
    scenario's true source, resamplings) and the scenario's resolved settings. The simulation,
    ``dcee replay`` and the ROS demo all summarise through it."""
    pf = searcher.filter
    out = summarise(records, scenario, strategy, seed, path_length)
    planner = searcher.planner
    out["planner_options"] = planner.options() if planner is not None else {}
    out["recoveries"] = len(pf.recoveries)
    out["tempering_events"] = sum(r["kind"] == "tempering" for r in pf.recoveries)
    out["rejected_readings"] = sum(r["kind"] == "rejected" for r in pf.recoveries)
    out["truth_in_95"] = pf.in_credible_region(scenario.truth_theta()[:3], 0.95)
    out.update(scenario.resolved_settings())
    out["resamples"] = pf.n_resamples
    out["stall_guard_fired"] = searcher.guard_fired  # decisions the stall guard restricted
    if isinstance(pf, ModelBank):  # which reading model the readings chose, and how firmly
        out["model"] = pf.selected_name
        out["model_probability"] = pf.selected_probability
        out["model_switches"] = pf.switches
    out["config"] = scenario.name
    out["parameter_names"] = list(scenario.unknown_names)
    return out


def run_episode(
    scenario: Scenario,
    strategy: str,
    seed: int,
    planner_options: dict[str, Any] | None = None,
    truth: TruthModel | None = None,
    progress: Callable[[float, dict[str, Any]], None] | None = None,
    snapshot_at: Sequence[float] | None = None,
    snapshot_particles: int = 2000,
) -> EpisodeResult:
    """Fly one search until the budget is spent (or the posterior spread < ``stop_spread``).

    ``snapshot_at``: times (s) at which to keep a weighted subsample of ``snapshot_particles``
    source locations (at the first reading at or after each time; the last reading always, when
    any are asked for), e.g. :func:`snapshot_times` of the budget, or a dense grid for an
    animation. The subsamples come from their own random stream: they never change the search.
    """
    planner = get_planner(strategy, **planner_defaults(strategy, scenario, planner_options))
    sim = SearchSimulation(scenario, seed, planner, truth)
    pf, searcher = sim.filter, sim.searcher
    snapshots: list[tuple[float, np.ndarray]] = []
    pending = sorted(snapshot_at) if snapshot_at is not None else []
    team = scenario.agent.count > 1
    if team:
        check_team_planner(planner)
    while True:
        rec = sim.sense()[-1]
        t = sim.time
        if pending and t >= pending[0] - 1e-9:
            snapshots.append((t, _subsample(pf, snapshot_particles, sim.figure_rng)))
            while pending and t >= pending[0] - 1e-9:
                pending.pop(0)
        if sim.finished:
            waypoint = None
        else:
            waypoint = searcher.ask_team(sim.positions) if team else searcher.ask()
        if waypoint is not None:
            rec["decision_seconds"] = searcher.last_decision_seconds
        if progress:
            progress(t, rec)
        if waypoint is None:
            break
        sim.move(waypoint)
        if sim.over_budget:
            break
    records = sim.records
    summary = sim.summary(strategy)
    if snapshot_at is not None and (not snapshots or snapshots[-1][0] != records[-1]["time"]):
        snapshots.append((records[-1]["time"], _subsample(pf, snapshot_particles, sim.figure_rng)))
    config = {
        "scenario": scenario.model_dump(mode="json"),
        "strategy": strategy,
        "seed": seed,
        "planner_options": summary["planner_options"],
        "code": code_version(),
    }
    summary["code"] = config["code"]
    summary["version"] = config["code"]["version"]
    return EpisodeResult(records, summary, pf.theta.copy(), pf.weights.copy(), snapshots, config)


def _subsample(pf: ParticleFilter, n: int, rng: np.random.Generator) -> np.ndarray:
    idx = rng.choice(pf.n, size=min(n, pf.n), replace=True, p=pf.weights)
    return pf.source_locations[idx].copy()


def planner_defaults(
    strategy: str, scenario: Scenario, options: dict[str, Any] | None
) -> dict[str, Any]:
    """Constructor defaults: the scenario's hypothesis count (a spec's own, ``dcee:hypotheses=25``,
    overrides it in :func:`dcee.planning.get`)."""
    opts = dict(options or {})
    if planner_class(strategy).uses_hypotheses:
        opts.setdefault("n_hypotheses", scenario.search.hypotheses)
    return opts


__all__ = [
    "FINAL_SAMPLE",
    "MOTION_STREAM",
    "RESULT_FILES",
    "SNAPSHOT_FRACTIONS",
    "EpisodeResult",
    "SearchSimulation",
    "make_searcher",
    "motion_stream",
    "planner_defaults",
    "reading_record",
    "run_episode",
    "search_summary",
    "snapshot_times",
    "streams",
]
