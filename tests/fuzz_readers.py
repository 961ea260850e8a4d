"""Fuzzing every reader of files written elsewhere (issue 80): a valid sample of each format,
corrupted at random, must give a result or one :class:`~dcee.errors.DceeInputError` line —
never another exception, a hang or an allocation beyond the limits (:mod:`dcee.limits`).

Used by ``tests/test_fuzz_readers.py`` (a few cases per format, every run) and by the
benchmark ``python studies/fuzz_readers.py`` (thousands, output in docs/results/fuzz/).

Each format has a sample maker (a valid file or folder written into a scratch folder), the
files of it that are corrupted, and the entry points a user's command reaches. A case changes
one file of the sample: random bytes set (1-8), a random span overwritten, a cut, a span
repeated, or an aligned 4- or 8-byte word set to an extreme (the sizes and counts of binary
headers); for a compressed format, half the cases corrupt the content and compress it again
(so the parser, not only the decompressor, sees it); for a checkpoint, half corrupt its JSON
header and repack it with the checksum and digest a forger recomputes (so the state decoder
sees it), and half of the rest recompute the digest.
"""

from __future__ import annotations

import gzip
import hashlib
import io
import json
import os
import shutil
import signal
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from dcee.errors import DceeInputError

ROOT = Path(__file__).resolve().parent
GADEN = ROOT / "data" / "gaden"
EXTREMES = (0xFFFFFFFF, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFFFFFFFFFF, 0x7FFFFFFFFFFFFFFF, 0)


@dataclass(frozen=True)
class Format:
    """A format's sample, the files of the sample a case corrupts (relative to the sample
    where it is a folder), how a corrupted file is rewritten (``wrap``: compress again,
    re-sign) and the readers a user reaches."""

    make: Callable[[Path], Path]
    targets: tuple[str, ...]
    read: Callable[[Path], object]
    unwrap: Callable[[bytes], bytes] | None = None
    wrap: Callable[[bytes, bytes], bytes] | None = None
    """(corrupted content, the original file) → the file (compressed again, repacked)"""
    resign: Callable[[bytes], bytes] | None = None
    """a corrupted file → the same with the digest a forger recomputes"""
    mutate: Callable[[bytes, np.random.Generator], bytes] | None = None
    """the unwrapped content's corruption where bytes are not enough (default :func:`corrupt`)"""


# --- samples ------------------------------------------------------------------------------------


def _recording(folder: Path, suffix: str) -> Path:
    from dcee.simulation.playback import save_recording

    rng = np.random.default_rng(0)
    t, x, y = np.arange(4.0), np.linspace(0, 10, 6), np.linspace(0, 8, 5)
    path = folder / f"rec{suffix}"
    save_recording(path, rng.random((4, 5, 6)), t, x, y, source=np.array([1.0, 2.0, 0.5]))
    return path


def _netcdf(folder: Path) -> Path:
    import xarray as xr

    rng = np.random.default_rng(0)
    ds = xr.Dataset(
        {"c": (("time", "y", "x"), rng.random((4, 5, 6)), {"units": "g m-3"})},
        coords={
            "time": ("time", np.arange(4.0), {"units": "s", "axis": "T"}),
            "y": ("y", np.linspace(0, 8, 5), {"units": "m", "axis": "Y"}),
            "x": ("x", np.linspace(0, 10, 6), {"units": "m", "axis": "X"}),
            "z": ((), 2.0, {"units": "m", "axis": "Z"}),
        },
    )
    path = folder / "rec.nc"
    ds.to_netcdf(path, engine="h5netcdf")
    return path


def _gaden_room(folder: Path) -> Path:
    """A GADEN folder of the sample room cut to three result files."""
    room = folder / "room"
    (room / "result").mkdir(parents=True)
    src = GADEN / "empty-room-cfd"
    for name in ("OccupancyGrid3D.csv", "sim.yaml", "times.csv"):
        shutil.copy(src / name, room / name)
    for k in range(3):
        shutil.copy(src / "result" / f"iteration_{k}", room / "result" / f"iteration_{k}")
    lines = (room / "times.csv").read_text().splitlines()
    (room / "times.csv").write_text("\n".join(lines[:4]) + "\n")
    (room / "wind").mkdir()
    shutil.copy(src / "wind" / "wind_iteration_0", room / "wind" / "wind_iteration_0")
    # the solver's wind CSV cut to its first 3,000 rows (cells without a row read as calm)
    rows = gzip.decompress((src / "wind_0.csv.gz").read_bytes()).splitlines()[:3001]
    (room / "wind_0.csv.gz").write_bytes(gzip.compress(b"\n".join(rows) + b"\n"))
    return room


