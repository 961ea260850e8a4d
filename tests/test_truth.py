"""Ground-truth models: filament plume statistics and recorded-plume playback."""

from __future__ import annotations

import json

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.scenarios import FilamentSpec, load_scenario, truth_choice
from dcee.simulation import (
    FilamentTruth,
    IsotropicTruth,
    PlaybackTruth,
    load_recording,
    make_truth,
    plume_stream,
    save_recording,
)
from tests.helpers import run_cli

SCENARIO = load_scenario("paper:1")  # source (37.5, 12.5, 1), wind from +x at 4 m/s: plume to -x
THETA = SCENARIO.truth_theta()
LOW, HIGH = np.array(SCENARIO.volume.low), np.array(SCENARIO.volume.high)


def filament(seed: int = 0, **spec) -> FilamentTruth:
    return FilamentTruth(THETA, FilamentSpec(**spec), np.random.default_rng(seed), LOW, HIGH)


def time_series(truth, points, times) -> np.ndarray:
    """(len(times), len(points)) concentrations."""
    return np.array([truth.field(np.asarray(points, dtype=float), t) for t in times])


# --- filament ---------------------------------------------------------------------------------


def test_filament_is_deterministic_per_seed():
    pts = [[20.0, 12.5, 1.0], [30.0, 14.0, 2.0]]
    a = time_series(filament(3), pts, range(0, 60, 3))
    b = time_series(filament(3), pts, range(0, 60, 3))
    c = time_series(filament(4), pts, range(0, 60, 3))
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)


def test_plume_stream_is_the_reserved_child_of_the_seed():
    expected = np.random.default_rng(np.random.SeedSequence(7).spawn(4)[3]).random(3)
    np.testing.assert_array_equal(plume_stream(7).random(3), expected)


def test_looking_back_in_time_gives_the_field_of_that_time():
    pts = np.array([[25.0, 12.5, 1.0], [15.0, 10.0, 1.0]])
    fresh = filament(1).field(pts, 47.0)
    truth = filament(1)
    truth.field(pts, 300.0)  # run past it, then look back (restores a checkpoint)
    np.testing.assert_array_equal(truth.field(pts, 47.0), fresh)


def test_without_meander_and_filaments_the_mean_field_is_the_isotropic_plume():
    # Gaussian puffs of variance 2 ζ1 age, advected at u and decaying with ζ2, are the Green's
    # function of the equation whose steady state is the isotropic model: with every random
    # part switched off the field after spin-up must equal it up to the puff discretisation.
    truth = filament(meander_intensity=0.0, puff_share=1.0)
    iso = IsotropicTruth(THETA)
    pts = np.array([[30.0, 12.5, 1.0], [20.0, 12.5, 4.0], [10.0, 15.0, 2.0], [25.0, 9.0, 1.0]])
    np.testing.assert_allclose(truth.field(pts, 100.0), iso.field(pts, 0.0), rtol=0.01)


def test_time_averaged_field_peaks_downwind_on_the_mean_wind_and_decays_across():
    truth = filament(2)
    ys = np.arange(0.0, 25.1, 2.5)
    transect = np.column_stack([np.full(ys.size, 22.5), ys, np.ones(ys.size)])  # 15 m downwind
    upwind = np.array([[47.5, 12.5, 1.0]])
    times = np.arange(0.0, 600.0, 1.0)
    mean = time_series(truth, np.vstack([transect, upwind]), times).mean(0)
    across, up = mean[:-1], mean[-1]
    peak = int(np.argmax(across))
    assert abs(ys[peak] - 12.5) <= 2.5  # on the mean-wind line through the source
    assert across[0] < 0.2 * across[peak] and across[-1] < 0.2 * across[peak]
    assert up < 1e-3 * across[peak]  # nothing upwind
    # comparable to the estimator's model: same order of magnitude on the centre line
    iso = IsotropicTruth(THETA).concentration(np.array([22.5, 12.5, 1.0]), 0.0)
    assert 0.2 < across[peak] / iso < 2.0


