"""numba's cache locator for dcee's kernels: the cache subfolder of a kernel is its module's
folder relative to the package (``dcee/estimation``), not a hash of the checkout's absolute
folder as numba's own ``NUMBA_CACHE_DIR`` locator makes it.

Why: every fresh clone (a new folder: CI, a second worktree, a user's second checkout)
compiled every kernel again, about 85 s of one core, although the machine had compiled the
same source before. Sharing is safe because :func:`dcee.kernel_cache.key_numba_cache` keys the
cache root by the contents of every module that uses numba, and numba stamps each cache index
with its source file's content hash. Chosen through ``NUMBA_CACHE_LOCATOR_CLASSES`` (numba 0.68
reads it; a numba that does not know the variable keeps its own locator), and only where dcee
chose the cache folder; a file outside the package falls through to numba's locators.
"""

from __future__ import annotations

import os
from pathlib import Path

from numba.core import config
from numba.core.caching import UserProvidedCacheLocator

PACKAGE_DIR = Path(__file__).resolve().parent


class PackageRelativeLocator(UserProvidedCacheLocator):
    """``NUMBA_CACHE_DIR/<module folder relative to the package's parent>``."""

    def __init__(self, py_func, py_file) -> None:
        super().__init__(py_func, py_file)
        relative = Path(py_file).resolve().parent.relative_to(PACKAGE_DIR.parent)
        self._cache_path = os.path.join(config.CACHE_DIR, *relative.parts)

    @classmethod
    def from_function(cls, py_func, py_file):
        try:
            Path(py_file).resolve().relative_to(PACKAGE_DIR)
        except ValueError:
            return None  # not a dcee module: numba's own locators
        return super().from_function(py_func, py_file)
