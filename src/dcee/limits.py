"""What a reader of a file written elsewhere will allocate: the limits, checked against what a
file *declares* (an array's shape, a compressed stream's size) before the memory is taken.

A recording, a map, a simulation output or a checkpoint may come from anyone: a few bytes of
HDF5 can declare a petabyte dataset, a kilobyte of gzip can expand to gigabytes. Each reader
checks the declared size against these limits first and refuses in one line
(:class:`~dcee.errors.DceeInputError`) naming the file, what it declares and the limit; the
fuzz benchmark (``python studies/fuzz_readers.py``) feeds every reader corrupt and absurd files.

The limits are far above any real input measured here (docs/guide/plume-data.md): the largest
recording, the 3-D plume of a release cell (240 × 20 × 48 × 75), holds 0.14 GB as float64.
``DCEE_MAX_ARRAY_BYTES`` (bytes) raises or lowers the array limit for a machine that needs it.
"""

from __future__ import annotations

import io
import math
import os
from pathlib import Path
from typing import IO, Any

from dcee.errors import DceeInputError

DEFAULT_MAX_ARRAY_BYTES = 8 * 2**30
"""8 GiB: the largest array a reader makes (after conversion to float64), unless
``DCEE_MAX_ARRAY_BYTES`` says otherwise."""

MAX_TEXT_BYTES = 64 * 2**20
"""64 MiB: the largest text file read whole (a map's YAML, a recording's JSON metadata, GADEN's
occupancy grid: 32 million cells)."""

MAX_IMAGE_PIXELS = 2**26
"""67 million pixels: the largest map image read (an 8 km square at 1 m, 400 m at 5 cm; below
Pillow's own decompression-bomb warning at 89 million)."""


def max_array_bytes() -> int:
    """The array limit in bytes (:data:`DEFAULT_MAX_ARRAY_BYTES` or ``DCEE_MAX_ARRAY_BYTES``)."""
    raw = os.environ.get("DCEE_MAX_ARRAY_BYTES")
    if raw is None:
        return DEFAULT_MAX_ARRAY_BYTES
    try:
        value = int(raw)
    except ValueError:
        value = -1
    if value <= 0:
        raise DceeInputError("DCEE_MAX_ARRAY_BYTES", f"must be a whole number > 0, got {raw!r}")
    return value


def check_declared(field: str, where: str, shape: Any, itemsize: int = 8) -> None:
    """Refuse an array that ``where`` declares with ``shape`` (elements of ``itemsize`` bytes
    once read) when it is not a shape or exceeds :func:`max_array_bytes`."""
    try:
        dims = tuple(int(n) for n in shape)
    except (TypeError, ValueError):
        raise DceeInputError(field, f"{where}: declares an unreadable shape {shape!r}") from None
    if any(n < 0 for n in dims):
        raise DceeInputError(field, f"{where}: declares a negative dimension {dims}")
    nbytes = math.prod(dims) * int(itemsize)
    limit = max_array_bytes()
    if nbytes > limit:
        raise DceeInputError(
            field,
            f"{where}: declares an array of {dims} ({nbytes / 2**30:.3g} GiB as read), over "
            f"the {limit / 2**30:.3g} GiB limit (DCEE_MAX_ARRAY_BYTES)",
        )


def check_npy(path: Path, field: str) -> tuple[int, ...]:
    """The shape a ``.npy`` file declares; a file whose header is unreadable, declares Python
    objects, or declares more bytes than the file holds or :func:`max_array_bytes` allows is
    refused (its data unread)."""
    import numpy as np

    path = Path(path)
    with path.open("rb") as fh:
        try:
            version = np.lib.format.read_magic(fh)
            read_header = {
                (1, 0): np.lib.format.read_array_header_1_0,
                (2, 0): np.lib.format.read_array_header_2_0,
            }.get(version)
            if read_header is None:
                raise ValueError(f"npy version {version}")
            shape, _, dtype = read_header(fh)
        except Exception as exc:  # numpy parses the header text: any failure is a bad header
            raise DceeInputError(
                field, f"{path.name} is not a readable .npy file ({type(exc).__name__})"
            ) from None
        data_bytes = path.stat().st_size - fh.tell()
    if dtype.hasobject:
        raise DceeInputError(field, f"{path.name} holds Python objects (refused)")
    check_declared(field, path.name, shape, max(dtype.itemsize, 8))
    if math.prod(shape) * dtype.itemsize > data_bytes:
        raise DceeInputError(
            field, f"{path.name}: declares {shape} of {dtype} but holds {data_bytes:,} bytes"
        )
    return tuple(shape)


def read_text(path: Path, field: str, limit: int = MAX_TEXT_BYTES, encoding: str = "utf-8") -> str:
    """The text of ``path`` when it is at most ``limit`` bytes; FileNotFoundError and
    UnicodeDecodeError pass through for the caller's own message, a larger file is refused."""
    path = Path(path)
    size = path.stat().st_size
    if size > limit:
        raise DceeInputError(
            field, f"{path} is {size:,} bytes; a file read whole may hold {limit:,}"
        )
    return path.read_text(encoding=encoding)


class CappedStream(io.RawIOBase):
    """A binary stream that reads ``inner`` and refuses (DceeInputError) once more than
    ``limit`` bytes came out of it: a compressed file read through it cannot expand without
    bound."""

    def __init__(self, inner: IO[bytes], limit: int, field: str, where: str) -> None:
        self.inner, self.limit, self.field, self.where = inner, int(limit), field, where
        self.count = 0

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        data = self.inner.read(len(buffer))
        self.count += len(data)
        if self.count > self.limit:
            raise DceeInputError(
                self.field, f"{self.where}: expands to more than {self.limit:,} bytes (refused)"
            )
        buffer[: len(data)] = data
        return len(data)

    def close(self) -> None:
        self.inner.close()
        super().close()


__all__ = [
    "DEFAULT_MAX_ARRAY_BYTES",
    "MAX_IMAGE_PIXELS",
    "MAX_TEXT_BYTES",
    "CappedStream",
    "check_declared",
    "check_npy",
    "max_array_bytes",
    "read_text",
]
