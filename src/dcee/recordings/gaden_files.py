"""GADEN's files (Monroy et al., Sensors 17(7) 1479, 2017; MAPIRlab's ``gaden_core`` 3.0) read as
GADEN writes them; :mod:`dcee.recordings.gaden` computes the concentration from them.

A GADEN simulation folder (laid out as ``shared/gaden/empty-room``, docs/guide/plume-data.md):

* ``result/iteration_<k>``: one zlib stream each (RFC 1950). Decompressed: version (int32
  major, minor; 3.0 is read, anything else refused), the grid (3 × int32 cell counts, float32 min
  and max corners in m, float32 cell size in m), the source (a length-prefixed type name, its
  float32 fields, float32 position), int32 gas type, float32 ``totalMolesInFilament`` (mol),
  float32 ``numMolesAllGasesIncm3`` (mol/cm³), int32 wind index, a length-prefixed mode
  (``filaments``; ``concentrations`` is refused), uint64 N and N filaments of 20 bytes (float32
  x, y, z in m, float32 σ in cm, uint8 active, 3 padding bytes). Little-endian throughout.
* ``OccupancyGrid3D.csv``: four header lines (min, max, cell counts, cell size), then per z
  layer nx lines of ny values (0 free, 1 obstacle, 2 outlet) and a line ``;``.
* ``wind/wind_iteration_<i>``: int32 3, int32 0, then nx·ny·nz float32 (u, v, w) m/s, flat index
  i + nx (j + ny k).
* The files carry no time: ``times.csv`` (``file,t_s``) gives it where present; else
  ``sim.yaml``'s ``deltaTime`` and ``saveDeltaTime``: GADEN saves at step 0 and then whenever its
  clock exceeds the last save time by more than ``saveDeltaTime``, so every
  ⌊saveDeltaTime / deltaTime⌋ + 1 steps; where that ratio is a whole number GADEN's float32 clock
  decides, and the reader asks for ``times.csv`` instead of guessing.

Untrusted input: a decompressed file larger than :data:`MAX_DECOMPRESSED_BYTES`, a grid of more
than :data:`MAX_CELLS` cells or a filament count that the file's length does not hold is refused
in one line before the memory is taken; so are a truncated or corrupt stream, an unknown version
and a grid that does not match the occupancy grid's.
"""

from __future__ import annotations

import gzip
import io
import math
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from dcee.errors import DceeInputError
from dcee.limits import CappedStream, read_text

SUPPORTED_VERSIONS = ((3, 0),)
"""(major, minor) versions of GADEN's result and wind files that this reader knows."""
MAX_DECOMPRESSED_BYTES = 256 * 2**20
"""A result file that decompresses to more than this is refused (about 13 million filaments)."""
MAX_CELLS = 200_000_000
"""A grid of more cells than this is refused (2.4 GB of wind as float32)."""
GAS_MOLAR_MASS = {0: 46.07}
"""g/mol of GADEN's gas types known by number (``gasType`` in ``sim.yaml`` and the result files):
0, ethanol (the samples'); another gas needs its molar mass given."""
FREE, OBSTACLE, OUTLET = 0, 1, 2
"""GADEN's cell states in the occupancy grid."""
_FILAMENT = np.dtype([("xyz", "<f4", 3), ("sigma", "<f4"), ("active", "u1"), ("pad", "u1", 3)])
_SOURCE_FIELDS = {"point": 0, "box": 3, "line": 3, "sphere": 1, "cylinder": 2}
"""float32 fields each source type stores before its position (gaden_core's ``Sources``)."""


def gaden_error(where: Path | str, message: str) -> DceeInputError:
    """The one-line error for a problem with the GADEN file or folder ``where``."""
    return DceeInputError(f"GADEN {where}", message)


