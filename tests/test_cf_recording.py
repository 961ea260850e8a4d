"""CF-convention NetCDF recordings (issue 29): axes found by their attributes in any order,
units converted to g/m³, s and m, and every bad recording a one-line error before any work."""

from __future__ import annotations

import json

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")

from dcee.errors import DceeInputError  # noqa: E402
from dcee.recordings.cf import concentration_factor  # noqa: E402
from dcee.scenarios import load_scenario  # noqa: E402
from dcee.simulation import make_truth  # noqa: E402
from dcee.simulation.playback import load_cf_recording  # noqa: E402
from tests.helpers import run_cli  # noqa: E402

R = 8.314462618


def _field(t, y, x, z):
    """A smooth positive field (g/m³) on (t, y, x, z) metres and seconds."""
    T, Y, X, Z = np.meshgrid(t, y, x, z, indexing="ij")
    return (
        1e-3
        * (1.0 + 0.5 * np.sin(0.1 * X) * np.cos(0.07 * Y))
        * np.exp(-0.1 * Z)
        * (1.0 + 0.01 * T)
    )


def _write(path, *, units="ppm", molar_mass=16.04, nan=False, extra=None, drop_axis_attrs=False):
    """A recording as a field campaign might write it: dimensions (z, x, time, y), x in km,
    y decreasing, time in minutes since a date, concentration as a CH4 mixing ratio."""
    t_s = np.arange(0.0, 1200.0, 60.0)  # 20 frames, one a minute
    x_m = np.linspace(-5.0, 55.0, 13)
    y_m = np.linspace(-5.0, 55.0, 7)
    z_m = np.array([0.0, 2.0, 5.0])
    g = _field(t_s, y_m, x_m, z_m)  # (t, y, x, z) g/m³
    to_ppm = (R * 293.15) / (101325.0 * molar_mass) / 1e-6
    data = np.transpose(g, (3, 2, 0, 1)) * (to_ppm if units == "ppm" else 1.0)  # (z, x, t, y)
    data = data[:, :, :, ::-1]  # y stored decreasing
    if nan:
        data = data.copy()
        data[1, 2, 3, 4] = np.nan
    ds = xr.Dataset(
        {"ch4": (("level", "xe", "tm", "north"), data, {"units": units})},
        coords={
            "level": ("level", z_m, {"units": "m", "standard_name": "height", "axis": "Z"}),
            "xe": ("xe", x_m / 1000.0, {"units": "km", "axis": "X"}),
            "tm": ("tm", t_s / 60.0, {"units": "minutes since 2024-05-01 12:00"}),
            "north": (
                "north",
                y_m[::-1],
                {"units": "m", "standard_name": "projection_y_coordinate"},
            ),
        },
        attrs=extra or {},
    )
    if drop_axis_attrs:
        ds["xe"].attrs.pop("axis")
    ds["tm"].attrs["axis"] = "T"
    ds.to_netcdf(path, engine="h5netcdf")
    return g, t_s, x_m, y_m, z_m


def test_axes_in_another_order_and_ppm_replay_at_the_nodes(tmp_path):
    path = tmp_path / "campaign.nc"
    g, t_s, x_m, y_m, z_m = _write(path)
    truth, source = load_cf_recording(path, molar_mass=16.04)
    assert source is None
    assert np.allclose(truth.t, t_s) and np.allclose(truth.x, x_m) and np.allclose(truth.y, y_m)
    assert np.allclose(truth.z, z_m)
    # at grid nodes the replay is the field itself, in g/m³
    for k, i, j, m in [(0, 0, 0, 0), (3, 2, 5, 1), (19, 6, 12, 2)]:
        pos = np.array([x_m[j], y_m[i], z_m[m]])
        assert truth.concentration(pos, t_s[k]) == pytest.approx(g[k, i, j, m], rel=1e-9)


def test_mass_density_units_convert_by_their_factor():
    assert concentration_factor("kg m-3", None, 293.15, 101325.0) == 1000.0
    assert concentration_factor("kg/m^3", None, 293.15, 101325.0) == 1000.0
    assert concentration_factor("mg/m3", None, 293.15, 101325.0) == pytest.approx(1e-3)
    assert concentration_factor("µg m-3", None, 293.15, 101325.0) == pytest.approx(1e-6)
    assert concentration_factor("g m-3", None, 293.15, 101325.0) == 1.0
    # hand calculation: 1 ppm of methane at 20 °C and 1 atm is 0.6668 mg/m³
    ppm = concentration_factor("ppm", 16.04, 293.15, 101325.0)
    assert ppm == pytest.approx(101325.0 * 16.04 / (R * 293.15) * 1e-6)
    assert ppm == pytest.approx(6.668e-4, rel=1e-3)


