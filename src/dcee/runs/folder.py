"""The folder of a single run (``dcee run``): its default name, which says what differs from the
built-in scenario, and the refusal to write into a folder that holds a different search."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from dcee.errors import DceeInputError
from dcee.runs.identity import scenario_identity
from dcee.scenarios import Scenario

NAMED_CHANGES = (
    "search.particles",
    "search.hypotheses",
    "search.budget",
    "unknown",
    "truth.model",
    "agent.count",
)
"""Overrides that the default run folder names in words; any other change adds a hash."""


def edits(changes: dict[str, Any]) -> dict[str, Any]:
    """The changes a run's folder name cannot say in words (``--set``, ``--likelihood``), as
    dotted settings: recorded with its results."""
    return {k: v for k, v in changes.items() if k not in NAMED_CHANGES and v is not None}


def edited_name(scenario: Scenario, base: Scenario, changes: dict[str, Any]) -> str:
    """The name a run's results carry: the built-in's (``paper:1``) when only settings the
    folder names in words changed, else the built-in's with a short hash of the resolved
    scenario (``paper:1+3fa2c1d0``), so an edited scenario never passes for the built-in."""
    try:
        named_only = base.with_overrides(**{k: v for k, v in changes.items() if k in NAMED_CHANGES})
    except DceeInputError:
        # the named changes hold only with the others (``--truth lbm`` needs ``--set
        # truth.z`` in the flight plane): the scenario is edited beyond what words say
        named_only = None
    if scenario.model_copy(update={"name": base.name}) == named_only:
        return base.name
    resolved = scenario.model_copy(update={"name": base.name}).model_dump(mode="json")
    digest = hashlib.sha256(json.dumps(resolved, sort_keys=True).encode()).hexdigest()[:8]
    return f"{base.name}+{digest}"


def default_run_folder(
    scenario: Scenario, base: Scenario, changes: dict[str, Any], strategy: str, seed: int
) -> str:
    """``paper-1_dcee_seed0``, plus what differs from the built-in: ``_n10000`` particles,
    ``_j20`` hypotheses, ``_b300`` budget, ``_full`` unknowns, ``_filament`` truth, ``_a3``
    robots, and a short
    hash of the resolved scenario when anything else changed (``--likelihood``, ``--set``), so
    two different runs never share a default folder."""
    parts = [base.name.replace(":", "-"), strategy.replace(":", "+"), f"seed{seed}"]
    s, b = scenario.search, base.search
    if s.particles != b.particles:
        parts.append(f"n{s.particles}")
    if s.hypotheses != b.hypotheses:
        parts.append(f"j{s.hypotheses}")
    if s.budget != b.budget:
        parts.append(f"b{s.budget:g}")
    if scenario.unknown != base.unknown:
        parts.append(scenario.unknown)
    if scenario.truth.model != base.truth.model:
        parts.append(scenario.truth.model_name)
    if scenario.agent.count != base.agent.count:
        parts.append(f"a{scenario.agent.count}")
    _, edited, digest = edited_name(scenario, base, changes).partition("+")
    if edited:  # the same hash the results' scenario name carries
        parts.append(digest)
    return "_".join(parts)


def check_same_run(out_dir: Path, scenario: Scenario, strategy: str, seed: int) -> None:
    """Refuse an output folder that holds anything but an earlier run of this very search (same
    resolved scenario, strategy and seed), so results never mix."""
    entries = [p for p in out_dir.iterdir() if not p.name.startswith(".")]
    if not entries:
        return
    try:
        config = json.loads((out_dir / "config.json").read_text())
        same = (
            isinstance(config.get("scenario"), dict)
            and scenario_identity(config["scenario"])
            == scenario_identity(scenario.model_dump(mode="json"))
            and config.get("strategy") == strategy
            and config.get("seed") == seed
        )
    except (OSError, ValueError):
        same = False
    if not same:
        raise DceeInputError(
            "out",
            f"{str(out_dir)!r} holds other files or a different search; choose another --out "
            "(or remove it)",
        )
