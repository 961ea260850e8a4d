"""The 3-D surface-layer plume (``truth.model = "lbm3d"``): a tiny grid of the solver here (the
full grid's check against published figures is ``dcee plume --model lbm3d``, stored by
studies/recipes/lbm3d.toml); the replay moves, turns, lifts and rescales the canonical field
exactly; the slice is planar; the cache computes once; the 3-D statistics recover a known
Gaussian plume's spreads."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("lbmpy")

from dcee.errors import DceeInputError
from dcee.recordings.statistics import section_statistics_3d
from dcee.scenarios import load_scenario
from dcee.scenarios.schema.truth import Lbm3dSpec
from dcee.simulation import lbm3d, lbm3d_solver
from dcee.simulation.playback import PlaybackTruth

TINY = {
    "spacing": 1.0,
    "store_stride": 1,
    "downstream": 14.0,
    "width": 8.0,
    "height": 6.0,
    "store_height": 5.0,
    "inflow_distance": 4.0,
    "spinup": 20.0,
    "duration": 6.0,
    "lattice_speed": 0.05,
    "smagorinsky": 0.2,
    "relaxation": 1.9,
}
"""A grid of 19 × 8 × 7 cells: about 20 s, nearly all of it lbmpy generating its kernels. At
the coarse 1 m spacing the default lattice speed and subgrid constant were unstable in one of
several runs (NaN after the 2-D solver's test in the same process): a slower lattice and more
subgrid viscosity here."""


def _canonical(z_release: float = 1.25) -> PlaybackTruth:
    """A canonical 3-D field that tells every grid point apart: c = 1 + x + 10 y² + 100 z."""
    t = np.arange(4.0)
    x, y, z = np.arange(-2.0, 11.0), np.arange(-4.0, 5.0), np.arange(0.25, 4.0, 0.5)
    c = 1.0 + x[None, None, :, None] + 10 * y[None, :, None, None] ** 2 + 100 * z
    c = np.broadcast_to(c, (len(t), len(y), len(x), len(z))).copy()
    return PlaybackTruth(c, t, x, y, z, "linear", loop=True)


def _fake_solve(attrs: dict, calls: list[float] | None = None):
    """A stand-in for the solver: the canonical field of :func:`_canonical`, released at the
    lattice height of the height asked for, with ``attrs``; each height asked is appended to
    ``calls``."""

    def solve(spec: Lbm3dSpec, height: float, progress: object = None) -> dict:
        if calls is not None:
            calls.append(height)
        rec = _canonical()
        return {
            "concentration": rec.values.astype(np.float32),
            "t": rec.t,
            "x": rec.x,
            "y": rec.y,
            "z": rec.z,
            "attrs": {"release_height": lbm3d_solver.lattice_height(spec, height), **attrs},
        }

    return solve


def test_the_tiny_solver_writes_a_3d_cf_recording(tmp_path) -> None:
    spec = Lbm3dSpec(**TINY)
    run = lbm3d_solver.solve(spec, 1.2)
    c = run["concentration"]
    assert c.dtype == np.float32 and np.all(np.isfinite(c)) and c.min() >= 0.0
    assert c.shape == (len(run["t"]), len(run["y"]), len(run["x"]), len(run["z"]))
    assert len(run["t"]) >= 6 and np.all(np.diff(run["t"]) > 0)
    # the release sits in its lattice cell's centre, the ground on the first layer's top face
    assert run["attrs"]["release_height"] == 1.5 == lbm3d_solver.lattice_height(spec, 1.2)
    assert run["z"][0] == 0.5 and run["z"][-1] == 4.5
    # the gas is most concentrated at the release and thins downwind
    mean = c.mean(axis=0)
    peak = np.unravel_index(np.argmax(mean), mean.shape)
    assert run["x"][peak[1]] == 0.0 and run["z"][peak[2]] == 1.5
    sections = [mean[:, np.argmin(np.abs(run["x"] - d)), :].max() for d in (2.0, 5.0, 10.0)]
    assert sections[0] > sections[1] > sections[2] > 0.0
    path = tmp_path / "tiny.nc"
    lbm3d.write_recording(path, spec, run)
    truth, release = lbm3d.load_canonical(path)
    assert release == 1.5 and truth.z is not None and truth.loop
    np.testing.assert_allclose(truth.values, c, rtol=1e-6)
    xr = pytest.importorskip("xarray")
    with xr.open_dataset(path, engine="h5netcdf") as ds:  # anyone can open it
        assert ds["concentration"].dims == ("time", "z", "y", "x")
        assert ds["z"].attrs["standard_name"] == "height"


def test_replay_moves_turns_lifts_and_scales_the_canonical_field() -> None:
    rec = _canonical()
    source = np.array([20.0, 30.0, 1.0])  # 0.25 m below the recording's release height
    # the wind from the west (φ = π: the plume extends towards +x), 2 m/s, 4 g/s
    truth = lbm3d.SolverPlume3dTruth(rec, source, 1.25, 4.0, 2.0, math.pi, 1.0)
    p = np.array([[25.0, 32.0, 3.0]])  # 5 m downwind, 2 m to the left, 2 m above the source
    want = rec.field(np.array([[5.0, 2.0, 3.25]]), 1.0 + 0.5 * 2.0) * 4.0 / 2.0
    np.testing.assert_allclose(truth.field(p, 0.5), want)
    # below the lowest stored cell centre: that cell's value; above the stored height and
    # upwind of the domain: nothing
    low = truth.field(np.array([[25.0, 32.0, 0.0]]), 0.5)
    np.testing.assert_allclose(low, rec.field(np.array([[5.0, 2.0, 0.25]]), 2.0) * 2.0)
    assert truth.field(np.array([[25.0, 32.0, 9.0], [10.0, 30.0, 1.0]]), 0.5).tolist() == [0, 0]
    # a slice reads its plane at every altitude
    sliced = lbm3d.SolverPlume3dTruth(rec, source, 1.25, 4.0, 2.0, math.pi, 1.0, plane=3.0)
    at = sliced.field(np.array([[25.0, 32.0, 0.5], [25.0, 32.0, 4.5]]), 0.5)
    np.testing.assert_allclose(at, [want[0], want[0]])
    with pytest.raises(DceeInputError, match=r"truth\.u"):
        lbm3d.SolverPlume3dTruth(rec, source, 1.25, 4.0, 0.0, math.pi, 1.0)


def test_scenarios_on_the_3d_plume_and_its_slice(monkeypatch, tmp_path) -> None:
    monkeypatch.setenv("DCEE_CACHE", str(tmp_path))
    base = load_scenario("random:1").with_overrides(**{"estimator.likelihood": "fluctuation"})
    cube = base.with_overrides(**{"truth.model": "lbm3d"})
    assert not cube.planar_truth and "z" in cube.unknown_names and cube.climb > 0
    sliced = base.with_overrides(**{"truth.model": {"kind": "lbm3d", "plane": 4.0}})
    assert sliced.planar_truth and sliced.reading_plane == 4.0 and sliced.climb == 0.0
    assert "z" in sliced.unknown_names and sliced.truth.model_name == "lbm3d-slice@4m"
    # the slice reads the 3-D run: the same cache file
    spec = cube.truth.model
    assert lbm3d.cache_path(spec, 1.07) == lbm3d.cache_path(sliced.truth.model, 1.07)
    assert lbm3d.cache_path(spec, 1.07) == lbm3d.cache_path(spec, 1.49)  # one cell
    assert lbm3d.cache_path(spec, 1.07) != lbm3d.cache_path(spec, 1.51)
    with pytest.raises(DceeInputError, match=r"^truth\.model\.plane: the slice at 0\.5 m"):
        base.with_overrides(
            **{"truth.model": {"kind": "lbm3d", "plane": 0.5}, "agent.start": [2.0, 2.0, 0.5]}
        )
    with pytest.raises(DceeInputError, match=r"truth\.extra_sources"):
        cube.with_overrides(**{"truth.extra_sources": [{"x": 30.0, "y": 30.0, "z": 1.0}]})
    # computed once, then read back
    calls: list[float] = []
    monkeypatch.setattr(lbm3d, "solve", _fake_solve({}, calls))
    from dcee.simulation import make_truth

    truth = make_truth(cube, 0)
    assert truth.lift == pytest.approx(1.25 - 1.07) and calls == [1.07]
    make_truth(cube, 1)
    assert calls == [1.07]


def test_3d_statistics_recover_a_gaussian_plume() -> None:
    x = np.arange(0.0, 41.0)
    y = np.arange(-20.0, 20.5, 0.5)
    z = np.arange(0.25, 30.0, 0.5)
    sy, sz = 0.2 * x + 0.5, 0.1 * x + 0.5
    zc = 12.0
    c = np.exp(
        -(y[:, None, None] ** 2) / (2 * sy[None, :, None] ** 2)
        - (z[None, None, :] - zc) ** 2 / (2 * sz[None, :, None] ** 2)
    )
    rows = section_statistics_3d(np.repeat(c[None], 3, axis=0), x, y, z, [10.0, 30.0])
    for r in rows:
        assert r.sigma_y == pytest.approx(0.2 * r.x + 0.5, rel=0.01)
        assert r.sigma_z == pytest.approx(0.1 * r.x + 0.5, rel=0.01)
        assert r.centroid_z == pytest.approx(zc, abs=0.01)
        assert r.intensity == 0.0 and r.intermittency == 1.0


def test_plume_command_reports_the_3d_comparison(monkeypatch, tmp_path, capsys) -> None:
    import json

    from tests.helpers import run_cli

    monkeypatch.setenv("DCEE_CACHE", str(tmp_path))
    u_star = lbm3d_solver.friction_velocity(Lbm3dSpec())
    heights = np.arange(0.25, 10.0, 0.5)
    attrs = {
        "mean_wind_heights": heights,
        "mean_wind_profile": lbm3d_solver.log_law(Lbm3dSpec(), heights),
        "turbulence_intensity_u": 2.4 * u_star,
        "turbulence_intensity_v": 1.9 * u_star,
        "turbulence_intensity_w": 1.25 * u_star,
        "lagrangian_time_estimate": 3.0,
    }
    monkeypatch.setattr(lbm3d, "solve", _fake_solve(attrs))
    out = tmp_path / "plume.json"
    code, stdout, _ = run_cli(
        ["plume", "--model", "lbm3d", "--height", "1.1", "-q", "--json", str(out)], capsys
    )
    assert code == 0 and "release at 1.25 m" in stdout and "Briggs" in stdout
    assert "σu/u*, σv/u*, σw/u* = 2.40 (2.4), 1.90 (1.9), 1.25 (1.25)" in stdout
    doc = json.loads(out.read_text())
    assert doc["release_height"] == 1.25 and [round(s["x"]) for s in doc["sections"]] == [5]
    code, _, err = run_cli(["plume", "--model", "lbm3d", "--set", "bar_spacing=3"], capsys)
    assert code == 2 and err.startswith("dcee: error: bar_spacing: not a setting of the lbm3d")


def test_a_plume_not_yet_cached_is_announced_before_it_is_computed(tmp_path, monkeypatch, capsys):
    """`dcee run` says, once, that a solver plume is about to be computed and where it will be
    cached (minutes of silence otherwise); nothing once it is cached, nothing with -q."""
    from dcee.console import plume_notice
    from dcee.scenarios import load_scenario

    monkeypatch.setenv("DCEE_CACHE", str(tmp_path))
    three_d = load_scenario("random:9").with_overrides(**{"truth.model": "lbm3d"})
    planar = load_scenario("paper:1").with_overrides(**{"truth.model": "lbm", "truth.z": 4.0})
    for scenario, what in ((three_d, "the 3-D plume"), (planar, "the planar solver plume")):
        plume_notice(scenario, True)
        assert capsys.readouterr().err == ""
        plume_notice(scenario, False)
        err = capsys.readouterr().err
        assert err.startswith(f"dcee: computing {what}") and err.count("\n") == 1
        cached = Path(err.split("cached as ")[1].strip())
        assert cached.parent == tmp_path / "plumes"
        cached.parent.mkdir(exist_ok=True)
        cached.touch()
        plume_notice(scenario, False)
        assert capsys.readouterr().err == ""


def test_a_release_outside_the_stored_layer_and_an_unwritable_cache_are_refused_first(
    monkeypatch, tmp_path
) -> None:
    """Found 2026-12-05: `dcee plume --model lbm3d --height 50` ran into an IndexError inside
    the solver, and an unwritable cache failed only after minutes of solving."""

    def no_solver(*args, **kwargs):  # the checks come before any solving
        raise AssertionError("the solver ran")

    monkeypatch.setattr(lbm3d, "solve", no_solver)
    spec = Lbm3dSpec()
    for height in (-0.5, 9.6, 50.0):
        with pytest.raises(DceeInputError, match="outside the 3-D plume's stored layer"):
            lbm3d.cached_recording(spec, height)
    lbm3d.check_release_height(spec, 9.5, "truth.z")  # the top of the layer is allowed
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    monkeypatch.setenv("DCEE_CACHE", str(blocker))
    with pytest.raises(DceeInputError, match="cache: cannot write"):
        lbm3d.cached_recording(spec, 1.0)
