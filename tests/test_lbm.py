"""The fluid solver's plume (``truth.model = "lbm"``): a small grid here, the full grid in
``studies/lbm_statistics.py``. Checked against what any plume of a conserved scalar in turbulence
must show and against published figures (module doc of :mod:`dcee.recordings.statistics`): the
flux is conserved downwind, the mean spread grows inside Briggs' open-country envelope, the
centreline intermittency rises downwind; the replay moves, turns and rescales the canonical
field exactly; the cache computes once."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

pytest.importorskip("lbmpy")

from dcee.errors import DceeInputError
from dcee.recordings.statistics import briggs_sigma_y, section_statistics
from dcee.scenarios.schema.truth import LbmSpec
from dcee.simulation import lbm
from dcee.simulation.playback import PlaybackTruth

SMALL = {
    "spacing": 1.0,
    "store_stride": 1,
    "bar_diameter": 2.0,
    "bar_spacing": 6.0,
    "grid_distance": 24.0,
    "downstream": 40.0,
    "width": 48.0,
    "source_radius": 1.0,
    "spinup": 150.0,
    "duration": 250.0,
}
"""A grid of 72 × 48 cells: a few seconds with the kernels' compilation."""


@pytest.fixture(scope="module")
def small_run() -> dict:
    return lbm.solve(LbmSpec(**SMALL))


def test_small_grid_is_a_conserved_turbulent_plume(small_run: dict) -> None:
    c, x, y = small_run["concentration"], small_run["x"], small_run["y"]
    assert c.dtype == np.float32 and np.all(np.isfinite(c)) and c.min() >= 0
    assert c.shape == (250, len(y), len(x))
    rows = section_statistics(c, x, y, [10, 20, 30, 38])
    # normalised to unit flux per unit wind speed at 10 m; a conserved scalar keeps it downwind
    # (the mean-flow part ∫C̄ dy · U; the turbulent part u'c' is the rest)
    for r in rows:
        assert 0.85 < r.flux < 1.1, r
    # the spread grows, and grows inside the open-country envelope (classes D to A) downwind
    spreads = [r.sigma_y for r in rows]
    assert all(b > a for a, b in itertools.pairwise(spreads))
    for r in rows[2:]:  # past the coarse grid's 2 m source disc
        assert briggs_sigma_y(r.x, "D") < r.sigma_y < 1.3 * briggs_sigma_y(r.x, "A"), r
    # a turbulent plume: the centreline fluctuates, and is intermittent near the source more
    # than far from it
    assert all(r.intensity > 0.2 for r in rows)
    assert rows[0].intermittency < 1.0
    assert small_run["attrs"]["turbulence_intensity_v"] > 0.05


def test_same_parameters_same_plume(small_run: dict) -> None:
    again = lbm.solve(LbmSpec(**SMALL))
    np.testing.assert_array_equal(again["concentration"], small_run["concentration"])
    other = lbm.solve(LbmSpec(**{**SMALL, "realisation": 1}))
    assert not np.array_equal(other["concentration"], small_run["concentration"])


def _canonical() -> PlaybackTruth:
    """A synthetic canonical field: c(x, y, t) = (1 + x) · exp(−y²/8) · (1 + t/100), x ≥ 0."""
    t = np.arange(0.0, 101.0)
    x = np.arange(-5.0, 41.0)
    y = np.arange(-20.0, 21.0)
    X, Y = np.meshgrid(x, y)
    base = np.where(X >= 0, 1.0 + X, 0.0) * np.exp(-(Y**2) / 8.0)
    c = base[None] * (1.0 + t[:, None, None] / 100.0)
    return PlaybackTruth(c, t, x, y, loop=True)


