"""GADEN's output (dcee.recordings.gaden) against GADEN's own player: ``reference.csv`` of both
sample rooms (tests/data/gaden, copied from shared/gaden: files written by GADEN 3.0 itself,
reference values from ``PlaybackSimulation::SampleConcentration``), a hand calculation for one
filament, and files that are truncated, corrupt, of another version or inconsistent."""

from __future__ import annotations

import math
import shutil
import struct
import zlib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from dcee.errors import DceeInputError
from dcee.recordings import gaden, gaden_files
from dcee.recordings.gaden import GadenSimulation, read_result, read_wind_csv

DATA = Path(__file__).resolve().parent / "data" / "gaden"
ROOMS = ("empty-room", "empty-room-cfd")


@pytest.mark.parametrize("room", ROOMS)
def test_the_reader_reproduces_gaden_s_player_at_every_reference_point(room):
    """72 rows each (24 points × 60, 150, 300 s): within 1e-5 relative (GADEN sums in float32),
    and exactly 0 where GADEN reads 0 (outlets, behind walls, beyond the cut-off)."""
    sim = GadenSimulation.open(DATA / room)
    ref = pd.read_csv(DATA / room / "reference.csv")
    got = np.concatenate(
        [
            sim.concentration(rows[["x", "y", "z"]].to_numpy(), float(t))
            for t, rows in ref.groupby("t_s", sort=False)
        ]
    )
    want = ref["gaden_ppm"].to_numpy()
    assert (got == 0).sum() == (want == 0).sum() >= 20
    np.testing.assert_array_equal(got == 0, want == 0)
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=0)
    # the times: iteration_k at k s (times.csv), the file in force at a time between saves
    assert sim.iteration_at(150.0) == 150 and sim.iteration_at(150.7) == 150


@pytest.mark.parametrize("room", ROOMS)
def test_the_compiled_kernel_equals_its_numpy_reference(room):
    """At 4,000 points around the filaments (each a filament's position moved by up to 1 m:
    within, at and beyond the cut-off, through the walls and doors) and 1,000 over and beyond
    the grid, at four times: the same zero pattern and values to 1e-12."""
    sim = GadenSimulation.open(DATA / room)
    rng = np.random.default_rng(3)
    for t in (5.0, 60.0, 150.0, 300.0):
        res = sim.result(sim.iteration_at(t))
        near = res.filaments[rng.integers(0, len(res.filaments), 4000), :3].astype(np.float64)
        near += rng.uniform(-1.0, 1.0, near.shape)
        far = rng.uniform([-0.5, -0.5, -0.2], [10.5, 6.5, 2.7], (1000, 3))
        pts = np.vstack([near, far])
        got = gaden.filament_concentration(pts, res, sim.occupancy, sim.grid)
        want = gaden.filament_concentration_reference(pts, res, sim.occupancy, sim.grid)
        np.testing.assert_array_equal(got > 0, want > 0)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
        assert (want > 0).sum() > 300  # the points meet the gas


def test_times_from_the_simulation_settings_match_gaden_s_table(tmp_path):
    """Without times.csv the times come from sim.yaml (a save every ⌊0.95 / 0.1⌋ + 1 = 10 steps
    of 0.1 s): the same as GADEN's table; a whole ratio is refused rather than guessed."""
    room = tmp_path / "room"
    shutil.copytree(DATA / "empty-room", room)
    table = GadenSimulation.open(room).times
    (room / "times.csv").unlink()
    np.testing.assert_allclose(GadenSimulation.open(room).times, table, atol=1e-9)
    sim = (room / "sim.yaml").read_text().replace("saveDeltaTime: 0.95", "saveDeltaTime: 1.0")
    (room / "sim.yaml").write_text(sim)
    with pytest.raises(DceeInputError, match=r"is whole: .*times\.csv"):
        GadenSimulation.open(room)