def _map(folder: Path) -> Path:
    from dcee.models.ros_map import write_ros_map
    from dcee.models.site import SiteMap

    blocked = np.zeros((20, 30), bool)
    blocked[5:9, 10:20] = True
    return write_ros_map(SiteMap(blocked, (0.0, 0.0), 0.5, name="fuzz"), folder / "map.yaml")


def _bag(folder: Path) -> Path:
    from dcee.robot.bag import BagWriter

    bag = folder / "bag"
    with BagWriter(bag) as writer:
        for k in range(5):
            t = 1.0 + k
            writer.write_search_step(t, pose=(1.0 + k, 2.0, 0.0, 0.0, 0.0), reading=0.1 * k)
            writer.write_search_step(t, goal=(2.0 + k, 2.0, 0.0))
    return bag


def _checkpoint(folder: Path) -> Path:
    from dcee.planning import get as get_planner
    from dcee.runs import make_searcher, streams
    from dcee.scenarios import load_scenario

    sc = load_scenario("paper:1").with_overrides(**{"search.particles": 200})
    _, filter_rng, planner_rng, _ = streams(0)
    searcher = make_searcher(sc, get_planner("infotaxis"), filter_rng, planner_rng)
    for k in range(2):
        searcher.tell(np.array([2.0 + k, 2.0, 4.0]), 0.0, time=float(k))
    return searcher.save(folder / "search.ckpt")


# --- readers ------------------------------------------------------------------------------------


def _read_recording(path: Path) -> object:
    from dcee.recordings import recording_layout
    from dcee.simulation.playback import load_recording

    recording_layout(path)
    return load_recording(path)


def _read_cf(path: Path) -> object:
    from dcee.recordings.cf import cf_layout, read_cf_recording

    cf_layout(path)
    return read_cf_recording(path)


def _gaden_grid():
    from dcee.recordings.gaden_files import read_occupancy

    return read_occupancy(GADEN / "empty-room-cfd" / "OccupancyGrid3D.csv")[0]


def _read_gaden_folder(room: Path) -> object:
    from dcee.recordings.gaden import GadenSimulation

    sim = GadenSimulation.open(room)
    for k in sim.iterations:
        sim.result(int(k))
    return sim.wind(0)


def _read_wind_csv(room: Path) -> object:
    from dcee.recordings.gaden_files import read_wind_csv

    return read_wind_csv(room / "wind_0.csv.gz", _gaden_grid())


def _read_map(path: Path) -> object:
    from dcee.models.ros_map import load_ros_map

    return load_ros_map(path)


def _read_bag(path: Path) -> object:
    from dcee.robot.bag import read_events

    return read_events(path)


def _read_checkpoint(path: Path) -> object:
    from dcee.searcher import Searcher

    return Searcher.load(path)


def _resign(data: bytes) -> bytes:
    body = bytearray(data)
    if len(body) > 64:
        body[-64:] = hashlib.sha256(body[:-64]).hexdigest().encode()
    return bytes(body)


def _checkpoint_header(data: bytes) -> bytes:
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        return zf.read("header.json")


PALETTE = (
    0, -1, 2**63, 2**200, 1.5, -1e308, "x", "", None, True, [], [1, [2, [3]]],
    {"dict": [[1, 2], [[], 3]]}, {"tuple": "x"}, {"set": [[1]]}, {"float": "nan"},
    {"float": "1e999"}, {"array": ["a0", 0]}, {"array": ["zz", 99]}, {"ref": 0}, {"ref": 10**6},
    {"scalar": ["<f8", 1.0]}, {"scalar": ["|O", 1]}, {"scalar": ["<i2", 10**9]},
    {"rng": ["PCG64", 900, {"dict": []}]}, {"rng": ["Evil", 901, None]},
    {"object": ["dcee.searcher:Searcher", 902, {"dict": []}]},
    {"object": ["dcee.searcher:Searcher", 903, 5]},
    {"object": ["dcee.models.plume:IsotropicPlume", 904, {"dict": [["meander", "x"]]}]},
    {"object": ["os:system", 905, None]}, {"object": ["dcee.io:write_json", 906, None]},
    {"enum": ["dcee.searcher:Searcher", 1]}, {"namedtuple": ["dcee.searcher:Searcher", []]},
    {"unknown-tag": 1}, {"a": 1, "b": 2},
)  # fmt: skip
"""What a forger may put anywhere in a checkpoint's state (every tag, good and bad)."""


