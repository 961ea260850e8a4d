"""Run a study from its recipe: ``python -m studies NAME`` (``bash studies/run.sh NAME`` calls
it). A recipe, ``studies/recipes/NAME.toml``, is data: a description and the study's steps in
order, each one command of

* ``dcee = "ARGS"``: the command line (a campaign ``bench``, a ``run``, a ``report``, ``perf``);
* ``python = "studies/SCRIPT.py ARGS"``: a table or figure step;
* ``shell = "rm|cp|mkdir ARGS"``: moving stored results (arguments with ``*`` are globbed);

ARGS split as a shell splits them, with these tokens:

* ``@PIN``: a historical pin of ``studies/pins.toml`` (the settings a stored study flew with,
  with the reason), written ``--set KEY=VALUE`` for dcee and ``--pin KEY=VALUE`` for a script;
* ``@workers:N``: the ``WORKERS`` environment variable, N where it is unset;
* ``@existing:PATH[=TAGS]``: the argument when PATH exists, else nothing; a glob, every match
  (with ``sort_existing = true`` the step's existing paths in sorted order, as ``ls -d`` lists
  them);
* ``@elapsed``: whole seconds since the step before this one started.

A step may carry ``unless_exists = "PATH"`` or ``only_if_exists = "PATH"``, read once when the
step is reached (a ``shell`` step may be a list of lines run under one condition). Campaigns resume
(``dcee bench`` skips finished searches); a ``dcee run`` step is skipped when its ``--json``
file or ``--out``'s ``summary.json`` exists (a search is deterministic). ``--dry-run`` prints
each command as a JSON list instead of running it.
"""

from __future__ import annotations

import glob
import json
import os
import shlex
import signal
import subprocess
import sys
import time
import tomllib
from collections.abc import Callable, Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RECIPES = ROOT / "studies" / "recipes"
PINS = ROOT / "studies" / "pins.toml"
KINDS = ("dcee", "python", "shell")
SHELL = ("rm", "cp", "mkdir")
CONDITIONS = ("unless_exists", "only_if_exists")


class RecipeError(ValueError):
    """A recipe or pin that cannot be run: the one-line message names the file and field."""


def _read_toml(path: Path) -> dict:
    """A TOML file's contents; a file that does not parse is a one-line RecipeError."""
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise RecipeError(f"{path.name}: {exc}") from None


def load_pins(path: Path = PINS) -> dict[str, dict]:
    """Every pin by name: ``reason`` (str) and ``settings`` (["KEY=VALUE", ...])."""
    pins = _read_toml(path)
    for name, pin in pins.items():
        if not (isinstance(pin.get("reason"), str) and pin["reason"].strip()):
            raise RecipeError(f"{path.name}: pin {name!r} needs a reason")
        settings = pin.get("settings")
        if not (isinstance(settings, list) and settings and all("=" in s for s in settings)):
            raise RecipeError(f"{path.name}: pin {name!r}: settings must be KEY=VALUE strings")
    return pins


def names() -> list[str]:
    return sorted(p.stem for p in RECIPES.glob("*.toml"))


def load_recipe(name: str) -> dict:
    """The recipe NAME, checked: a description and steps of known kinds and conditions."""
    path = RECIPES / f"{name}.toml"
    if not path.is_file():
        raise RecipeError(f"study: no recipe {name!r} (python -m studies --list)")
    recipe = _read_toml(path)
    if not isinstance(recipe.get("description"), str):
        raise RecipeError(f"{path.name}: description must be a string")
    steps = recipe.get("step", [])
    if not steps:
        raise RecipeError(f"{path.name}: no [[step]]")
    for i, step in enumerate(steps, start=1):
        kinds = [k for k in KINDS if k in step]
        extra = set(step) - set(KINDS) - set(CONDITIONS) - {"sort_existing"}
        if len(kinds) != 1 or extra:
            raise RecipeError(f"{path.name}: step {i} needs one of {KINDS}, got {sorted(step)}")
        if kinds[0] == "shell":
            lines = step["shell"] if isinstance(step["shell"], list) else [step["shell"]]
            if not all(shlex.split(line)[0] in SHELL for line in lines):
                raise RecipeError(f"{path.name}: step {i}: shell runs only {SHELL}")
    return recipe


def expand(step: dict, pins: dict[str, dict], previous_start: float) -> list[tuple[str, list[str]]]:
    """The (kind, argv) commands of one step with their tokens written out (a ``shell`` step
    may hold several lines), none when its condition says it does not run (read against the
    working directory when the step is reached)."""
    if "unless_exists" in step and Path(step["unless_exists"]).exists():
        return []
    if "only_if_exists" in step and not Path(step["only_if_exists"]).exists():
        return []
    kind = next(k for k in KINDS if k in step)
    lines = step[kind] if isinstance(step[kind], list) else [step[kind]]
    out = [
        _expand_line(kind, line, pins, previous_start, step.get("sort_existing", False))
        for line in lines
    ]
    return [command for command in out if command is not None]