def test_instantaneous_readings_are_intermittent_and_heavy_tailed():
    truth = filament(5)
    point = [[27.5, 12.5, 1.0]]  # 10 m downwind, inside the mean plume
    c = time_series(truth, point, np.arange(0.0, 900.0, 1.0))[:, 0]
    threshold = SCENARIO.sensor.threshold
    iso = IsotropicTruth(THETA).concentration(np.array(point[0]), 0.0)
    assert iso > 20 * threshold  # the mean plume is well above the detection threshold here
    assert np.mean(c < threshold) > 0.3  # yet a large share of readings is below it
    assert np.percentile(c, 99) > 5 * c.mean()  # rare, strong filaments
    assert np.mean(c > 3 * c.mean()) > 0.01


def test_meander_has_the_configured_standard_deviation():
    truth = filament(6, meander_intensity=0.25)
    samples = []
    for t in np.arange(0.0, 6000.0, 5.0):
        truth.puffs(t)
        samples.append(truth._state.meander[:, 0].copy())
    sd = np.std(samples, axis=0)
    np.testing.assert_allclose(sd, 0.25 * THETA[4], rtol=0.25)


# --- configuration ----------------------------------------------------------------------------


def test_filament_shorthand_resolves_every_parameter():
    scenario = SCENARIO.with_overrides(**{"truth.model": "filament"})
    assert scenario.truth.model == FilamentSpec()
    assert scenario.truth.model_name == "filament"
    assert scenario.model_dump()["truth"]["model"]["puff_rate"] == 10.0
    assert SCENARIO.model_dump()["truth"]["model"] == "isotropic"  # older folders still resume
    assert isinstance(make_truth(scenario, 0), FilamentTruth)


@pytest.mark.parametrize(
    ("model", "field"),
    [("plumes", "truth.model"), ({"kind": "filament", "puff_rate": -1}, "truth.model.puff_rate: ")],
)
def test_bad_truth_model_is_a_one_line_error_naming_the_field(model, field):
    with pytest.raises(DceeInputError) as exc:
        SCENARIO.with_overrides(**{"truth.model": model})
    assert str(exc.value).startswith(field)
    assert "\n" not in str(exc.value)


def test_truth_choice_rejects_what_is_neither_a_model_nor_a_recording(tmp_path):
    assert truth_choice("filament") == "filament"
    assert truth_choice("puffs") == "puffs"
    with pytest.raises(
        DceeInputError,
        match=r"isotropic, filament, puffs, lbm, lbm3d, a \.npy/\.h5/\.nc recording or a GADEN",
    ):
        truth_choice("gaussian")
    with pytest.raises(DceeInputError, match="no such recording"):
        truth_choice(str(tmp_path / "missing.h5"))


# --- playback ---------------------------------------------------------------------------------


def linear_recording(with_z: bool):
    """A field linear in t, x, y (and z): interpolation must reproduce it exactly anywhere."""
    t = np.array([0.0, 10.0, 30.0])
    x = np.array([0.0, 20.0, 35.0, 50.0])
    y = np.array([0.0, 25.0, 50.0])
    z = np.array([0.0, 2.0, 5.0])
    axes = (t, y, x, z) if with_z else (t, y, x)
    grids = np.meshgrid(*axes, indexing="ij")
    if with_z:
        tt, yy, xx, zz = grids
        values = 1.0 + 0.01 * tt + 0.02 * xx + 0.03 * yy + 0.05 * zz
    else:
        tt, yy, xx = grids
        values = 1.0 + 0.01 * tt + 0.02 * xx + 0.03 * yy
    return values, t, x, y, (z if with_z else None)


def exact(t, p, with_z):
    return 1.0 + 0.01 * t + 0.02 * p[:, 0] + 0.03 * p[:, 1] + (0.05 * p[:, 2] if with_z else 0.0)