def test_the_wind_csv_and_gaden_s_wind_file_agree():
    """The CFD room's wind CSV (GADEN's OpenFOAM export format) filed cell by cell equals the
    wind file GADEN's preprocessing wrote from it; the uniform room's is 0.4 m/s along x."""
    sim = GadenSimulation.open(DATA / "empty-room-cfd")
    csv = read_wind_csv(DATA / "empty-room-cfd" / "wind_0.csv.gz", sim.grid)
    np.testing.assert_array_equal(csv, sim.wind(0))
    assert sim.wind(0)[22, 32, 5] == pytest.approx([0.405, 0.0, 0.011], abs=1e-3)  # the source
    uniform = GadenSimulation.open(DATA / "empty-room").wind(0)
    assert np.all(uniform == np.array([0.4, 0.0, 0.0], dtype=np.float32))


def _result_bytes(
    filaments: list[tuple[float, float, float, float]],
    version: tuple[int, int] = (3, 0),
    shape: tuple[int, int, int] = (20, 20, 10),
    count: int | None = None,
) -> bytes:
    """A GADEN result file (before compression) in a 2 × 2 × 1 m grid of 0.1 m cells."""
    out = struct.pack("<ii", *version) + struct.pack("<3i", *shape)
    out += struct.pack("<3f", 0, 0, 0) + struct.pack("<3f", 2, 2, 1) + struct.pack("<f", 0.1)
    out += struct.pack("<Q", 5) + b"point" + struct.pack("<3f", 0.5, 1.0, 0.5)
    out += struct.pack("<i", 0) + struct.pack("<ff", 6.440745e-6, 4.0894633e-5)
    out += struct.pack("<i", 0) + struct.pack("<Q", 9) + b"filaments"
    out += struct.pack("<Q", len(filaments) if count is None else count)
    for x, y, z, sigma in filaments:
        out += struct.pack("<4fB3x", x, y, z, sigma, 1)
    return out


def _grid() -> gaden.GadenGrid:
    return gaden.GadenGrid((20, 20, 10), np.zeros(3), np.array([2.0, 2.0, 1.0]), 0.1)


def test_one_filament_by_hand_with_its_cut_off_and_a_wall(tmp_path):
    """One filament of σ = 20 cm at (1.05, 1.05, 0.55) m: C0 = 10⁶ n / (√(8π³) σ³) / n_air at
    its centre, the Gaussian at 30 cm, nothing at 3σ = 60 cm or beyond, nothing through a wall
    of obstacle cells, nothing at a point in an outlet cell or outside the grid."""
    path = tmp_path / "iteration_0"
    path.write_bytes(zlib.compress(_result_bytes([(1.05, 1.05, 0.55, 20.0)])))
    res = read_result(path)
    free = np.zeros((20, 20, 10), dtype=np.uint8)
    c0 = 1e6 * 6.440745e-6 / (math.sqrt(8 * math.pi**3) * 20.0**3) / 4.0894633e-5
    pts = np.array([[1.05, 1.05, 0.55], [1.35, 1.05, 0.55], [1.64, 1.05, 0.55], [1.66, 1.05, 0.55]])
    got = gaden.filament_concentration(pts, res, free, _grid())
    np.testing.assert_allclose(got[:2], [c0, c0 * math.exp(-(30.0**2) / (2 * 20.0**2))], rtol=1e-5)
    assert got[2] > 0 and got[3] == 0.0  # the cut-off at 3σ = 0.60 m
    walled = free.copy()
    walled[12, :, :] = gaden_files.OBSTACLE  # x 1.2-1.3 m
    behind = gaden.filament_concentration(pts, res, walled, _grid())
    assert behind[0] == pytest.approx(c0, rel=1e-5) and np.all(behind[1:] == 0.0)
    outlet = free.copy()
    outlet[13, 10, 5] = gaden_files.OUTLET  # the cell of (1.35, 1.05, 0.55)
    assert gaden.filament_concentration(pts[1:2], res, outlet, _grid())[0] == 0.0
    assert gaden.filament_concentration(np.array([[1.05, 1.05, 1.2]]), res, free, _grid())[0] == 0.0


def _one(**kw) -> bytes:
    return zlib.compress(_result_bytes([(1, 1, 0.5, 10)], **kw))


