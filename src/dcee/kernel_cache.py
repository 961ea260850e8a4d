"""Where numba keeps the compiled kernels: one folder per state of the package's source.

numba's on-disk cache checks only the file that defines a function. Kernels here inline helpers
from other modules (``dcee.numeric``'s vectorised ``exp`` and ``log``, the plume and sensor
terms), so after a change to a helper (a ``git pull`` that touches ``numeric.py`` only) the
cached machine code of every kernel that inlines it would be reused, stale and silently wrong.
Before numba is imported, :func:`key_numba_cache` points ``NUMBA_CACHE_DIR`` at
``$XDG_CACHE_HOME/dcee/numba/<key>`` (``~/.cache`` by default), the key a hash of the path and
contents of every module that uses numba: a change to any of them compiles every kernel anew
(about a minute, once), a change elsewhere (the command line, the docs) none, and the folders
of the last few states are kept so that switching back and forth does not recompile. Within
it each kernel is filed by its module's package-relative folder (:mod:`dcee.kernel_locator`),
so that a second checkout of the same source (a fresh clone, CI) reuses what the first
compiled. A ``NUMBA_CACHE_DIR`` set by the user wins (numba's own locator then); where the
cache root cannot be written numba's own default is left in place.

Standard library only: :mod:`dcee` imports this before anything else.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
KEEP = 4
"""Cache folders of this many source states are kept (the most recently used)."""

LOCATORS = (
    "dcee.kernel_locator.PackageRelativeLocator,UserProvidedCacheLocator,InTreeCacheLocator,"
    "UserWideCacheLocator,IPythonCacheLocator,ZipCacheLocator"
)
"""``NUMBA_CACHE_LOCATOR_CLASSES`` where dcee chose the cache folder (:mod:`dcee.kernel_locator`
is the first; the rest are numba's own, in numba's order)."""


def source_stamp(package_dir: Path = PACKAGE_DIR) -> str:
    """16 hex digits over the relative path and contents of every ``*.py`` file under
    ``package_dir`` that mentions numba or ``njit`` (the modules whose compiled code the cache
    holds, and the helpers inlined into it); a few milliseconds for the package."""
    h = hashlib.sha256()
    for path in sorted(package_dir.rglob("*.py")):
        text = path.read_bytes()
        if b"numba" in text or b"njit" in text:
            h.update(path.relative_to(package_dir).as_posix().encode() + b"\0")
            h.update(text + b"\0")
    return h.hexdigest()[:16]


def cache_root() -> Path:
    """``$XDG_CACHE_HOME/dcee/numba``, ``~/.cache/dcee/numba`` without it."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "dcee" / "numba"


def _writable(folder: Path) -> bool:
    """Whether ``folder`` can be created or written (tested on its nearest existing parent)."""
    probe = folder
    while not probe.exists():
        if probe.parent == probe:
            return False
        probe = probe.parent
    return os.access(probe, os.W_OK | os.X_OK)


def _prune(root: Path, keep: Path) -> None:
    """Remove all but the :data:`KEEP` most recently used source states' folders under root."""
    try:
        folders = sorted(
            (p for p in root.iterdir() if p.is_dir() and p != keep),
            key=lambda p: p.stat().st_mtime,
            reverse=True,
        )
    except OSError:
        return
    for old in folders[KEEP - 1 :]:
        shutil.rmtree(old, ignore_errors=True)


def key_numba_cache() -> Path | None:
    """Set ``NUMBA_CACHE_DIR`` to this source state's folder unless the user set it, numba is
    already imported (its configuration is read once) or the cache root is not writable;
    returns the folder in use, or None where numba's default applies."""
    if "NUMBA_CACHE_DIR" in os.environ:
        return Path(os.environ["NUMBA_CACHE_DIR"])
    if "numba" in sys.modules:
        return None
    root = cache_root()
    if not _writable(root):
        return None
    folder = root / source_stamp()
    try:
        fresh = not folder.exists()
        folder.mkdir(parents=True, exist_ok=True)
        os.utime(folder)  # most recently used
        if fresh:
            _prune(root, folder)
    except OSError:
        return None
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    # kernels filed by their package-relative folder, so that another checkout of the same
    # source reuses them (dcee.kernel_locator; the name is written out here: that module
    # imports numba, which must not be imported yet)
    os.environ.setdefault("NUMBA_CACHE_LOCATOR_CLASSES", LOCATORS)
    return folder


def compiled_before() -> bool:
    """Whether this source state's kernels are in the cache already (index files present)."""
    folder = os.environ.get("NUMBA_CACHE_DIR")
    if folder:
        return any(Path(folder).rglob("*.nbi"))
    return any((PACKAGE_DIR / "models" / "__pycache__").glob("*.nbi"))