def _expand_line(
    kind: str, line: str, pins: dict[str, dict], previous_start: float, sort_existing: bool
) -> tuple[str, list[str]] | None:
    argv: list[str] = []
    existing: list[str] = []
    slot: int | None = None
    for token in shlex.split(line):
        if token.startswith("@workers:"):
            argv.append(os.environ.get("WORKERS") or token.split(":", 1)[1])
        elif token.startswith("@existing:"):
            value = token.split(":", 1)[1]
            slot = len(argv) if slot is None else slot
            if "*" in value:
                existing += sorted(glob.glob(value))
            elif Path(value.split("=", 1)[0]).exists():
                existing.append(value)
        elif token == "@elapsed":
            argv.append(str(int(time.time() - previous_start)))
        elif token.startswith("@"):
            if token[1:] not in pins:
                raise RecipeError(f"unknown pin {token!r} (studies/pins.toml)")
            flag = "--set" if kind == "dcee" else "--pin"
            argv += [part for kv in pins[token[1:]]["settings"] for part in (flag, kv)]
        elif kind == "shell" and "*" in token:
            argv += sorted(glob.glob(token)) or [token]
        else:
            argv.append(token)
    if slot is not None:
        argv[slot:slot] = sorted(set(existing)) if sort_existing else existing
    if kind == "dcee" and argv[:1] == ["run"] and _search_done(argv):
        return None
    return kind, argv


def _search_done(argv: list[str]) -> bool:
    """Whether a ``dcee run`` step's result is there already (its --json, or --out's summary)."""

    def value(flag: str) -> str | None:
        return argv[argv.index(flag) + 1] if flag in argv[:-1] else None

    json_file, out = value("--json"), value("--out")
    if json_file is not None:
        return Path(json_file).exists()
    return out is not None and (Path(out) / "summary.json").exists()


def commands(name: str, pins: dict[str, dict] | None = None) -> Iterator[tuple[str, list[str]]]:
    """The study's commands in order, each expanded just before it is yielded (so that a
    condition sees what the steps before it wrote)."""
    pins = load_pins() if pins is None else pins
    previous_start = time.time()
    for step in load_recipe(name)["step"]:
        now = time.time()
        yield from expand(step, pins, previous_start)
        previous_start = now


def execute(kind: str, argv: list[str]) -> None:
    if kind == "dcee":
        subprocess.run([str(ROOT / ".venv" / "bin" / "dcee"), *argv], check=True)
        if argv[0] == "report" and len(argv) > 1:
            metrics = Path(argv[1]) / "report" / "metrics.md"
            if metrics.is_file():
                print(metrics.read_text(encoding="utf-8"))
    elif kind == "python":
        subprocess.run([str(ROOT / ".venv" / "bin" / "python"), *argv], check=True)
    else:
        subprocess.run(argv, check=True)


def run(name: str, dry_run: bool = False, say: Callable[[str], None] = print) -> int:
    """Run (or with ``dry_run`` print) study NAME; returns the exit code."""
    load_recipe(name)  # a bad recipe fails before anything runs
    pins = load_pins()
    if not dry_run and not (ROOT / ".venv" / "bin" / "dcee").exists():
        subprocess.run(["bash", str(ROOT / "scripts" / "setup.sh")], check=True)
    for kind, argv in commands(name, pins):
        if dry_run:
            say(json.dumps([kind, *argv]) if kind != "shell" else json.dumps(argv))
        else:
            execute(kind, argv)
    return 0


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if argv is None and hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `--list | head` ends quietly
    os.chdir(ROOT)
    try:
        if not args or args[0] in ("--list", "-l"):
            for name in names():
                print(f"{name:34} {load_recipe(name)['description']}")
            return 0
        if args[0] == "--pins":
            for name, pin in load_pins().items():
                print(f"@{name}: {' '.join(pin['settings'])}")
                print(f"    {' '.join(pin['reason'].split())}")
            return 0
        dry = "--dry-run" in args
        rest = [a for a in args if a != "--dry-run"]
        if len(rest) != 1 or rest[0].startswith("-"):
            raise RecipeError("usage: python -m studies NAME [--dry-run] | --list | --pins")
        return run(rest[0], dry_run=dry)
    except RecipeError as exc:
        print(f"study: {exc}" if not str(exc).startswith("study:") else exc, file=sys.stderr)
        return 2
    except subprocess.CalledProcessError as exc:
        print(f"study: {shlex.join(map(str, exc.cmd))} exited {exc.returncode}", file=sys.stderr)
        return exc.returncode or 1