def _mutate_json(header: bytes, rng: np.random.Generator) -> bytes:
    """The header with 1-3 random nodes of its JSON replaced from :data:`PALETTE` (or its
    bytes corrupted where it does not parse)."""
    try:
        doc = json.loads(header)
    except ValueError:
        return corrupt(header, rng)
    for _ in range(int(rng.integers(1, 4))):
        slots = _slots(doc, [])
        parent, key = slots[int(rng.integers(0, len(slots)))]
        value = PALETTE[int(rng.integers(0, len(PALETTE)))]
        parent[key] = json.loads(json.dumps(value))  # type: ignore[index]
    return json.dumps(doc).encode()


def _slots(node: object, out: list) -> list:
    """(container, key) of every value inside ``node``."""
    items = (
        node.items()
        if isinstance(node, dict)
        else enumerate(node)
        if isinstance(node, list)
        else ()
    )
    for k, v in items:
        out.append((node, k))
        _slots(v, out)
    return out


def _checkpoint_repack(header: bytes, original: bytes) -> bytes:
    """A checkpoint with ``header`` (corrupted) and the original's arrays, its checksum (where
    the header still parses) and digest recomputed: what reaches the state decoder."""
    from dcee.state_file import DIGEST, checksum

    with zipfile.ZipFile(io.BytesIO(original)) as zf:
        members = {n: zf.read(n) for n in zf.namelist() if n != "header.json"}
    try:
        doc = json.loads(header)
        arrays = {n[:-4]: np.load(io.BytesIO(b)) for n, b in members.items()}
        doc["checksum"] = checksum(doc, arrays)
        header = json.dumps(doc).encode()
    except Exception:  # not JSON any more, or not a dict: left as it is
        pass
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("header.json", header)
        for name, data in members.items():
            zf.writestr(name, data)
        zf.comment = DIGEST + b"0" * 64
    return _resign(buf.getvalue())


FORMATS: dict[str, Format] = {
    "recording .npy": Format(
        lambda d: _recording(d, ".npy"), ("rec.npy", "rec.json"), _read_recording
    ),
    "recording .h5": Format(lambda d: _recording(d, ".h5"), ("rec.h5",), _read_recording),
    "CF NetCDF": Format(_netcdf, ("rec.nc",), _read_cf),
    "GADEN result": Format(
        _gaden_room,
        ("result/iteration_1",),
        _read_gaden_folder,
        unwrap=zlib.decompress,
        wrap=lambda content, _: zlib.compress(content),
    ),
    "GADEN folder": Format(
        _gaden_room,
        ("OccupancyGrid3D.csv", "sim.yaml", "times.csv", "wind/wind_iteration_0"),
        _read_gaden_folder,
    ),
    "GADEN wind CSV": Format(
        _gaden_room,
        ("wind_0.csv.gz",),
        _read_wind_csv,
        unwrap=gzip.decompress,
        wrap=lambda content, _: gzip.compress(content),
    ),
    "ROS map": Format(_map, ("map.yaml", "map.pgm"), _read_map),
    "ROS 2 bag": Format(_bag, ("metadata.yaml", "bag.mcap"), _read_bag),
    "checkpoint": Format(
        _checkpoint,
        ("search.ckpt",),
        _read_checkpoint,
        unwrap=_checkpoint_header,
        wrap=_checkpoint_repack,
        resign=_resign,
        mutate=lambda header, rng: (
            _mutate_json(header, rng) if rng.random() < 0.8 else corrupt(header, rng)
        ),
    ),
}


# --- cases --------------------------------------------------------------------------------------