@pytest.mark.parametrize("with_z", [False, True])
@pytest.mark.parametrize("suffix", [".npy", ".h5"])
def test_playback_is_exact_at_nodes_and_linear_between(tmp_path, with_z, suffix):
    values, t, x, y, z = linear_recording(with_z)
    path = tmp_path / f"plume{suffix}"
    save_recording(path, values, t, x, y, z)
    truth, source = load_recording(path)
    assert source is None
    # stored values at every node of frame 1
    nodes = np.array([[xi, yi, 1.0] for yi in y for xi in x])
    zs = z if with_z else [1.0]
    for k, zk in enumerate(zs):
        nodes[:, 2] = zk
        expected = values[1, :, :, k].ravel() if with_z else values[1].ravel()
        np.testing.assert_allclose(truth.field(nodes, 10.0), expected, rtol=0, atol=1e-12)
    # anywhere between nodes and frames: the linear field itself
    rng = np.random.default_rng(0)
    pts = rng.uniform([0, 0, 0], [50, 50, 5], size=(50, 3))
    for time in (0.0, 3.7, 10.0, 22.5, 30.0):
        np.testing.assert_allclose(truth.field(pts, time), exact(time, pts, with_z), atol=1e-12)


def test_nearest_frame_and_looping():
    values, t, x, y, _ = linear_recording(False)
    nearest = PlaybackTruth(values, t, x, y, time_interpolation="nearest")
    p = np.array([10.0, 10.0, 0.0])
    assert nearest.concentration(p, 4.9) == pytest.approx(exact(0.0, p[None], False)[0])
    assert nearest.concentration(p, 5.1) == pytest.approx(exact(10.0, p[None], False)[0])
    looped = PlaybackTruth(values, t, x, y, loop=True)  # period 30 + 20 = 50 s
    for time in (3.0, 17.0):
        assert looped.concentration(p, time + 50.0) == pytest.approx(looped.concentration(p, time))
    # between the last frame (t = 30) and frame 0 again (t = 50): linear back to the start
    halfway = 0.5 * (exact(30.0, p[None], False)[0] + exact(0.0, p[None], False)[0])
    assert looped.concentration(p, 40.0) == pytest.approx(halfway)
    with pytest.raises(DceeInputError, match="past the recording"):
        PlaybackTruth(values, t, x, y).concentration(p, 31.0)


def test_playback_errors_are_clear(tmp_path):
    values, t, x, y, z = linear_recording(True)
    p = np.array([10.0, 10.0, 1.0])
    cases = {
        "time × y × x": lambda: PlaybackTruth(values[0, 0], t, x, y),
        "needs 'z' metadata": lambda: PlaybackTruth(values, t, x, y),
        "strictly increasing": lambda: PlaybackTruth(values, t[::-1], x, y, z),
        "has 5 values": lambda: PlaybackTruth(values, t, [*x[:3].tolist(), 60, 70], y, z),
        "finite and >= 0": lambda: PlaybackTruth(np.where(values > 2, np.nan, values), t, x, y, z),
        "outside the recording's grid": lambda: PlaybackTruth(values, t, x, y, z).concentration(
            p + np.array([0, 0, 10]), 0.0
        ),
    }
    for message, make in cases.items():
        with pytest.raises(DceeInputError, match=message) as exc:
            make()
        assert str(exc.value).startswith("truth.model.file")
    np.save(tmp_path / "lonely.npy", values)
    with pytest.raises(DceeInputError, match=r"needs its metadata in lonely\.json"):
        load_recording(tmp_path / "lonely.npy")
    np.save(tmp_path / "partial.npy", values)
    (tmp_path / "partial.json").write_text(json.dumps({"t": t.tolist(), "x": x.tolist()}))
    with pytest.raises(DceeInputError, match="missing metadata y, z"):
        load_recording(tmp_path / "partial.npy")
    (tmp_path / "junk.h5").write_bytes(b"not hdf5")
    with pytest.raises(DceeInputError, match=r"cannot read junk\.h5"):
        load_recording(tmp_path / "junk.h5")
    with pytest.raises(DceeInputError, match="unsupported recording"):
        load_recording(tmp_path / "partial.json")


