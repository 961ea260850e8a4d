"""Atomic result files: a reader never sees a half-written file, whatever interrupts the writer."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any


def check_writable_dir(path: Path, field: str, create: bool = True) -> None:
    """Create ``path`` (a folder) if needed and check that a file can be written in it, so a
    command fails at once with one line instead of after its work. ``create=False`` (a dry
    run): leave the file system as it was, checking that the nearest existing folder on the
    way takes a new folder (one made there and removed at once)."""
    path = Path(path)
    try:
        if path.exists() and not path.is_dir():
            raise NotADirectoryError(f"{path} is a file")
        if not create and not path.exists():
            parent = path.absolute().parent
            while not parent.exists():
                parent = parent.parent
            if not parent.is_dir():
                raise NotADirectoryError(f"{parent} is a file")
            os.rmdir(tempfile.mkdtemp(prefix=".dcee-write-check.", dir=parent))
            return
        path.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".dcee-write-check.", dir=path)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        from dcee.errors import DceeInputError

        raise DceeInputError(
            field, f"cannot write to {str(path)!r} ({exc.strerror or exc})"
        ) from None


def check_writable_file(path: Path, field: str) -> None:
    """Check that ``path`` (a file) can be written: its folder is writable and it is not a
    folder itself."""
    path = Path(path)
    if path.is_dir():
        from dcee.errors import DceeInputError

        raise DceeInputError(field, f"{str(path)!r} is a folder; give a file name")
    check_writable_dir(path.parent, field)


def write_atomic(path: Path, writer: Callable[[Path], None]) -> None:
    """Write via ``writer(tmp)`` to a temporary file beside ``path``, then rename over it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        writer(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the usual permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_json(path: Path, data: Any) -> None:
    """Write ``data`` as indented JSON, atomically."""
    write_atomic(path, lambda p: p.write_text(json.dumps(data, indent=2, default=jsonable)))


def jsonable(obj: Any) -> Any:
    """JSON fallback for NumPy scalars and arrays."""
    import numpy as np  # here, not at the top: the command line's start-up stays light

    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj)}")


@contextlib.contextmanager
def folder_kept_only_on_success(path: Path) -> Iterator[None]:
    """A folder this block creates is removed again when the block fails (a user mistake
    found late, an interruption), so a failed command leaves no empty or half-filled folder
    behind; a folder that existed before is left as it was."""
    path = Path(path)
    existed = path.exists()
    try:
        yield
    except BaseException:
        if not existed:
            shutil.rmtree(path, ignore_errors=True)
        raise
