"""Every fenced Python block in the documentation runs: the blocks of one page run in order in
one fresh interpreter (a later block may use what an earlier one defined), in a temporary folder
that holds a small study under ``results/study`` for the pages that load one. A page whose
snippet fails fails the suite."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parent.parent / "docs"
FENCE = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def python_blocks(page: Path) -> list[str]:
    return FENCE.findall(page.read_text(encoding="utf-8"))


PAGES = sorted(p for p in DOCS.rglob("*.md") if "generated" not in p.parts and python_blocks(p))


def test_the_pages_with_python_are_found():
    names = {p.name for p in PAGES}
    assert {"python-api.md", "learning.md", "robot.md"} <= names


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder with a small finished study in results/study (2 searches at toy scale)."""
    root = tmp_path_factory.mktemp("docs")
    subprocess.run(
        [sys.executable, "-m", "dcee.cli", "bench", "--suite", "smoke", "--strategies", "mpc",
         "--repeats", "1", "--workers", "1", "--out", "results/study"],
        cwd=root, check=True, capture_output=True, timeout=300,
    )  # fmt: skip
    return root


def _snippet_env(workdir: Path) -> dict[str, str]:
    """A bare environment (no user settings leak into the pages' code) that shares this
    process's compiled-kernel cache: importing dcee keyed ``NUMBA_CACHE_DIR`` to the source state,
    and a page's interpreter under its own ``HOME`` would otherwise compile every kernel again
    (about 20 s a page)."""
    env = {"MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin", "HOME": str(workdir)}
    names = ("NUMBA_CACHE_DIR", "NUMBA_CACHE_LOCATOR_CLASSES")
    # and the thread counts the suite's processes run with (tests/conftest.py)
    names += ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
    for name in names:
        if name in os.environ:
            env[name] = os.environ[name]

    return env


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(DOCS)) for p in PAGES])
def test_every_python_block_of_a_page_runs(page: Path, workdir: Path):
    code = "\n\n".join(python_blocks(page))
    proc = subprocess.run(
        [sys.executable, "-c", code],
        cwd=workdir,
        capture_output=True,
        text=True,
        timeout=600,
        env=_snippet_env(workdir),
    )
    assert proc.returncode == 0, f"{page.name}:\n{proc.stderr[-3000:]}"


def test_the_api_reference_rewrites_sphinx_markup_to_markdown():
    """The Griffe extension of the API reference (scripts/griffe_docstrings.py)."""
    sys.path.insert(0, str(DOCS.parent / "scripts"))
    try:
        from griffe_docstrings import markdown
    finally:
        sys.path.pop(0)
    doc = (
        "See :meth:`~dcee.searcher.Searcher.ask` and :class:`dcee.runs.EpisodeResult`, ``x``::\n"
        "\n    a = 1\n    b = 2\n\nThen\n\n>>> run()\n>>> stop()\n\nEnd."
    )
    assert markdown(doc) == (
        "See `ask` and `dcee.runs.EpisodeResult`, `x`:\n\n```python\na = 1\nb = 2\n```\n\n"
        "Then\n\n```pycon\n>>> run()\n>>> stop()\n```\n\nEnd."
    )


def test_the_api_reference_links_roles_to_documented_objects(monkeypatch):
    """A role whose target the API pages render becomes an autorefs link, resolved as Python
    would from where it is written; one whose target is not rendered stays inline code."""
    import griffe

    sys.path.insert(0, str(DOCS.parent / "scripts"))
    try:
        from griffe_docstrings import documented_paths, markdown
    finally:
        sys.path.pop(0)
    monkeypatch.chdir(DOCS.parent)  # the API pages are read from docs/reference/api
    pkg = griffe.load("dcee", search_paths=[str(DOCS.parent / "src")], resolve_aliases=False)
    documented = documented_paths(pkg)
    assert "dcee.searcher.Searcher.ask" in documented
    assert "dcee.numeric.exp_scalar" not in documented  # not on an API page
    searcher = pkg.modules_collection["dcee.searcher.Searcher"]
    doc = ":meth:`ask`, :class:`~dcee.stopping.StopRule`, :func:`dcee.numeric.exp_scalar`"
    assert markdown(doc, searcher, documented) == (
        "[`ask`][dcee.searcher.Searcher.ask], [`StopRule`][dcee.stopping.StopRule], "
        "`dcee.numeric.exp_scalar`"
    )
