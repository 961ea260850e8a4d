"""Defaults that follow the truth: a planar truth (a 2-D recording, the same at every altitude)
keeps the agent at its altitude. An unset climb is 0 there, whatever the likelihood (a 3-D
recording keeps the climbing default); the source height is estimated between the ground and the
recording's plane unless the scenario declares it known (``dimensions = 2``); a climb asked for
or an agent off the plane a recording declares is refused in one line, and a search with default
settings is the search with ``agent.climb = 0``, reading for reading. No truth value other than
the declared known ones reaches the estimator (issue 78)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.recordings import recording_layout
from dcee.runs import run_episode
from dcee.scenarios import load_scenario
from dcee.scenarios.schema.agent import AUTO_CLIMB
from dcee.simulation import save_recording


def _plume_2d(path: Path, plane: float | None = None, three_d: bool = False) -> Path:
    """A steady Gaussian plume from (25, 25) blowing towards +x over the paper's area."""
    t = np.array([0.0, 1.0])
    x = np.linspace(0.0, 50.0, 51)
    y = np.linspace(0.0, 50.0, 51)
    X, Y = np.meshgrid(x, y)
    along = np.maximum(X - 25.0, 0.0)
    sigma = 0.5 + 0.15 * along
    field = np.where(X >= 25.0, 0.5 / sigma * np.exp(-((Y - 25.0) ** 2) / (2 * sigma**2)), 0.0)
    c = np.repeat(field[None], 2, axis=0)
    if three_d:
        z = np.array([0.0, 5.0])
        save_recording(path, np.repeat(c[..., None], 2, axis=3), t, x, y, z)
    else:
        save_recording(path, c, t, x, y)
        if plane is not None:
            meta_path = path.with_suffix(".json")
            meta = json.loads(meta_path.read_text())
            meta["z"] = plane
            meta_path.write_text(json.dumps(meta))
    return path


def _scenario(path: Path, **more: object):
    base = load_scenario("random:1").with_overrides(
        **{
            "truth.x": 25.0,
            "truth.y": 25.0,
            "truth.phi": 180.0,
            "prior.phi.mean": 180.0,
            "estimator.likelihood": "fluctuation",
        }
    )
    return base.with_overrides(**{"truth.model": {"file": str(path), "loop": True}, **more})


def test_layout_is_read_from_the_header(tmp_path: Path) -> None:
    assert recording_layout(_plume_2d(tmp_path / "flat.npy")) == (True, None)
    assert recording_layout(_plume_2d(tmp_path / "at2.npy", plane=2.0)) == (True, 2.0)
    assert recording_layout(_plume_2d(tmp_path / "cube.npy", three_d=True)) == (False, None)
    with pytest.raises(DceeInputError, match="no such file"):
        recording_layout(tmp_path / "missing.npy")
    (tmp_path / "plume.txt").write_text("1 2 3")
    with pytest.raises(DceeInputError) as err:
        recording_layout(tmp_path / "plume.txt")
    assert str(err.value).count("truth.model.file") == 1 and "unsupported" in str(err.value)


def test_cf_slice_declares_its_plane(tmp_path: Path) -> None:
    xr = pytest.importorskip("xarray")
    ds = xr.Dataset(
        {"c": (("time", "y", "x"), np.zeros((2, 3, 4)), {"units": "g m-3"})},
        coords={
            "time": ("time", [0.0, 1.0], {"units": "s"}),
            "y": ("y", [0.0, 1.0, 2.0], {"units": "m"}),
            "x": ("x", [0.0, 1.0, 2.0, 3.0], {"units": "m"}),
            "height": ((), 150.0, {"units": "cm", "axis": "Z"}),
        },
    )
    ds["c"] = ds["c"].assign_coords(height=ds["height"])
    path = tmp_path / "slice.nc"
    ds.to_netcdf(path, engine="h5netcdf")
    assert recording_layout(path) == (True, 1.5)


def test_planar_recording_sets_the_defaults(tmp_path: Path) -> None:
    flat = _scenario(_plume_2d(tmp_path / "flat.npy"))
    assert flat.planar_truth and flat.climb == 0.0 and flat.search_dimensions == 3
    # the source height is estimated, between the ground and the plane (the agent's 4 m here)
    prior = flat.make_prior()
    assert "z" in flat.unknown_names and "z" in prior.unknown_names
    z = prior.sample(np.random.default_rng(0), 4000)[:, 2]
    assert 0.0 <= z.min() and z.max() <= 4.0 and z.max() > 3.9
    at2 = _scenario(_plume_2d(tmp_path / "at2.npy", plane=2.0), **{"agent.start": [2, 2, 2]})
    assert at2.make_prior().sample(np.random.default_rng(0), 4000)[:, 2].max() <= 2.0
    # declared known: dimensions = 2 fixes it at truth.z
    known = flat.with_overrides(dimensions=2)
    assert known.search_dimensions == 2 and "z" not in known.unknown_names
    assert set(known.make_prior().sample(np.random.default_rng(0), 5)[:, 2]) == {flat.truth.z}
    cube = _scenario(_plume_2d(tmp_path / "cube.npy", three_d=True))
    assert not cube.planar_truth and cube.climb == AUTO_CLIMB and "z" in cube.unknown_names