@dataclass(frozen=True)
class GadenGrid:
    """GADEN's environment grid: ``shape`` (nx, ny, nz) cells of ``cell`` m from ``low`` (3,) m
    to ``high`` (3,) m."""

    shape: tuple[int, int, int]
    low: np.ndarray
    high: np.ndarray
    cell: float

    def matches(self, other: GadenGrid) -> bool:
        return (
            self.shape == other.shape
            and np.allclose(self.low, other.low, atol=1e-5)
            and np.allclose(self.high, other.high, atol=1e-5)
            and abs(self.cell - other.cell) < 1e-6
        )

    def describe(self) -> str:
        lo, hi = (", ".join(f"{v:g}" for v in a) for a in (self.low, self.high))
        nx, ny, nz = self.shape
        return f"{nx}×{ny}×{nz} cells of {self.cell:g} m, ({lo}) to ({hi})"

    def cells(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(M, 3) int64 cell indices of ``points`` (M, 3) m and (M,) whether each is inside the
        grid: ⌊(p − low) / cell⌋ in float32, truncated toward zero as GADEN does (so the slab
        just below ``low`` maps to index 0 too), inside where 0 ≤ index < shape."""
        rel = (points.astype(np.float32) - self.low.astype(np.float32)) / np.float32(self.cell)
        idx = np.trunc(rel).astype(np.int64)
        inside = np.all((idx >= 0) & (idx < np.array(self.shape)), axis=-1)
        return idx, inside


@dataclass(frozen=True)
class GadenResult:
    """One ``result/iteration_<k>`` file: the grid, the source and gas constants, the filaments
    (N, 4) float32: x, y, z (m) and σ (cm), oldest first."""

    version: tuple[int, int]
    grid: GadenGrid
    source_type: str
    source_position: np.ndarray
    gas_type: int
    moles_per_filament: float
    moles_per_cm3: float
    wind_index: int
    filaments: np.ndarray


class _Reader:
    """Bounds-checked little-endian reads from a decompressed file."""

    def __init__(self, data: bytes, where: Path) -> None:
        self.data, self.pos, self.where = data, 0, where

    def take(self, fmt: str, what: str) -> tuple:
        size = struct.calcsize("<" + fmt)
        if self.pos + size > len(self.data):
            raise gaden_error(
                self.where, f"truncated: the file ends inside {what} (byte {self.pos})"
            )
        out = struct.unpack_from("<" + fmt, self.data, self.pos)
        self.pos += size
        return out

    def text(self, what: str, limit: int = 64) -> str:
        (n,) = self.take("Q", what)
        if n > limit:
            raise gaden_error(self.where, f"{what} is {n} bytes long; at most {limit} are allowed")
        (raw,) = self.take(f"{n}s", what)
        try:
            return raw.decode("ascii")
        except UnicodeDecodeError:
            raise gaden_error(self.where, f"{what} is not ASCII text") from None


def _decompress(path: Path) -> bytes:
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise gaden_error(path, "no such file") from None
    except OSError as exc:
        raise gaden_error(path, f"cannot be read ({exc.strerror})") from None
    inflater = zlib.decompressobj()
    try:
        data = inflater.decompress(raw, MAX_DECOMPRESSED_BYTES)
    except zlib.error as exc:
        raise gaden_error(path, f"not a zlib stream or corrupt ({exc})") from None
    if inflater.unconsumed_tail:
        raise gaden_error(path, f"decompresses to more than {MAX_DECOMPRESSED_BYTES // 2**20} MiB")
    if not inflater.eof:
        raise gaden_error(path, "truncated: the zlib stream ends early")
    return data


def _version(reader: _Reader) -> tuple[int, int]:
    version = reader.take("ii", "the version")
    if version not in SUPPORTED_VERSIONS:
        known = ", ".join(f"{a}.{b}" for a, b in SUPPORTED_VERSIONS)
        raise gaden_error(
            reader.where, f"version {version[0]}.{version[1]}; this reader knows {known}"
        )
    return version


def _grid(shape: tuple, low: tuple, high: tuple, cell: float, where: Path | str) -> GadenGrid:
    if not all(0 < n for n in shape) or math.prod(shape) > MAX_CELLS:
        raise gaden_error(where, f"a grid of {shape} cells; 1 to {MAX_CELLS:,} cells are allowed")
    if not (math.isfinite(cell) and cell > 0) or not all(map(math.isfinite, low + high)):
        raise gaden_error(
            where, f"grid corners {low}, {high} and cell {cell} must be finite, cell > 0"
        )
    return GadenGrid(tuple(int(n) for n in shape), np.array(low), np.array(high), float(cell))


def read_result(path: str | Path) -> GadenResult:
    """One GADEN result file (``result/iteration_<k>``), every field checked."""
    path = Path(path)
    reader = _Reader(_decompress(path), path)
    version = _version(reader)
    shape = reader.take("3i", "the cell counts")
    low, high = reader.take("3f", "the grid's min corner"), reader.take("3f", "its max corner")
    (cell,) = reader.take("f", "the cell size")
    grid = _grid(shape, low, high, cell, path)
    source_type = reader.text("the source type")
    if source_type not in _SOURCE_FIELDS:
        raise gaden_error(path, f"source type {source_type!r}; known: {', '.join(_SOURCE_FIELDS)}")
    reader.take(f"{_SOURCE_FIELDS[source_type]}f", "the source's fields")
    position = np.array(reader.take("3f", "the source position"))
    (gas_type,) = reader.take("i", "the gas type")
    moles, air = reader.take("ff", "the filament constants")
    (wind_index,) = reader.take("i", "the wind index")
    mode = reader.text("the mode")
    if mode != "filaments":
        raise gaden_error(path, f"mode {mode!r}; only 'filaments' results are read")
    if not (moles > 0 and air > 0 and math.isfinite(moles) and math.isfinite(air)):
        raise gaden_error(path, f"filament constants {moles}, {air} mol must be finite and > 0")
    (count,) = reader.take("Q", "the filament count")
    left = len(reader.data) - reader.pos
    if count * _FILAMENT.itemsize != left:
        raise gaden_error(
            path,
            f"declares {count:,} filaments ({count * _FILAMENT.itemsize:,} bytes) but "
            f"{left:,} bytes follow: truncated or corrupt",
        )
    records = np.frombuffer(reader.data, dtype=_FILAMENT, count=count, offset=reader.pos)
    filaments = np.column_stack([records["xyz"], records["sigma"]]).astype(np.float32)
    filaments = np.ascontiguousarray(filaments[records["active"] != 0])
    if not np.all(np.isfinite(filaments)) or np.any(filaments[:, 3] <= 0):
        raise gaden_error(path, "a filament with a non-finite position or σ ≤ 0: corrupt")
    return GadenResult(
        version, grid, source_type, position, gas_type, moles, air, wind_index, filaments
    )


def read_occupancy(path: str | Path) -> tuple[GadenGrid, np.ndarray]:
    """GADEN's ``OccupancyGrid3D.csv``: the grid and its cells (nx, ny, nz) uint8 (0 free,
    1 obstacle, 2 outlet)."""
    path = Path(path)
    try:
        lines = read_text(path, "GADEN", encoding="ascii").splitlines()
    except FileNotFoundError:
        raise gaden_error(path, "no such file: a GADEN folder needs its occupancy grid") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise gaden_error(path, f"cannot be read as text ({exc})") from None
    heads = ("#env_min", "#env_max", "#num_cells", "#cell_size")
    values = []
    for k, head in enumerate(heads):
        if len(lines) <= k or not lines[k].startswith(head):
            raise gaden_error(path, f"line {k + 1} must start with {head}")
        try:
            values.append([float(v) for v in lines[k].split()[1:]])
        except ValueError:
            raise gaden_error(path, f"line {k + 1}: not numbers") from None
    if [len(v) for v in values] != [3, 3, 3, 1] or any(n != int(n) for n in values[2]):
        raise gaden_error(
            path, "the header needs 3 min, 3 max, 3 whole cell counts and 1 cell size"
        )
    grid = _grid(tuple(int(n) for n in values[2]), tuple(values[0]), tuple(values[1]),
                 values[3][0], path)  # fmt: skip
    nx, ny, nz = grid.shape
    rows = [ln for ln in lines[4:] if ln.strip() and ln.strip() != ";"]
    if len(rows) != nx * nz:
        raise gaden_error(path, f"{len(rows)} rows of cells; the header's grid needs {nx * nz}")
    cells = np.empty((nx * nz, ny), dtype=np.uint8)
    for k, row in enumerate(rows):  # row by row: no list of every cell's text at once
        values = row.split()
        if len(values) != ny or not all(v in ("0", "1", "2") for v in values):
            raise gaden_error(path, f"row {k + 5}: every row needs {ny} cell values 0, 1 or 2")
        cells[k] = np.array(values, dtype=np.uint8)
    return grid, cells.reshape(nz, nx, ny).transpose(1, 2, 0).copy()


def read_wind(path: str | Path, grid: GadenGrid) -> np.ndarray:
    """GADEN's preprocessed wind file: (nx, ny, nz, 3) float32 m/s."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise gaden_error(path, f"cannot be read ({exc.strerror})") from None
    reader = _Reader(raw, path)
    _version(reader)
    n = math.prod(grid.shape)
    if len(raw) != 8 + 12 * n:
        raise gaden_error(path, f"{len(raw):,} bytes; the grid's {n:,} cells need {8 + 12 * n:,}")
    flat = np.frombuffer(raw, dtype="<f4", offset=8).reshape(n, 3)
    nx, ny, nz = grid.shape
    return flat.reshape(nz, ny, nx, 3).transpose(2, 1, 0, 3).copy()