def test_replay_moves_turns_and_rescales_the_canonical_field() -> None:
    rec = _canonical()
    phi = math.radians(30.0)  # wind from 30°: the plume goes towards 210°
    q, u, depth = 6.0, 4.0, 2.0
    truth = lbm.SolverPlumeTruth(rec, np.array([10.0, 20.0, 4.0]), q, u, phi, depth, start=10.0)
    down = -np.array([math.cos(phi), math.sin(phi)])
    left = np.array([-down[1], down[0]])
    scale = q / depth / u
    for along, cross, t in ((12.0, 0.0, 0.0), (7.0, 2.0, 5.0), (30.0, -3.0, 20.0)):
        p = np.array([10.0, 20.0, 1.0]) + np.r_[along * down + cross * left, 0.0]
        canonical_t = 10.0 + t * u  # the flow runs u times faster than the canonical 1 m/s
        expected = (1 + along) * math.exp(-(cross**2) / 8.0) * (1 + canonical_t / 100.0)
        assert truth.concentration(p, t) == pytest.approx(expected * scale, rel=1e-9)
    # upwind of the domain and beyond half its width: no gas
    assert truth.concentration(np.array([10.0, 20.0, 4.0]) - 8.0 * np.r_[down, 0.0], 0.0) == 0
    assert truth.concentration(np.array([10.0, 20.0, 4.0]) + 25.0 * np.r_[left, 0.0], 0.0) == 0
    assert truth.time_step == pytest.approx(1.0 / u)


def test_cache_computes_once_and_replays_as_a_recording(monkeypatch, tmp_path) -> None:
    monkeypatch.setenv("DCEE_CACHE", str(tmp_path))
    spec = LbmSpec(**{**SMALL, "spinup": 20.0, "duration": 30.0})
    path = lbm.cached_recording(spec)
    assert path.parent == tmp_path / "plumes" and path.suffix == ".nc"

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("solved again although cached")

    monkeypatch.setattr(lbm, "solve", refuse)
    assert lbm.cached_recording(spec) == path
    truth = lbm.load_canonical(path)  # through the CF reader, as a user's recording would be
    assert truth.z is None and truth.values.shape[0] == 30
    # a changed parameter is another plume (another file); the depth only rescales
    assert lbm.cache_path(LbmSpec(**{**SMALL, "realisation": 3})) != lbm.cache_path(spec)
    assert lbm.cache_path(spec.model_copy(update={"layer_depth": 9.0})) == path


def test_a_scenario_on_the_lbm_truth_is_planar(monkeypatch, tmp_path) -> None:
    from dcee.scenarios import load_scenario

    base = load_scenario("random:1")
    # the planar plume's source lies in the plane the UAV flies: a source below it is refused
    # in one line naming truth.z (no truth height may reach the reading model)
    with pytest.raises(DceeInputError, match=r"^truth\.z: 1\.07 m is off the flight plane"):
        base.with_overrides(**{"truth.model": "lbm", "estimator.likelihood": "fluctuation"})
    scenario = base.with_overrides(
        **{"truth.model": "lbm", "truth.z": 4.0, "estimator.likelihood": "fluctuation"}
    )
    assert scenario.planar_truth and scenario.climb == 0.0
    assert "z" not in scenario.unknown_names
    assert scenario.make_prior().sample(np.random.default_rng(0), 3)[:, 2].tolist() == [4.0] * 3
    with pytest.raises(DceeInputError, match=r"agent\.climb"):
        scenario.with_overrides(**{"agent.climb": 1.0})
    with pytest.raises(DceeInputError, match=r"truth\.u"):
        lbm.SolverPlumeTruth(_canonical(), np.zeros(3), 1.0, 0.0, 0.0, 1.0, 0.0)


