"""Options shared by the ``dcee`` commands: registry-backed choices read when needed (``dcee
--help`` imports no heavy module), what the sensor sees, the reading model and ``--set``."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import click


class RegistryChoice(click.ParamType):
    """A choice among the names a registry holds, read when needed (not at import, so that
    ``dcee --help`` does not import the registries' heavy modules)."""

    name = "choice"

    def __init__(self, names: Callable[[], list[str]]) -> None:
        self.names = names

    def get_metavar(self, param: click.Parameter, ctx: click.Context | None = None) -> str:
        return "[" + "|".join(self.names()) + "]"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        allowed = self.names()
        if value not in allowed:
            self.fail(f"{value!r} is not one of {', '.join(allowed)}", param, ctx)
        return value


def suite_names() -> list[str]:
    from dcee.campaign.suites import SUITES

    return list(SUITES)


def likelihood_names() -> list[str]:
    from dcee.scenarios import LIKELIHOODS

    return list(LIKELIHOODS)


# Shared by ``run`` and ``bench``: what the sensor sees.
TRUTH_OPTION = click.option(
    "--truth",
    help="What the sensor sees: isotropic | filament | puffs | lbm (a fluid solver's planar "
    "plume) | lbm3d (its 3-D surface-layer plume) | PATH of a recording | a GADEN simulation "
    "folder (with `dcee run`, no --scenario needed: the room's own) "
    "[default: the scenario's truth.model].",
)
LIKELIHOOD_OPTION = click.option(
    "--likelihood",
    type=RegistryChoice(likelihood_names),
    help="Reading model of the filter and planners: paper (eq. 3) | fluctuation (intermittent "
    "log-normal for turbulent plumes, with the paper's calm model beside it, the two selected "
    "online by the readings' evidence) [default: the scenario's estimator.likelihood].",
)
SET_OPTION = click.option(
    "--set",
    "settings",
    multiple=True,
    metavar="PATH=VALUE",
    help="Override any scenario setting, e.g. --set sensor.average=0 --set estimator.log_sd=0.8 "
    "(repeatable; VALUE is TOML).",
)


def overrides(likelihood: str | None, settings: tuple[str, ...]) -> dict[str, Any]:
    """The dotted scenario overrides of --likelihood and --set (checked before any work)."""
    from dcee.scenarios import parse_setting

    # the likelihood first: a --set may name a setting that only it allows (estimator.learn)
    out: dict[str, Any] = {"estimator.likelihood": likelihood} if likelihood else {}
    out.update(parse_setting(s) for s in settings)
    return out
