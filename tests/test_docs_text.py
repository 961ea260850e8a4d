"""No control character in anything that becomes a documentation page: a ``\\bar`` typed into
a Python string as ``"\\bar"`` is a backspace and ``ar``, which breaks the equation around it
and which only a browser shows. The docs build refuses such a page too (scripts/docs_hooks.py);
this finds it without building the site."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "scripts/docs_hooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_planted_backspace_is_found_with_its_line(hooks):
    page = "# Title\n\nThe mean \\(\\bar s\\) and\n" + "a \\(\x08ar s\\) broken\n"
    assert hooks.control_characters(page) == ["line 4: U+0008"]
    assert hooks.control_characters("tab\tand\r\nnewline\n") == []
    with pytest.raises(Exception, match="control character at line 4: U\\+0008"):
        hooks._refuse_control_characters(page, "planted.md")


def test_no_page_source_holds_a_control_character(hooks):
    sources = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    # the API reference is rendered from the docstrings
    sources += sorted((ROOT / "src/dcee").rglob("*.py"))
    found = {
        str(p.relative_to(ROOT)): hit
        for p in sources
        if (hit := hooks.control_characters(p.read_text(encoding="utf-8")))
    }
    assert not found


def test_generated_reference_pages_hold_no_control_character(hooks):
    assert hooks.control_characters(hooks.cli_reference()) == []
    assert hooks.control_characters(hooks.scenario_reference()) == []
