"""Every ``dcee run`` and ``dcee bench`` command the documentation shows is still accepted as
written (checked with ``--dry-run``: the scenarios, the settings, the strategies and the memory,
no search); every refusal it shows (a ``$ dcee run …`` line followed by ``dcee: error: …``) is
still refused with that line, and a dry run it shows (followed by ``would run …``) still prints
that line. A command that names a file of the reader's own (``my-site.geojson``,
``tunnel.nc``) is left out; a usage synopsis (``[--particles N]``) too."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from tests.helpers import run_cli

ROOT = Path(__file__).resolve().parent.parent
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)
FILE = re.compile(r"[\w./-]+\.(?:npy|nc|geojson|toml|bag|json)\b")


def documented_commands() -> list[tuple[str, str, str | None]]:
    """(page, command, the output line shown after it or None) of every ``dcee run`` and
    ``dcee bench`` line in a fenced block of the README and the docs (backslash continuations
    joined)."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    found = []
    for page in pages:
        if "generated" in page.parts:
            continue
        for _, body in FENCE.findall(page.read_text(encoding="utf-8")):
            lines = body.replace("\\\n", " ").splitlines()
            for i, line in enumerate(lines):
                text = line.strip()
                prompt = text.startswith("$ ")
                text = text.removeprefix("$ ").replace(".venv/bin/dcee", "dcee")
                if not text.startswith(("dcee run ", "dcee bench ")):
                    continue
                after = lines[i + 1].strip() if i + 1 < len(lines) else ""
                shown = prompt and after.startswith(("dcee: error:", "would run "))
                found.append((str(page.relative_to(ROOT)), text, after if shown else None))
    return found


RUNS = documented_commands()


def _checkable(command: str) -> bool:
    """Not a synopsis, and every file it names is in the repository."""
    args = shlex.split(command, comments=True)
    if any(a.startswith("[") for a in args):
        return False
    return all((ROOT / f).exists() for f in FILE.findall(command))


CHECKED = [r for r in RUNS if _checkable(r[1])]


def test_the_documented_commands_are_found():
    assert len(RUNS) >= 20 and len(CHECKED) >= 14
    shown = [line for _, _, line in CHECKED if line]
    assert any(line.startswith("dcee: error:") for line in shown)  # a documented refusal
    assert any(line.startswith("would run ") for line in shown)  # a documented dry run


@pytest.mark.parametrize(
    "page, command, shown", CHECKED, ids=[f"{p}:{c[5:60]}" for p, c, _ in CHECKED]
)
def test_a_documented_command_does_what_the_page_says(
    page, command, shown, capsys, monkeypatch, tmp_path
):
    # the repository's files (tests/data/...) where the pages name them, and no results of
    # this checkout's own (a campaign folder there would be checked as a resume)
    for top in ("tests", "docs", "studies", "src"):
        (tmp_path / top).symlink_to(ROOT / top)
    monkeypatch.chdir(tmp_path)
    args = shlex.split(command, comments=True)[1:]
    code, out, err = run_cli([*args, "--dry-run"], capsys)
    if shown is None or shown.startswith("would run "):
        assert code == 0, f"{page}: {command}\n{err}"
        assert out.startswith("would run ") and out.strip() == (shown or out.strip())
    else:
        assert code == 2 and err.strip() == shown, f"{page}: {command}\n{err}"