def test_plume_command_computes_once_and_refuses_bad_settings(monkeypatch, tmp_path, capsys):
    import json

    from tests.helpers import run_cli

    monkeypatch.setenv("DCEE_CACHE", str(tmp_path))
    settings = [f"--set=truth.model.{k}={v}" for k, v in {**SMALL, "duration": 40.0}.items()]
    out = tmp_path / "stats.json"
    code, stdout, _ = run_cli(["plume", "-q", *settings, "--json", str(out)], capsys)
    assert code == 0 and "cached recording" in stdout
    doc = json.loads(out.read_text())
    assert [round(s["x"]) for s in doc["sections"]] == [5, 10, 20, 30]
    assert all(0.5 < s["flux"] < 1.2 for s in doc["sections"])
    # a second call reads the cache back
    monkeypatch.setattr(lbm, "solve", lambda *a, **k: pytest.fail("solved again"))
    assert run_cli(["plume", "-q", *settings], capsys)[0] == 0
    code, _, err = run_cli(["plume", "--set", "truth.model.bogus=1"], capsys)
    assert code == 2 and err.startswith("dcee: error: truth.model.bogus: not a setting")
    code, _, err = run_cli(["plume", "--set", "spacing=-1"], capsys)
    assert code == 2 and "truth.model.spacing" in err and len(err.strip().splitlines()) == 1


def _wall_mask(spec: LbmSpec) -> np.ndarray:
    """A wall 2 m thick and 16 m long across the plume, 14-16 m downwind of the source."""
    return lbm.solid_cells(spec, lambda x, y: (x >= 14.0) & (x <= 16.0) & (np.abs(y) <= 8.0))


def test_a_wall_across_the_plume_shelters_what_lies_behind_it() -> None:
    # both at the sites' slower lattice speed (the same viscosity and diffusivity)
    spec = LbmSpec(**{**SMALL, "lattice_speed": lbm.SITE_LATTICE_SPEED})
    walled = lbm.solve(spec, solids=_wall_mask(spec))
    c, x, y = walled["concentration"], walled["x"], walled["y"]
    assert np.all(np.isfinite(c)) and c.min() >= 0
    mean_walled = c.mean(axis=0)
    mean_open = lbm.solve(spec)["concentration"].mean(axis=0)

    def at(mean: np.ndarray, px: float, py: float) -> float:
        return float(mean[np.argmin(np.abs(y - py)), np.argmin(np.abs(x - px))])

    # upwind of the wall the plume is nearly the open one; in the wall there is no gas; behind
    # it (measured 0.28 and 0.13 of the open plume's mean) and far behind it little
    assert at(mean_walled, 12.5, 0.5) > 0.8 * at(mean_open, 12.5, 0.5)
    assert at(mean_walled, 15.5, 0.5) == 0.0
    assert at(mean_walled, 18.5, 0.5) < 0.4 * at(mean_open, 18.5, 0.5)
    assert at(mean_walled, 30.5, 0.5) < 0.25 * at(mean_open, 30.5, 0.5)
    # the gas goes round the wall's ends instead (measured 94 and 69 times the open plume's)
    assert at(mean_walled, 15.5, 10.5) > 20.0 * at(mean_open, 15.5, 10.5)
    assert at(mean_walled, 15.5, -9.5) > 20.0 * at(mean_open, 15.5, -9.5)