def test_no_truth_value_reaches_the_estimator(tmp_path: Path) -> None:
    """Over a recording the readings do not depend on the scenario's truth: two scenarios whose
    truths differ in every parameter but the known ones (all eight unknown here) give the same
    estimates, reading for reading; only the errors against the truth differ."""
    quick = {"search.particles": 600, "search.hypotheses": 8, "search.budget": 60.0}
    path = _plume_2d(tmp_path / "flat.npy")
    a = _scenario(path, unknown="full", **quick)
    moved = {"truth.x": 27.5, "truth.y": 23.0, "truth.z": 2.5, "truth.q": 11.0, "truth.u": 5.5}
    b = a.with_overrides(**moved, **{"truth.zeta1": 1.4, "truth.zeta2": 6.0})
    assert b.truth_theta()[:6].tolist() != a.truth_theta()[:6].tolist()
    ra, rb = run_episode(a, "dcee-cl", 5), run_episode(b, "dcee-cl", 5)
    assert len(ra.records) > 3
    for x, y in zip(ra.records, rb.records, strict=True):
        assert x["reading"] == y["reading"] and x["x"] == y["x"] and x["z"] == y["z"]
        assert (x["mean_x"], x["mean_y"], x["mean_z"]) == (y["mean_x"], y["mean_y"], y["mean_z"])
    assert [r["rmse"] for r in ra.records] != [r["rmse"] for r in rb.records]


def test_what_cannot_work_is_one_line(tmp_path: Path) -> None:
    flat = _plume_2d(tmp_path / "flat.npy")
    with pytest.raises(DceeInputError, match=r"^agent\.climb: .*planar") as err:
        _scenario(flat, **{"agent.climb": 1.0})
    assert "\n" not in str(err.value)
    with pytest.raises(DceeInputError, match=r"^agent\.start: z = 4 m .*z = 2 m"):
        _scenario(_plume_2d(tmp_path / "at2.npy", plane=2.0))
    ok = _scenario(_plume_2d(tmp_path / "at4.npy", plane=4.0))
    assert ok.planar_truth


def test_default_search_is_the_fixed_altitude_search(tmp_path: Path) -> None:
    quick = {"search.particles": 800, "search.hypotheses": 8, "search.budget": 120.0}
    flat = _scenario(_plume_2d(tmp_path / "flat.npy"), **quick)
    fixed = flat.with_overrides(**{"agent.climb": 0.0})
    a, b = run_episode(flat, "dcee-cl", 3), run_episode(fixed, "dcee-cl", 3)
    assert [r["reading"] for r in a.records] == [r["reading"] for r in b.records]
    assert [r["rmse"] for r in a.records] == [r["rmse"] for r in b.records]
    assert {r["z"] for r in a.records} == {4.0}
    assert math.isfinite(a.summary["final_rmse"])


def test_show_says_what_each_default_was_chosen_on() -> None:
    from dcee.scenarios import to_toml
    from dcee.scenarios.defaults import DEFAULTS

    text = to_toml(load_scenario("random:1000"))
    assert "near_source_length = 0.5\n# ^ default, chosen on filament + puffs" in text
    assert "independent on isotropic, lbm" in text
    # a built-in's own value is not the measured default: no provenance under it
    lab = to_toml(load_scenario("lab:upwind"))
    assert "log_sd = 0.72\n# ^" not in lab
    # every entry names a real setting
    scenario = load_scenario("random:1000")
    for section, key in DEFAULTS:
        assert key in type(getattr(scenario, section)).model_fields, (section, key)
    # the file still reads back to the same scenario
    import tomllib

    from dcee.scenarios import validate_scenario

    assert validate_scenario(tomllib.loads(text)) == scenario


def test_the_new_users_lbm_command_refuses_in_one_line(capsys) -> None:
    """Issue 78's second row: the planar lbm plume with the scenario's source below the UAV
    took the source height from the truth; now the command refuses before any work."""
    from tests.helpers import run_cli

    argv = ["run", "--scenario", "random:5000", "--truth", "lbm", "--likelihood", "fluctuation"]
    code, out, err = run_cli([*argv, "--unknown", "full", "-q"], capsys)
    assert code == 2 and out == ""
    assert err.startswith("dcee: error: truth.z: ") and err.count("\n") == 1
    assert 'truth.model = "lbm3d"' in err