def read_wind_csv(path: str | Path, grid: GadenGrid) -> np.ndarray:
    """A wind CSV as GADEN's preprocessing reads it (its OpenFOAM export: columns ``U:0``,
    ``U:1``, ``U:2`` in m/s and ``Points:0``, ``Points:1``, ``Points:2`` in m, one row per cell
    centre, gzip allowed): (nx, ny, nz, 3) float32, each row filed in the cell of its point,
    cells without a row 0."""
    import pandas as pd

    path = Path(path)
    columns = ["U:0", "U:1", "U:2", "Points:0", "Points:1", "Points:2"]
    cells = math.prod(grid.shape)
    # a row of six numbers as GADEN's export writes them is under 128 bytes: a file that
    # expands (gzip) to more than that per cell is refused before pandas holds it
    limit = 128 * (cells + 1)
    try:
        raw = gzip.open(path) if path.suffix == ".gz" else path.open("rb")
        with io.BufferedReader(CappedStream(raw, limit, "GADEN", str(path))) as stream:
            frame = pd.read_csv(stream, usecols=columns, dtype=np.float64, nrows=cells + 1)
    except FileNotFoundError:
        raise gaden_error(path, "no such file") from None
    except DceeInputError:
        raise
    except (ValueError, OSError, EOFError, zlib.error, pd.errors.ParserError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise gaden_error(path, f"needs numeric columns {', '.join(columns)} ({first})") from None
    if len(frame) > math.prod(grid.shape) or not np.all(np.isfinite(frame.to_numpy())):
        raise gaden_error(path, "more rows than the grid has cells, or a value that is not finite")
    idx, inside = grid.cells(frame[columns[3:]].to_numpy())
    if not inside.all():
        raise gaden_error(path, f"row {int(np.argmin(inside)) + 2}: a point outside the grid")
    wind = np.zeros((*grid.shape, 3), dtype=np.float32)
    wind[idx[:, 0], idx[:, 1], idx[:, 2]] = frame[columns[:3]].to_numpy(dtype=np.float32)
    return wind