def test_a_site_grows_the_domain_round_the_search_area_and_walls_off_its_buildings() -> None:
    from dcee.scenarios import load_scenario

    scenario = load_scenario("site:wall").with_overrides(**{"truth.model": "lbm", "truth.z": 4.0})
    theta = scenario.truth_theta()
    spec = LbmSpec(**SMALL)
    grown, solids = lbm.site_frame(
        spec, (0.0, 0.0), (50.0, 50.0), theta[:2], float(theta[5]),
        lambda xy: scenario.in_obstacle(xy, no_go=False),
    )  # fmt: skip
    # the search area seen from the source (37.5, 12.5) with the wind from +x: 37.5 m downwind,
    # 12.5 m upwind, 37.5 m to one side; the site's slower lattice
    assert grown.downstream >= 37.5 + lbm.SITE_MARGIN
    assert grown.width >= 2 * 37.5 + 2 * lbm.SITE_MARGIN
    assert grown.grid_distance >= 12.5 + lbm.SITE_MARGIN
    assert grown.lattice_speed == lbm.SITE_LATTICE_SPEED
    # the wall x 20-21 m, y 0-35 m: canonical 16.5-17.5 m downwind, from 22.5 m right to
    # 12.5 m left of the source (the wind blows towards −x, so left is −y)
    dom_x = np.arange(solids.shape[0]) * grown.spacing - (grown.grid_distance + 4 * 2.0)
    xs = dom_x[np.nonzero(solids.any(axis=1))[0]]
    assert 16.0 <= xs.min() and xs.max() <= 18.0
    assert lbm.cache_path(grown, solids) != lbm.cache_path(grown)
    # no building: the open-terrain recording
    open_spec, none = lbm.site_frame(
        spec, (0.0, 0.0), (50.0, 50.0), theta[:2], float(theta[5]),
        lambda xy: np.zeros(len(xy), bool),
    )  # fmt: skip
    assert none is None and open_spec == spec
    # a building the domain's edge cuts (a real map's block reaching past the area): the band
    # along every edge stays air, the rest of the building walled off
    _, cut = lbm.site_frame(
        spec, (0.0, 0.0), (50.0, 50.0), theta[:2], float(theta[5]),
        lambda xy: xy[:, 1] < 5.0,  # everything south of y = 5 m, past the domain's edge
    )  # fmt: skip
    edge = round(lbm.SITE_EDGE / grown.spacing)
    assert cut.any() and not cut[:edge].any() and not cut[-edge:].any()
    assert not cut[:, :edge].any() and not cut[:, -edge:].any()


def test_a_run_that_diverges_but_stays_finite_is_refused() -> None:
    """A conserved scalar obeys a maximum principle: a cell of the air far above the most the
    release cell has held is a diverged run (site:passage's plume of 2026-12-05 reached 6.6e34
    of it, finite), refused in one line; a bounded field passes and the peak is kept."""
    from dcee.simulation.lbm_solver import BLOW_UP, bounded

    field = np.zeros((20, 10))
    field[10, 5] = 0.8  # the release cell
    field[15, 5] = 0.5  # gas downwind, below it
    assert bounded(field, 0.8, 1.0, 12.0) == 1.0  # the earlier peak kept
    assert bounded(field, 0.8, 0.0, 12.0) == 0.8
    field[3, 2] = 2.0 * BLOW_UP
    with pytest.raises(DceeInputError, match=r"became unstable 12 s into the run \(it diverged\)"):
        bounded(field, 0.8, 1.0, 12.0)
    field[3, 2] = 1e25  # finite, as the diverged run's
    with pytest.raises(DceeInputError, match="unstable"):
        bounded(field, 0.8, 1.0, 12.0)


