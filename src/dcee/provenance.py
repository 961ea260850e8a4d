"""Which code made a result: the package version, the git commit, a dirty flag and a hash of the
source files, recorded in every summary and campaign; and the platform it ran on (the CPU the
kernels were compiled for, numpy's and numba's versions), recorded in every summary.

The installed version alone is not enough: an editable install freezes it at install time, so
every result would claim the same version whatever the code. In a git work tree the version is
therefore recomputed from ``git describe`` with setuptools-scm's default scheme (read once per
process), and the commit and dirty flag come from git too; the source hash (SHA-256 of the
package's ``.py`` files, paths and contents) identifies the code even without git or with
uncommitted edits, and is what a resumed campaign compares.
"""

from __future__ import annotations

import functools
import hashlib
import os
import platform
import re
import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

PACKAGE_DIR = Path(__file__).resolve().parent


def package_version() -> str:
    """The installed distribution's version (from git tags via setuptools-scm at install time),
    or ``0+unknown`` when running from a source tree that was never installed."""
    try:
        return version("dcee")
    except PackageNotFoundError:
        return "0+unknown"


@functools.cache
def code_version() -> dict[str, Any]:
    """``{"version", "commit", "dirty", "source_hash"}`` of the running code. ``commit`` and
    ``dirty`` are None outside a git work tree (an installed wheel). ``dirty`` is True when the
    package's own files differ from the commit (edits elsewhere in the repository do not count)."""
    dirty = _dirty()
    described = (
        _git("describe", "--tags", "--long", "--match", "v[0-9]*") if dirty is not None else None
    )
    version = version_from_describe(described, bool(dirty))
    if version is None and dirty is not None:
        # no version tag in the history: setuptools-scm counts commits from its fallback
        count, sha = _git("rev-list", "--count", "HEAD"), _git("rev-parse", "--short=9", "HEAD")
        if count and count.isdigit() and sha:
            version = version_without_tag(int(count), sha, bool(dirty))
    return {
        "version": version or package_version(),
        "commit": _git("rev-parse", "HEAD"),
        "dirty": dirty,
        "source_hash": source_hash(),
    }


@functools.cache
def platform_record() -> dict[str, Any]:
    """``{"cpu", "machine", "numpy", "numba"}``: the CPU numba compiles the kernels for (the
    host's, or ``NUMBA_CPU_NAME`` where set), the architecture and the two libraries whose
    arithmetic a search runs on. Two machines with the same code can round the compiled sums
    differently in the last bit, and a search that meets nearly tied decisions (the lbm plume)
    then parts from its twin (docs/design.md, "Reproducibility"): a comparison search for search
    is one made on one platform."""
    import llvmlite.binding as llvm
    import numba
    import numpy

    return {
        "cpu": os.environ.get("NUMBA_CPU_NAME") or llvm.get_host_cpu_name(),
        "machine": platform.machine(),
        "numpy": numpy.__version__,
        "numba": numba.__version__,
    }


_DESCRIBE = re.compile(r"^v(?P<tag>\d+(?:\.\d+)*)-(?P<distance>\d+)-g(?P<sha>[0-9a-f]+)$")


def version_from_describe(described: str | None, dirty: bool) -> str | None:
    """The version setuptools-scm would give a work tree, from ``git describe --tags --long``
    output such as ``v0.1.0-26-g80ab722``: the tag itself on a clean tagged commit, else the
    next patch version with ``.dev<distance>+g<sha>`` (``.dirty`` appended for uncommitted
    edits). None when the output is not of that form (no tag: the installed version is used)."""
    m = _DESCRIBE.match(described or "")
    if m is None:
        return None
    tag, distance, sha = m["tag"], int(m["distance"]), m["sha"]
    if distance == 0 and not dirty:
        return tag
    parts = tag.split(".")
    parts[-1] = str(int(parts[-1]) + 1)
    local = f"g{sha}" + (".dirty" if dirty else "")
    return f"{'.'.join(parts)}.dev{distance}+{local}"


FALLBACK_VERSION = "0.1.0"
"""pyproject.toml's ``[tool.setuptools_scm] fallback_version``: the base of a history without a
version tag."""


def version_without_tag(count: int, sha: str, dirty: bool) -> str:
    """The version setuptools-scm gives a work tree whose history has no version tag: the
    fallback's next patch version with ``.dev<commits>+g<sha>`` (``.dirty`` for uncommitted
    edits), e.g. ``0.1.1.dev606+g7e23c7d1e``."""
    parts = FALLBACK_VERSION.split(".")
    parts[-1] = str(int(parts[-1]) + 1)
    return f"{'.'.join(parts)}.dev{count}+g{sha}" + (".dirty" if dirty else "")


def source_hash() -> str:
    """SHA-256 (first 16 hex digits) over the package's Python files, paths and contents."""
    h = hashlib.sha256()
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        h.update(path.relative_to(PACKAGE_DIR).as_posix().encode())
        h.update(b"\0")
        h.update(path.read_bytes())
        h.update(b"\0")
    return h.hexdigest()[:16]


def same_code(a: dict[str, Any] | None, b: dict[str, Any] | None) -> bool:
    """True when two recorded code versions ran the same source (same source hash)."""
    return bool(a and b and a.get("source_hash") and a.get("source_hash") == b.get("source_hash"))


def describe(code: dict[str, Any] | None) -> str:
    """One short line: ``0.2.0 (commit 53da257, dirty)``; ``unknown`` for results from before
    code versions were recorded."""
    if not code:
        return "unknown"
    commit = code.get("commit")
    extra = [f"commit {commit[:7]}" if commit else "no git", f"source {code.get('source_hash')}"]
    if code.get("dirty"):
        extra.append("dirty")
    return f"{code.get('version')} ({', '.join(extra)})"


def _git(*args: str) -> str | None:
    try:
        out = subprocess.run(
            ["git", *args],
            cwd=PACKAGE_DIR,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None


def _dirty() -> bool | None:
    if _git("rev-parse", "--is-inside-work-tree") != "true":
        return None
    status = _git("status", "--porcelain", "--untracked-files=normal", "--", ".")
    return bool(status)