def corrupt(data: bytes, rng: np.random.Generator) -> bytes:
    """One random corruption of ``data`` (module doc)."""
    out = bytearray(data)
    n = len(out)
    if n == 0:
        return bytes(rng.integers(0, 256, size=int(rng.integers(1, 64)), dtype=np.uint8))
    kind = int(rng.integers(0, 5))
    if kind == 0:
        for at in rng.integers(0, n, size=int(rng.integers(1, 9))):
            out[at] = int(rng.integers(0, 256))
    elif kind == 1:
        at = int(rng.integers(0, n))
        span = int(rng.integers(1, min(256, n - at) + 1))
        out[at : at + span] = rng.integers(0, 256, size=span, dtype=np.uint8).tobytes()
    elif kind == 2:
        out = out[: int(rng.integers(0, n))]
    elif kind == 3:
        at = int(rng.integers(0, n))
        span = int(rng.integers(1, min(4096, n - at) + 1))
        out[at:at] = out[at : at + span]
    else:
        width = 8 if rng.random() < 0.5 else 4
        at = int(rng.integers(0, max(n // width, 1))) * width
        value = int(EXTREMES[int(rng.integers(0, len(EXTREMES)))]) & (2 ** (8 * width) - 1)
        out[at : at + width] = value.to_bytes(width, "little")[: len(out[at : at + width])]
    return bytes(out)


@dataclass
class Outcome:
    read: int = 0
    refused: int = 0
    failures: list[str] = field(default_factory=list)


class _Timeout(Exception):
    pass


def _alarm(signum: int, frame: object) -> None:
    raise _Timeout


def run_format(
    name: str, cases: int, seed: int, scratch: Path, timeout: int = 30
) -> tuple[Outcome, float]:
    """Run ``cases`` corrupted variants of format ``name``; (outcome, seconds)."""
    import time

    fmt = FORMATS[name]
    rng = np.random.default_rng(seed)
    base = scratch / "sample"
    shutil.rmtree(base, ignore_errors=True)
    base.mkdir(parents=True)
    sample = fmt.make(base)
    work = scratch / "case"
    outcome = Outcome()
    previous = signal.signal(signal.SIGALRM, _alarm)
    t0 = time.perf_counter()
    try:
        for case in range(cases):
            shutil.rmtree(work, ignore_errors=True)
            shutil.copytree(base, work)
            target = fmt.targets[int(rng.integers(0, len(fmt.targets)))]
            root = sample if sample.is_dir() else base  # targets are relative to it
            target = str((root / target).relative_to(base))
            original = (base / target).read_bytes()
            content = original
            if fmt.unwrap is not None and fmt.wrap is not None and rng.random() < 0.5:
                mutate = fmt.mutate or corrupt
                content = fmt.wrap(mutate(fmt.unwrap(original), rng), original)
            else:
                content = corrupt(original, rng)
                if fmt.resign is not None and rng.random() < 0.5:
                    content = fmt.resign(content)
            (work / target).write_bytes(content)
            entry = work / sample.relative_to(base)
            signal.alarm(timeout)
            try:
                fmt.read(entry)
                outcome.read += 1
            except DceeInputError as exc:
                if "\n" in str(exc):
                    outcome.failures.append(f"case {case} ({target}): a message of several lines")
                else:
                    outcome.refused += 1
            except _Timeout:
                outcome.failures.append(f"case {case} ({target}): no answer in {timeout} s")
            except Exception as exc:  # what the fuzz is for: anything else is a failure
                first = str(exc).splitlines()[0][:120] if str(exc) else ""
                outcome.failures.append(f"case {case} ({target}): {type(exc).__name__}: {first}")
            finally:
                signal.alarm(0)
    finally:
        signal.signal(signal.SIGALRM, previous)
        shutil.rmtree(work, ignore_errors=True)
    return outcome, time.perf_counter() - t0


FUZZ_ARRAY_LIMIT = str(256 * 2**20)
"""The array limit (DCEE_MAX_ARRAY_BYTES) the fuzz runs under: every declared size above 256 MiB
is refused, so no case can make the machine allocate more."""


def fuzz_environment() -> None:
    """Set the limits the fuzz runs under (:data:`FUZZ_ARRAY_LIMIT`)."""
    os.environ["DCEE_MAX_ARRAY_BYTES"] = FUZZ_ARRAY_LIMIT
