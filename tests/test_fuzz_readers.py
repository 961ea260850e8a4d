"""Files from others read without trust (issue 80): every reader refuses an absurd declared
size before taking the memory, and random corruption of each format ends in a result or one
DceeInputError line (a few cases each here; ``python studies/fuzz_readers.py`` runs 1,000)."""

from __future__ import annotations

import gzip
import io

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.limits import MAX_TEXT_BYTES, check_declared, max_array_bytes
from tests.fuzz_readers import FORMATS, _gaden_grid, fuzz_environment, run_format


@pytest.fixture(autouse=True)
def _fuzz_limits(monkeypatch):
    monkeypatch.setenv("DCEE_MAX_ARRAY_BYTES", str(256 * 2**20))


@pytest.mark.parametrize("name", sorted(FORMATS))
def test_corrupt_files_are_read_or_refused_in_one_line(name, tmp_path) -> None:
    fuzz_environment()
    outcome, _ = run_format(name, 12, seed=80, scratch=tmp_path)
    assert outcome.failures == [], outcome.failures
    assert outcome.refused > 0  # the corruption reached the checks


def test_the_array_limit_is_stated_and_can_be_set(monkeypatch) -> None:
    assert max_array_bytes() == 256 * 2**20
    with pytest.raises(DceeInputError, match=r"over the 0.25 GiB limit \(DCEE_MAX_ARRAY_BYTES\)"):
        check_declared("f", "x.h5", (10**5, 10**5))
    check_declared("f", "x.h5", (1000, 1000))
    monkeypatch.setenv("DCEE_MAX_ARRAY_BYTES", "lots")
    with pytest.raises(DceeInputError, match="DCEE_MAX_ARRAY_BYTES: must be a whole number"):
        max_array_bytes()


def test_an_npy_recording_declaring_more_than_it_holds_is_refused(tmp_path) -> None:
    from dcee.simulation.playback import load_recording

    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (10, 20, 30), }".ljust(117)
    (tmp_path / "r.npy").write_bytes(b"\x93NUMPY\x01\x00v\x00" + header.encode() + b"\n" + b"x")
    (tmp_path / "r.json").write_text('{"t": [0], "x": [0], "y": [0]}')
    with pytest.raises(DceeInputError, match=r"declares \(10, 20, 30\) of float64 but holds 1 "):
        load_recording(tmp_path / "r.npy")
    huge = header.replace("(10, 20, 30)", "(10**9, 10**9, 1)".replace("**9", "000000000"))
    (tmp_path / "r.npy").write_bytes(b"\x93NUMPY\x01\x00v\x00" + huge.encode() + b"\n")
    with pytest.raises(DceeInputError, match=r"over the 0\.25 GiB limit"):
        load_recording(tmp_path / "r.npy")


def test_hdf5_and_netcdf_declaring_huge_arrays_are_refused_unread(tmp_path) -> None:
    import h5py

    from dcee.recordings.cf import read_cf_recording
    from dcee.simulation.playback import load_recording

    with h5py.File(tmp_path / "r.h5", "w") as h5:  # a few kB that declare 8 TB, chunked
        h5.create_dataset("concentration", shape=(10**6, 10**3, 10**3), dtype="f8", chunks=True)
        for k in ("t", "x", "y"):
            h5.create_dataset(k, data=np.arange(3.0))
    assert (tmp_path / "r.h5").stat().st_size < 100_000
    with pytest.raises(DceeInputError, match=r"dataset 'concentration': declares an array of"):
        load_recording(tmp_path / "r.h5")
    import h5netcdf

    with h5netcdf.File(tmp_path / "r.nc", "w") as nc:  # the same through NetCDF's own model
        nc.dimensions = {"time": 10**6, "y": 10**3, "x": 10**3}
        for dim, unit, axis in (("time", "s", "T"), ("y", "m", "Y"), ("x", "m", "X")):
            v = nc.create_variable(dim, (dim,), float, chunks=(1000,))
            v.attrs.update(units=unit, axis=axis)
        c = nc.create_variable("c", ("time", "y", "x"), float, chunks=(1, 100, 100))
        c.attrs["units"] = "g m-3"
    assert (tmp_path / "r.nc").stat().st_size < 100_000
    with pytest.raises(DceeInputError, match="variable 'c': declares an array of"):
        read_cf_recording(tmp_path / "r.nc")


def test_a_gzip_bomb_of_a_wind_csv_is_refused_while_it_expands(tmp_path) -> None:
    from dcee.recordings.gaden_files import read_wind_csv

    head = b'"U:0","U:1","U:2","Points:0","Points:1","Points:2"\n'
    buf = io.BytesIO()
    with gzip.GzipFile(fileobj=buf, mode="wb", compresslevel=1) as gz:
        gz.write(head)
        row = b"0,0,0,0.05" + b"0" * 280 + b",0.05,0.05\n"  # 300 bytes: fewer rows than cells
        for _ in range(30):  # 45 MB of text in about 0.2 MB
            gz.write(row * 5_000)
    (tmp_path / "w.csv.gz").write_bytes(buf.getvalue())
    assert len(buf.getvalue()) < 1_000_000
    with pytest.raises(DceeInputError, match="expands to more than"):
        read_wind_csv(tmp_path / "w.csv.gz", _gaden_grid())


def test_a_map_image_declaring_a_huge_size_and_an_oversized_yaml_are_refused(tmp_path) -> None:
    from dcee.models.ros_map import load_ros_map

    (tmp_path / "m.pgm").write_bytes(b"P5\n100000 100000\n255\n" + bytes(64))
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(DceeInputError, match=r"declares 100000 x 100000 pixels|cannot be read"):
        load_ros_map(tmp_path / "m.yaml")
    with (tmp_path / "big.yaml").open("wb") as fh:
        fh.truncate(MAX_TEXT_BYTES + 1)  # sparse: nothing written
    with pytest.raises(DceeInputError, match="a file read whole may hold"):
        load_ros_map(tmp_path / "big.yaml")
