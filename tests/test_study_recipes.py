"""The studies as data (issue 79): every recipe of studies/recipes/ is runnable as written (its
pins known, its scripts present, its dcee commands real subcommands), every historical pin says
why, and the runner expands a step's tokens as its documentation says. Equivalence with the
bash script the recipes replaced was checked once, command for command, when they were
written (docs/release-notes.md)."""

from __future__ import annotations

import json
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from studies import runner  # noqa: E402

from dcee.cli import cli  # noqa: E402

sys.path.pop(0)

NAMES = runner.names()


def test_there_is_a_recipe_for_every_study_the_readme_lists():
    import re

    readme = (ROOT / "studies" / "README.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"^\| `([a-z0-9-]+)`", readme, re.M))
    listed |= {
        n
        for row in re.findall(r"^\| (`[a-z0-9-]+`(?:, `[a-z0-9-]+`)+) \|", readme, re.M)
        for n in re.findall(r"`([a-z0-9-]+)`", row)
    }
    assert listed and listed <= set(NAMES), sorted(listed - set(NAMES))


def test_every_pin_has_a_reason_and_settings():
    pins = runner.load_pins()
    assert {"lookahead-1", "region-floor-0", "climb-0"} <= set(pins)
    for pin in pins.values():
        assert len(pin["reason"].split()) >= 8 and all("=" in kv for kv in pin["settings"])


@pytest.mark.parametrize("name", NAMES)
def test_every_recipe_is_runnable_as_written(name, tmp_path, monkeypatch):
    pins = runner.load_pins()
    recipe = runner.load_recipe(name)
    assert recipe["description"].strip()
    monkeypatch.chdir(tmp_path)  # no results here: every step expands, none is skipped
    commands = list(runner.commands(name, pins))
    assert commands
    for kind, argv in commands:
        assert not any(a.startswith("@") for a in argv), argv
        if kind == "dcee":
            assert argv[0] in cli.commands, argv  # a real dcee command
        elif kind == "python":
            assert (ROOT / argv[0]).is_file(), argv[0]


def test_tokens_expand_as_documented(tmp_path, monkeypatch):
    pins = {"p": {"reason": "why", "settings": ["a.b=1", "c.d=2"]}}
    monkeypatch.chdir(tmp_path)
    (tmp_path / "there").mkdir()
    step = {"dcee": "bench --workers @workers:2 @p --out x"}
    monkeypatch.delenv("WORKERS", raising=False)
    assert runner.expand(step, pins, 0.0) == [
        ("dcee", ["bench", "--workers", "2", "--set", "a.b=1", "--set", "c.d=2", "--out", "x"])
    ]
    monkeypatch.setenv("WORKERS", "5")
    assert runner.expand({"python": "s.py @p"}, pins, 0.0) == [
        ("python", ["s.py", "--pin", "a.b=1", "--pin", "c.d=2"])
    ]
    assert runner.expand({"dcee": "bench --workers @workers:1"}, pins, 0.0)[0][1][-1] == "5"
    step = {"python": "t.py @existing:there=tag:1 @existing:missing=tag:2 --csv o"}
    assert runner.expand(step, pins, 0.0) == [("python", ["t.py", "there=tag:1", "--csv", "o"])]
    assert runner.expand({"unless_exists": "there", "dcee": "report there"}, pins, 0.0) == []
    assert runner.expand({"only_if_exists": "missing", "dcee": "report x"}, pins, 0.0) == []
    # a dcee run whose summary is there is done (searches are deterministic)
    (tmp_path / "there" / "summary.json").write_text("{}")
    assert runner.expand({"dcee": "run --out there"}, pins, 0.0) == []
    assert runner.expand({"dcee": "run --out elsewhere"}, pins, 0.0)


def test_a_recipe_that_does_not_parse_is_a_one_line_error(tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "RECIPES", tmp_path)
    (tmp_path / "broken.toml").write_text('description = "x"\n[[step]\n')
    with pytest.raises(runner.RecipeError, match=r"^broken.toml: ") as exc:
        runner.load_recipe("broken")
    assert "\n" not in str(exc.value)


def test_a_bad_recipe_or_name_is_one_line_and_exit_2(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "studies", "no-such-study"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "no recipe" in proc.stderr
    dry = subprocess.run(
        [sys.executable, "-m", "studies", "paper-source", "--dry-run"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    first = json.loads(dry.stdout.splitlines()[0])
    assert first[:3] == ["dcee", "bench", "--suite"] and "results/paper-source" in first
    assert shlex.join(first)  # one command per line, as JSON


@pytest.mark.parametrize("name", NAMES)
def test_every_recipe_search_is_accepted_by_today_s_code(name, tmp_path, monkeypatch, capsys):
    """Each ``dcee run`` and ``dcee bench`` step of the recipe, checked with ``--dry-run`` (its
    scenario, settings, strategies and memory, no search): a published table stays
    reproducible only while today's code takes the commands that made it."""
    from tests.helpers import run_cli

    monkeypatch.chdir(tmp_path)
    for kind, argv in runner.commands(name, runner.load_pins()):
        if kind == "dcee" and argv[0] in ("run", "bench"):
            code, out, err = run_cli([*argv, "--dry-run"], capsys)
            assert code == 0 and out.startswith("would run "), f"{shlex.join(argv)}\n{err}"