BAD_RESULTS = {
    "cut-short": (lambda: _one()[:-9], "truncated"),
    "not-zlib": (lambda: b"not zlib at all", "not a zlib stream or corrupt"),
    "version": (lambda: _one(version=(2, 5)), "version 2.5; this reader knows 3.0"),
    "absurd-count": (lambda: _one(count=2**40), "declares 1,099,511,627,776 filaments"),
    "absurd-grid": (lambda: _one(shape=(10**5, 10**5, 10**5)), "1 to 200,000,000 cells"),
    "header-cut": (
        lambda: zlib.compress(_result_bytes([(1, 1, 0.5, 10)])[:30]),
        "truncated: the file ends inside",
    ),
}


@pytest.mark.parametrize(("make", "message"), BAD_RESULTS.values(), ids=BAD_RESULTS.keys())
def test_a_bad_result_file_is_one_line_naming_what_is_wrong(tmp_path, make, message):
    path = tmp_path / "iteration_0"
    path.write_bytes(make())
    with pytest.raises(DceeInputError, match=message) as err:
        read_result(path)
    assert "\n" not in str(err.value) and str(path) in str(err.value)


def test_a_flipped_byte_in_a_sample_file_is_refused(tmp_path):
    """zlib's checksum catches a flipped bit anywhere in the stream (every position tried in
    steps): refused in one line, never a wrong field or a traceback."""
    raw = bytearray((DATA / "empty-room" / "result" / "iteration_60").read_bytes())
    path = tmp_path / "iteration_60"
    for where in range(2, len(raw), max(1, len(raw) // 40)):
        bad = raw.copy()
        bad[where] ^= 0x10
        path.write_bytes(bytes(bad))
        with pytest.raises(DceeInputError, match="GADEN"):
            read_result(path)


def test_a_file_that_would_expand_beyond_the_cap_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(gaden_files, "MAX_DECOMPRESSED_BYTES", 2**20)
    path = tmp_path / "iteration_0"
    path.write_bytes(zlib.compress(bytes(4 * 2**20)))
    with pytest.raises(DceeInputError, match="decompresses to more than 1 MiB"):
        read_result(path)


def test_an_inconsistent_folder_is_refused_before_any_work(tmp_path):
    room = tmp_path / "room"
    shutil.copytree(DATA / "empty-room", room)
    (room / "result" / "iteration_7").unlink()
    with pytest.raises(DceeInputError, match="iteration_7 is missing"):
        GadenSimulation.open(room)
    shutil.rmtree(room)
    shutil.copytree(DATA / "empty-room", room)
    (room / "result" / "iteration_0").write_bytes(zlib.compress(_result_bytes([(1, 1, 0.5, 10)])))
    with pytest.raises(
        DceeInputError,
        match=r"its grid \(20×20×10 cells .* is not the occupancy grid's \(104×64×25",
    ):
        GadenSimulation.open(room)
    (room / "OccupancyGrid3D.csv").unlink()
    with pytest.raises(DceeInputError, match="needs its occupancy grid"):
        GadenSimulation.open(room)
    with pytest.raises(DceeInputError, match="no such folder"):
        GadenSimulation.open(tmp_path / "nowhere")


def test_a_corrupt_occupancy_grid_or_wind_file_is_refused(tmp_path):
    grid_text = (DATA / "empty-room" / "OccupancyGrid3D.csv").read_text()
    bad = tmp_path / "OccupancyGrid3D.csv"
    bad.write_text(grid_text.replace("#num_cells 104 64 25", "#num_cells 104 64 26"))
    with pytest.raises(DceeInputError, match="rows of cells; the header's grid needs"):
        gaden.read_occupancy(bad)
    bad.write_text(grid_text.replace("1 1 1 2 2", "1 1 1 7 2", 1))
    with pytest.raises(DceeInputError, match="cell values 0, 1 or 2"):
        gaden.read_occupancy(bad)
    wind = tmp_path / "wind_iteration_0"
    wind.write_bytes((DATA / "empty-room" / "wind" / "wind_iteration_0").read_bytes()[:-12])
    with pytest.raises(DceeInputError, match="bytes; the grid's 166,400 cells need 1,996,808"):
        gaden.read_wind(wind, GadenSimulation.open(DATA / "empty-room").grid)
