"""A campaign's searches and its folder: which (configuration, repeat, strategy) searches it
holds, where each one's results go, whether one is done, and the checks and record of
``campaign.json`` (the settings that identify the results and every code version that ran
searches in it). :mod:`dcee.campaign.runner` runs them."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import quote

from dcee.errors import DceeInputError
from dcee.io import write_json
from dcee.provenance import code_version, describe, same_code
from dcee.runs.identity import first_difference, settings_identity


def partition(key: str, value: object) -> str:
    """A hive partition folder name, ``key=value`` with the value URI-encoded (pyarrow's
    default ``segment_encoding="uri"`` decodes it)."""
    return f"{key}={quote(str(value), safe='')}"


@dataclass(frozen=True)
class SearchTask:
    """One search: everything a worker needs, as plain data (picklable)."""

    out_dir: str
    config: str
    strategy: str
    seed: int
    scenario: dict[str, Any]

    @property
    def folder(self) -> Path:
        return (
            Path(self.out_dir)
            / "runs"
            / partition("config", self.config)
            / partition("strategy", self.strategy)
            / partition("seed", self.seed)
        )


def is_done(task: SearchTask) -> bool:
    """True when the search's summary, record and posterior sample are complete and consistent."""
    from dcee.runs import EpisodeResult

    return EpisodeResult.is_complete(task.folder)


@dataclass
class Campaign:
    """The searches of one campaign folder and its stored settings."""

    out_dir: Path
    suite: str
    strategies: tuple[str, ...]
    repeats: int
    unknown: str | None = None
    particles: int | None = None
    truth: str | dict[str, str] | None = None
    overrides: dict[str, Any] = field(default_factory=dict)
    """dotted scenario settings applied to every scenario (``--likelihood``, ``--set``)"""
    allow_code_change: bool = False
    """resume a campaign that earlier code started (the versions used are all recorded)"""
    open_truths: bool = True
    """build each scenario's truth once to check it (a recording read, a solver's plume
    computed if not cached); ``dcee bench --dry-run`` leaves it to the searches"""

    def __post_init__(self) -> None:
        from dcee.campaign.suites import suite_scenarios
        from dcee.planning import get as get_planner

        if self.repeats < 1:
            raise DceeInputError("repeats", f"must be >= 1, got {self.repeats}")
        if not self.strategies:
            raise DceeInputError("strategies", "give at least one strategy")
        twice = sorted({s for s in self.strategies if self.strategies.count(s) > 1})
        if twice:  # their searches would share one folder, written by two workers at once
            raise DceeInputError("strategies", f"{', '.join(twice)} given more than once")
        for s in self.strategies:
            get_planner(s)  # unknown names and bad options fail before anything runs
        self.scenarios = {
            s.name: s
            for s in suite_scenarios(
                self.suite, self.unknown, self.particles, self.truth, self.overrides
            )
        }
        if any(sc.agent.count > 1 for sc in self.scenarios.values()):
            from dcee.planning import check_team_planner

            for s in self.strategies:
                check_team_planner(get_planner(s))  # e.g. dcee-ms plans for one robot only
        if self.truth is not None and self.open_truths:
            from dcee.simulation import make_truth

            for scenario in self.scenarios.values():
                make_truth(scenario, 0)  # a bad recording fails here, not in every search

    def settings(self) -> dict[str, Any]:
        """What identifies the results: strategies and repeats may grow, these may not change."""
        settings = {
            "suite": self.suite,
            "unknown": self.unknown,
            "particles": self.particles,
            "scenarios": {k: v.model_dump(mode="json") for k, v in self.scenarios.items()},
            # what each unset default resolved to: a later change of one is refused on resume
            "resolved": {k: v.resolved_unset() for k, v in self.scenarios.items()},
        }
        if self.truth is not None:  # absent, not null, so that older campaign folders resume
            settings["truth"] = self.truth
        if self.overrides:
            settings["overrides"] = dict(sorted(self.overrides.items()))
        return settings

    def prepare(self, write: bool = True) -> None:
        """Create the folder or check that it holds this campaign's results, made by this code
        (else refuse), and record the code that runs now. A folder whose every search of this
        call is done is left as it is, whatever code made it: resuming it runs nothing.
        ``write=False``: the checks alone (``dcee bench --dry-run``)."""
        path = self.out_dir / "campaign.json"
        settings = self.settings()
        code = code_version()
        codes: list[dict[str, Any]] = []
        if path.exists():
            try:
                stored = json.loads(path.read_text())
                if not isinstance(stored, dict):
                    raise ValueError("not a JSON object")
            except (OSError, ValueError):
                raise DceeInputError(
                    "out", f"{path} is unreadable; move the folder aside or choose another --out"
                ) from None
            kept = stored.get("settings", {})
            if "resolved" not in kept:  # stored before campaigns recorded it (2026-12-02)
                settings = {k: v for k, v in settings.items() if k != "resolved"}
            before, now = settings_identity(kept), settings_identity(settings)
            if before != now:
                changed = first_difference(before, now)
                raise DceeInputError(
                    "out",
                    f"{self.out_dir} holds results of a different configuration ({changed}); "
                    "use a new --out folder instead of mixing results",
                )
            codes = list(stored.get("code_versions", []))
            if all(is_done(t) for t in self.tasks()):
                return  # nothing will run: no code to refuse and none to record
            if not any(same_code(c, code) for c in codes) and not self.allow_code_change:
                earlier = describe(codes[-1]) if codes else "unknown (older dcee)"
                raise DceeInputError(
                    "out",
                    f"{self.out_dir} was started by other code ({earlier}; now "
                    f"{describe(code)}); use a new --out folder, or --allow-code-change "
                    "to resume anyway (every version used is recorded)",
                )
            strategies = sorted(set(stored.get("strategies", [])) | set(self.strategies))
            repeats = max(int(stored.get("repeats", 0)), self.repeats)
        else:
            strategies, repeats = sorted(self.strategies), self.repeats
        if not any(same_code(c, code) for c in codes):
            codes.append(code)
        if not write:
            return
        write_json(
            path,
            {
                "settings": settings,
                "strategies": strategies,
                "repeats": repeats,
                "version": codes[0].get("version"),
                "code_versions": codes,
            },
        )

    def tasks(self) -> list[SearchTask]:
        out = []
        for name, scenario in self.scenarios.items():
            dump = scenario.model_dump(mode="json")
            for seed in range(self.repeats):
                for strategy in self.strategies:
                    out.append(SearchTask(str(self.out_dir), name, strategy, seed, dump))
        return out