def test_scenario_checks_the_recording_against_volume_source_and_budget(tmp_path):
    values, t, x, y, z = linear_recording(True)
    ok = tmp_path / "ok.h5"
    save_recording(ok, values, t, x, y, z, source=THETA[:3])
    short = SCENARIO.with_overrides(**{"search.budget": 20.0})
    truth = make_truth(short.with_overrides(**{"truth.model": {"file": str(ok)}}), 0)
    assert isinstance(truth, PlaybackTruth)
    with pytest.raises(DceeInputError, match=r"lasts 30 s but search\.budget is 900 s"):
        make_truth(SCENARIO.with_overrides(**{"truth.model": {"file": str(ok)}}), 0)
    moved = tmp_path / "moved.h5"
    save_recording(moved, values, t, x, y, z, source=[1.0, 2.0, 0.0])
    with pytest.raises(DceeInputError, match="differs from the scenario's truth"):
        make_truth(short.with_overrides(**{"truth.model": {"file": str(moved)}}), 0)
    small = tmp_path / "small.h5"
    save_recording(small, values[:, :, :2], t, x[:2], y, z)
    with pytest.raises(DceeInputError, match="does not cover the search volume"):
        make_truth(short.with_overrides(**{"truth.model": {"file": str(small)}}), 0)


def test_scenario_file_names_its_recording_relative_to_itself(tmp_path):
    values, t, x, y, z = linear_recording(True)
    (tmp_path / "data").mkdir()
    save_recording(tmp_path / "data" / "plume.npy", values, t, x, y, z)
    (tmp_path / "site.toml").write_text(
        """
[volume]
low = [0.0, 0.0, 0.0]
high = [50.0, 50.0, 5.0]
[truth]
x = 37.5
y = 12.5
z = 1.0
q = 5.0
u = 4.0
phi = 0.0
zeta1 = 1.0
zeta2 = 8.0
model = { file = "data/plume.npy", loop = true }
[agent]
start = [2.0, 2.0, 4.0]
"""
    )
    scenario = load_scenario(str(tmp_path / "site.toml"))
    assert scenario.truth.model.file == str((tmp_path / "data" / "plume.npy").resolve())
    assert scenario.truth.model.loop
    assert scenario.truth.model_name == "playback:plume.npy"
    assert isinstance(make_truth(scenario, 0), PlaybackTruth)


# --- command line -----------------------------------------------------------------------------


def test_run_with_filament_truth_writes_a_figure_and_records_the_truth(tmp_path, capsys):
    out = tmp_path / "run"
    code, _, err = run_cli(
        ["run", "--scenario", "paper:1", "--strategy", "dcee", "--truth", "filament", "--seed", "0",
         "--particles", "500", "--hypotheses", "10", "--budget", "40", "--out", str(out), "-q"],
        capsys,
    )  # fmt: skip
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    config = json.loads((out / "config.json").read_text())
    assert summary["truth_model"] == "filament"
    assert config["scenario"]["truth"]["model"]["kind"] == "filament"
    assert (out / "figure.png").stat().st_size > 10_000


def test_run_with_a_recording_and_bad_truth_options(tmp_path, capsys):
    values, t, x, y, z = linear_recording(True)
    rec = tmp_path / "plume.h5"
    save_recording(rec, 1e-3 * values, t, x, y, z)
    base = ["run", "--scenario", "paper:1", "--strategy", "mpc", "--particles", "300",
            "--budget", "20", "-q", "--no-figure"]  # fmt: skip
    code, _, err = run_cli([*base, "--truth", str(rec), "--out", str(tmp_path / "r")], capsys)
    assert code == 0, err
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["truth_model"] == "playback:plume.h5"
    for bad, message in (("plume", "must be isotropic, filament"), ("nope.h5", "no such")):
        code, _, err = run_cli([*base, "--truth", bad, "--out", str(tmp_path / "x")], capsys)
        assert code == 2
        assert message in err and "Traceback" not in err
    assert not (tmp_path / "x").exists()


def test_bench_refuses_a_bad_recording_before_writing_anything(tmp_path, capsys):
    values, t, x, y, z = linear_recording(True)
    rec = tmp_path / "short.h5"
    save_recording(rec, values, t, x, y, z)  # 30 s, but the smoke suite flies 60 s
    out = tmp_path / "campaign"
    code, _, err = run_cli(
        ["bench", "--suite", "smoke", "--strategies", "mpc", "--repeats", "1", "--workers", "1",
         "--truth", str(rec), "--out", str(out)],
        capsys,
    )  # fmt: skip
    assert code == 2
    assert "truth.model.file: the recording lasts 30 s" in err and "Traceback" not in err
    assert not out.exists()