def test_a_site_whose_run_diverges_is_computed_once_more_slower(tmp_path, monkeypatch) -> None:
    """A site's run that diverges at the site's lattice speed is run once more at the slower
    one, and remembered: the next request goes to the slower run at once; in open terrain (no
    walls) a diverged run is refused."""
    from dcee.simulation import lbm
    from dcee.simulation.lbm_solver import unstable

    monkeypatch.setenv("DCEE_CACHE", str(tmp_path))
    calls: list[float] = []

    def fake_solve(spec, progress=None, solids=None):
        calls.append(spec.lattice_speed)
        if spec.lattice_speed > lbm.SITE_FALLBACK_SPEED:
            raise unstable(1465.0)
        t = np.arange(3.0)
        x, y = np.arange(4.0), np.arange(-1.0, 2.0)
        field = np.full((3, 3, 4), 0.5, np.float32)
        return {"concentration": field, "t": t, "x": x, "y": y, "attrs": {"flux_lattice": 1.0}}

    monkeypatch.setattr(lbm, "solve", fake_solve)
    spec = LbmSpec(lattice_speed=lbm.SITE_LATTICE_SPEED)
    walls = np.zeros((8, 6), dtype=bool)
    walls[3, 2] = True
    first = lbm.cached_recording(spec, solids=walls)
    assert calls == [lbm.SITE_LATTICE_SPEED, lbm.SITE_FALLBACK_SPEED]
    assert first == lbm.cache_path(spec.model_copy(update={"lattice_speed": 0.02}), walls)
    assert lbm.cached_recording(spec, solids=walls) == first and len(calls) == 2  # remembered
    with pytest.raises(DceeInputError, match="became unstable 1465 s into the run"):
        lbm.cached_recording(spec)  # open terrain: no slower run
    # a site that diverges at the slower speed too: once more, more viscous, then no further
    calls.clear()
    tried: list[tuple[float, float]] = []

    def steady_only_when_viscous(spec, progress=None, solids=None):
        tried.append((spec.lattice_speed, spec.relaxation))
        if spec.relaxation > lbm.SITE_FALLBACK_RELAXATION:
            raise unstable(456.0)
        return fake_solve(spec.model_copy(update={"lattice_speed": 0.01}))

    monkeypatch.setattr(lbm, "solve", steady_only_when_viscous)
    walls[4, 2] = True  # another site
    third = lbm.cached_recording(spec, solids=walls)
    assert tried == [(0.03, 1.99), (0.02, 1.99), (0.02, lbm.SITE_FALLBACK_RELAXATION)]
    assert third == lbm.cache_path(
        spec.model_copy(update={"lattice_speed": 0.02, "relaxation": 1.9}), walls
    )
    monkeypatch.setattr(lbm, "solve", lambda *a, **k: (_ for _ in ()).throw(unstable(9.0)))
    walls[5, 2] = True
    with pytest.raises(DceeInputError, match="became unstable 9 s"):
        lbm.cached_recording(spec, solids=walls)  # every set-up diverged: one line


def test_an_unwritable_cache_is_refused_before_the_solver_runs(monkeypatch, tmp_path) -> None:
    """Found 2026-12-05: the plume was solved for minutes, then its write failed."""

    def no_solver(*args, **kwargs):
        raise AssertionError("the solver ran")

    monkeypatch.setattr(lbm, "solve", no_solver)
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    monkeypatch.setenv("DCEE_CACHE", str(blocker))
    with pytest.raises(DceeInputError, match="cache: cannot write"):
        lbm.cached_recording(LbmSpec())


def test_plume_command_computes_a_scenario_s_site_plume_once(tmp_path, monkeypatch, capsys):
    """``dcee plume --scenario NAME``: the plume the scenario's solver truth flies (a site's,
    round its buildings) computed into the cache, then found there; a scenario without a
    solver truth is refused in one line."""
    from dcee.simulation import lbm
    from tests.helpers import run_cli

    monkeypatch.setenv("DCEE_CACHE", str(tmp_path))
    solved: list[bool] = []

    def fake_solve(spec, progress=None, solids=None):
        solved.append(solids is not None and bool(solids.any()))
        t, x, y = np.arange(3.0), np.arange(4.0), np.arange(-1.0, 2.0)
        field = np.full((3, 3, 4), 0.5, np.float32)
        return {"concentration": field, "t": t, "x": x, "y": y, "attrs": {"flux_lattice": 1.0}}

    monkeypatch.setattr(lbm, "solve", fake_solve)
    code, out, err = run_cli(["plume", "--scenario", "site:wall", "-q"], capsys)
    assert code == 0, err
    assert solved == [True] and "site:wall: lbm plume ready (" in out and str(tmp_path) in out
    code, out, _ = run_cli(["plume", "--scenario", "site:wall", "-q"], capsys)
    assert code == 0 and solved == [True] and "already in the cache" in out
    code, _, err = run_cli(["plume", "--scenario", "paper:1"], capsys)
    assert code == 2 and "not a solver's plume" in err and err.count("\n") == 1
    code, _, err = run_cli(["plume", "--scenario", "site:wall", "--model", "lbm3d"], capsys)
    assert code == 2 and err.startswith("dcee: error: --model: not with --scenario")
