"""Which code made a result: the package version, the git commit, a dirty flag and a hash of the
source files, recorded in every summary and campaign.

``__version__`` alone is not enough: an editable install freezes the version at install time, so
every result would claim the same version whatever the code. The commit and dirty flag come from
git when the package runs from a work tree (read once per process); the source hash (SHA-256 of
the package's ``.py`` files, paths and contents) identifies the code even without git or with
uncommitted edits, and is what a resumed campaign compares.
"""

from __future__ import annotations

import functools
import hashlib
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
    return {
        "version": package_version(),
        "commit": _git("rev-parse", "HEAD"),
        "dirty": _dirty(),
        "source_hash": source_hash(),
    }


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
