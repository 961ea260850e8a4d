"""Defaults that follow the truth: a planar truth (a 2-D recording, the same at every altitude)
makes the search planar. An unset climb is 0 there, whatever the likelihood (a 3-D recording
keeps the climbing default), the source height is not estimated, a climb asked for or an agent
off the plane a recording declares is refused in one line, and a search with default settings
is the search with ``agent.climb = 0``, reading for reading."""

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
    assert flat.planar_truth and flat.climb == 0.0 and flat.search_dimensions == 2
    assert "z" not in flat.unknown_names and "z" not in flat.make_prior().unknown_names
    cube = _scenario(_plume_2d(tmp_path / "cube.npy", three_d=True))
    assert not cube.planar_truth and cube.climb == AUTO_CLIMB and "z" in cube.unknown_names


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
    # the error is horizontal: the source height is known (truth.z), not estimated
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


def test_run_says_when_the_source_is_off_a_planar_truths_plane(tmp_path: Path, capsys) -> None:
    from tests.helpers import run_cli

    path = _plume_2d(tmp_path / "flat.npy")
    argv = ["run", "--scenario", "random:1", "--truth", str(path), "--budget", "20"]
    argv += ["--particles", "300", "--no-figure"]
    for setting in ("truth.x=25.0", "truth.y=25.0", "truth.phi=180.0", "prior.phi.mean=180.0"):
        argv += ["--set", setting]
    argv += ["--set", "truth.model.loop=true"]
    code, _, err = run_cli([*argv, "--out", str(tmp_path / "a")], capsys)
    z = load_scenario("random:1").truth.z
    assert code == 0 and f"takes the source at truth.z = {z:g} m" in err
    code, _, err = run_cli([*argv, "--set", "truth.z=4.0", "--out", str(tmp_path / "b")], capsys)
    assert code == 0 and "planar" not in err