def test_kg_per_cubic_metre_recording_and_a_mapping_for_unlabelled_axes(tmp_path):
    path = tmp_path / "cfd.nc"
    g, t_s, x_m, y_m, z_m = _write(path, units="kg m-3", drop_axis_attrs=True)
    # "xe" is neither labelled nor a conventional name: the scenario maps it
    with pytest.raises(DceeInputError, match=r"cannot tell which axis dimension 'xe'"):
        load_cf_recording(path)
    truth, _ = load_cf_recording(path, axes={"x": "xe"})
    pos = np.array([x_m[3], y_m[2], z_m[0]])
    assert truth.concentration(pos, t_s[4]) == pytest.approx(1000.0 * g[4, 2, 3, 0], rel=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "load", "message"),
    [
        ({"nan": True}, {"molar_mass": 16.04}, "1 of .* values of 'ch4' are NaN or missing"),
        ({}, {}, "mixing ratio: give the gas's molar_mass"),
        ({"units": "furlongs"}, {}, "unknown concentration units 'furlongs'"),
        ({}, {"variable": "co2", "molar_mass": 44.0}, "has no variable 'co2'"),
        ({}, {"axes": {"w": "xe"}, "molar_mass": 16.04}, "keys must be t, x, y, z"),
    ],
)
def test_bad_recordings_are_one_line_errors(tmp_path, kwargs, load, message):
    path = tmp_path / "bad.nc"
    _write(path, **kwargs)
    with pytest.raises(DceeInputError) as exc:
        load_cf_recording(path, **load)
    assert "\n" not in str(exc.value)
    assert exc.value.field.startswith("truth.model")
    import re

    assert re.search(message, str(exc.value))


def test_missing_time_axis_and_unreadable_file(tmp_path):
    path = tmp_path / "still.nc"
    xr.Dataset(
        {"c": (("y", "x", "z"), np.ones((3, 3, 2)), {"units": "g/m3"})},
        coords={"x": ("x", [0.0, 1.0, 2.0], {"units": "m"}), "y": ("y", [0.0, 1, 2], {})},
    ).to_netcdf(path, engine="h5netcdf")
    with pytest.raises(DceeInputError, match="has no t axis"):
        load_cf_recording(path)
    junk = tmp_path / "junk.nc"
    junk.write_text("not a netcdf file")
    with pytest.raises(DceeInputError, match=r"cannot read junk\.nc as NetCDF"):
        load_cf_recording(junk)


def test_one_set_replays_a_recording_and_a_bad_one_exits_2_before_any_work(tmp_path, capsys):
    path = tmp_path / "plume.nc"
    _write(path)
    spec = json.dumps(str(path))
    setting = f"truth.model={{file = {spec}, molar_mass = 16.04}}"
    scenario = load_scenario("paper:1").with_overrides(
        **{"truth.model": {"file": str(path), "molar_mass": 16.04}, "search.budget": 60.0}
    )
    truth = make_truth(scenario, 0)
    assert truth.concentration(np.array([25.0, 25.0, 2.0]), 30.0) > 0
    out = tmp_path / "run"
    code, _, err = run_cli(
        ["run", "--scenario", "paper:1", "--strategy", "infotaxis", "--set", setting,
         "--budget", "20", "--particles", "500", "-q", "--no-figure", "--out", str(out)],
        capsys,
    )  # fmt: skip
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["truth_model"].startswith("playback:plume.nc")
    # the grid stops at 55 m: a 60 m search area is not covered -> exit 2, nothing written
    bad = tmp_path / "bad-run"
    code, _, err = run_cli(
        ["run", "--scenario", "paper:1", "--strategy", "infotaxis", "--set", setting,
         "--set", "volume.high=[60.0, 60.0, 5.0]", "-q", "--out", str(bad)],
        capsys,
    )  # fmt: skip
    assert code == 2
    assert "does not cover" in err and len(err.strip().splitlines()) == 1
    assert not bad.exists() or not any(bad.iterdir())
