"""A run's identity: what must match for two results to belong to one study. A stored scenario
is reduced to what decides its results (no free-text description; settings added later compare
equal at the value the stored run used), so resuming a campaign or rerunning a ``dcee run``
folder refuses only real changes."""

from __future__ import annotations

import copy
from typing import Any

from dcee.scenarios import (
    OLD_OUTLIER_DEFAULT,
    READING_WEIGHT_DEFAULT,
    REPEAT_DEFAULT,
    UnicycleSpec,
    default_learn,
    default_learn_prior,
    unset_climb,
    unset_lookahead,
    unset_region_floor,
)
from dcee.scenarios.schema.reading_models import unset_plume
from dcee.scenarios.schema.world import WorldSpec, has_walls


def _unicycle_defaults() -> dict[str, Any]:
    return UnicycleSpec().model_dump(mode="json")


LATER_DEFAULTS: dict[tuple[str, ...], Any] = {
    ("agent", "count"): 1,
    # a fixed altitude before issue 29's climbing agent
    ("agent", "climb"): 0.0,
    # the robot's motion (issue 15); the grid agent at these defaults is the one that ran before
    ("agent", "model"): "grid",
    ("agent", "heading"): 0.0,
    ("agent", "localisation_sd"): 0.0,
    # the area's floor bounded the agent before agent.min_altitude
    ("agent", "min_altitude"): None,
    ("agent", "unicycle"): _unicycle_defaults(),
    # the fluctuation likelihood ran without the calm model before the setting existed (so a
    # campaign stored before resumes only with calm_prior = 0, not with the new default)
    ("estimator", "calm_prior"): 0.0,
    # no stall guard before issue 28
    ("search", "stall_guard"): 0.0,
    # the guard acted while the spread exceeded acquired_rmse before the share existed
    ("search", "guard_share"): 1.0,
    # every reading counted fully before issue 29
    ("estimator", "reading_weight"): 1.0,
    # a constant log-sd before the distance-dependent spread existed
    ("estimator", "log_sd_near"): 0.0,
    ("estimator", "log_sd_length"): 0.0,
    # every detection weighed by its magnitude before issue 29's detection-only readings
    ("estimator", "magnitude"): True,
    # a detection's mean was C (not C / Pd) before the mean-conserving intermittency
    ("estimator", "conserve_mean"): False,
    # every reading weighed reading_weight before the repeat discount
    ("estimator", "repeat_radius"): 0.0,
    ("estimator", "repeat_power"): 1.0,
    # every nuisance setting of the reading model fixed before issue 42's learned bank
    ("estimator", "learn"): {},
    # the point source's 1/r before issue 42's decay setting
    ("estimator", "decay"): 1.0,
    # no gas upwind of the release before issue 42's backflow setting
    ("estimator", "backflow"): 0.0,
    # a point source before issue 42's source_radius setting
    ("estimator", "source_radius"): 0.0,
    # the plume grew upwards by diffusion alone before issue 78's vertical meander
    ("estimator", "vertical_meander"): 0.0,
    # every learned value equally likely before issue 42's learn_prior setting
    ("estimator", "learn_prior"): {},
    # input only (a compass bearing converted to phi), always unset once validated
    ("truth", "wind_from"): None,
    # one release before issue 45's further releases
    ("truth", "extra_sources"): [],
    # dcee-cl looked one move ahead everywhere before search.lookahead (issue 42)
    ("search", "lookahead"): 1,
    # the particles' own 95 % region before issue 42's model-discrepancy floor
    ("estimator", "region_floor"): 0.0,
}
"""Scenario settings added after campaigns were first stored, with the value a stored scenario
without one ran with, so the two compare equal."""


_MISSING = object()

FLUCTUATION_ONLY = (
    "intermittency",
    "log_sd",
    "log_sd_near",
    "log_sd_length",
    "near_source_length",
    "calm_prior",
    "magnitude",
    "conserve_mean",
    "decay",
    "backflow",
    "source_radius",
    "vertical_meander",
    "learn",
)
"""Estimator settings that only the fluctuation likelihood reads: under the paper's likelihood
they decide nothing, so changing their defaults must not orphan a campaign."""


OLD_FALL_REPEAT = (2.5, (2.0, 0.25))
"""The fluctuation likelihood's near-source fall (m) and repeat discount (radius m, power) until
2026-11-27, when the two defaults changed together (0.5 m, power 1/2; issue 42)."""


def _unset_repeat(likelihood: str, estimator: dict[str, Any]) -> tuple[float, float]:
    """What an unset repeat discount ran with. Every stored scenario holds its near-source fall
    as a number, and the fall and the power changed together: a fluctuation scenario stored with
    the old 2.5 m fall and no power ran with power 1/4 (pin the power to compare a 2.5 m fall at
    today's power)."""
    if likelihood == "fluctuation" and estimator.get("near_source_length") == OLD_FALL_REPEAT[0]:
        return OLD_FALL_REPEAT[1]
    return REPEAT_DEFAULT[likelihood]


def settings_identity(settings: dict[str, Any]) -> dict[str, Any]:
    """What must match for results to belong together: the settings without the scenarios'
    free-text descriptions (rewording one must not orphan a campaign; it changes no result),
    without later-added settings at their defaults (:data:`LATER_DEFAULTS`), and without the
    ``--set`` overrides where the scenarios are stored (they hold every override's effect)."""
    out = dict(settings)
    overrides = out.get("overrides")
    if isinstance(out.get("scenarios"), dict) and out["scenarios"]:
        # every override is applied to every stored scenario, which records its effect: a
        # default pinned to the value a stored campaign ran with (a later-added setting, or an
        # old default after it changed) says nothing the scenarios do not
        out.pop("overrides", None)
    elif isinstance(overrides, dict):
        # a later-added setting pinned (--set) to the value a campaign stored before it existed
        # ran with says nothing the scenarios do not: the stored campaign still resumes
        kept = {
            key: value
            for key, value in overrides.items()
            if LATER_DEFAULTS.get(tuple(key.split(".")), _MISSING) != value
        }
        if kept:
            out["overrides"] = kept
        else:
            out.pop("overrides")
    scenarios = out.get("scenarios")
    # what a campaign's unset defaults resolved to when it was stored (since 2026-12-02): each
    # scenario compared as if they had been set to those values, so that a default changed
    # since is a difference (and pinning the old value with --set resumes the campaign)
    resolved = out.pop("resolved", None)
    if isinstance(scenarios, dict):
        out["scenarios"] = {
            name: scenario_identity(_with_resolved(sc, (resolved or {}).get(name)))
            if isinstance(sc, dict)
            else sc
            for name, sc in scenarios.items()
        }
    return out


def _with_resolved(scenario: dict[str, Any], resolved: Any) -> dict[str, Any]:
    """The stored ``scenario`` with each unset setting named in ``resolved`` ({"section.key":
    value}) set to that value."""
    if not isinstance(resolved, dict) or not resolved:
        return scenario
    out = copy.deepcopy(scenario)
    for dotted, value in resolved.items():
        section, _, key = str(dotted).partition(".")
        node = out.get(section)
        if isinstance(node, dict) and node.get(key) is None:
            node[key] = value
    return out


def scenario_key(scenario: Any) -> dict[str, str]:
    """{"name", "identity"}: a :class:`~dcee.scenarios.Scenario`'s name and the SHA-256 of its
    :func:`scenario_identity` (what a checkpoint records, so that a search is resumed only
    under the scenario it belongs to)."""
    import hashlib
    import json

    ident = scenario_identity(scenario.model_dump(mode="json"))
    digest = hashlib.sha256(json.dumps(ident, sort_keys=True, default=str).encode()).hexdigest()
    return {"name": str(scenario.name), "identity": digest}


def scenario_identity(scenario: dict[str, Any]) -> dict[str, Any]:
    """A stored scenario (its JSON dump) reduced to what decides the results: without its
    free-text description and without later-added settings at their defaults."""
    out = copy.deepcopy({k: v for k, v in scenario.items() if k != "description"})
    estimator = out.get("estimator")
    if isinstance(estimator, dict) and "plume" in estimator and estimator["plume"] is None:
        # unset: the plume it resolved to (Scenario.plume_model), compared as that model
        estimator["plume"] = unset_plume(
            has_walls(out.get("world")),
            str(out.get("unknown", "source")),
            int(estimator.get("max_sources", 1)),
            estimator.get("learn"),
        )
    if isinstance(estimator, dict):
        likelihood = estimator.get("likelihood", "paper")
        if likelihood == "paper":
            for key in FLUCTUATION_ONLY:  # read by the fluctuation likelihood only
                estimator.pop(key, None)
        if estimator.get("outlier", 0) is None:
            # stored before issue 29, when an unset weight meant 0 for the paper's likelihood
            estimator["outlier"] = OLD_OUTLIER_DEFAULT[likelihood]
        if "reading_weight" in estimator and estimator["reading_weight"] is None:
            # unset: the likelihood's default, compared as the number it stands for
            estimator["reading_weight"] = READING_WEIGHT_DEFAULT[likelihood]
        if "region_floor" in estimator and estimator["region_floor"] is None:
            # unset: the likelihood's default, compared as the number it stands for
            estimator["region_floor"] = unset_region_floor(
                likelihood, estimator.get("plume", "open")
            )
        for k, key in enumerate(("repeat_radius", "repeat_power")):
            if key in estimator and estimator[key] is None:
                # unset: the likelihood's default, compared as the number it stands for
                estimator[key] = _unset_repeat(likelihood, estimator)[k]
        if "learn_prior" in estimator and estimator["learn_prior"] is None:
            # unset: the prior it resolved to (Scenario.learn_prior), compared as that prior
            # (no learn key: stored before the learned bank, which ran no grid; a setting
            # stored before it existed ran at the plain model's value, as default_learn takes)
            estimator["learn_prior"] = default_learn_prior(
                likelihood, estimator, estimator.get("learn", {})
            )
        if "learn" in estimator and estimator["learn"] is None:
            # unset: the grid it resolved to (Scenario.learn), compared as that grid
            estimator["learn"] = default_learn(likelihood, estimator)
        if estimator.get("repeat_radius", 0.0) == 0.0:
            # no repeat discount: its power decides nothing
            estimator.pop("repeat_power", None)
    agent = out.get("agent")
    est = estimator if isinstance(estimator, dict) else {}
    world = WorldSpec.model_validate(out.get("world") or {})  # a stored dump round-trips
    if isinstance(agent, dict) and "climb" in agent and agent["climb"] is None:
        # unset: the climb it resolved to (Scenario.resolved_climb), compared as that number
        agent["climb"] = unset_climb(
            est.get("likelihood", "paper"),
            agent.get("model", "grid"),
            max_sources=int(est.get("max_sources", 1)),
            open_terrain=world.empty,
        )
    search = out.get("search")
    if isinstance(search, dict) and "lookahead" in search and search["lookahead"] is None:
        # unset: the look-ahead it resolved to (Scenario.lookahead), compared as that number
        model = agent.get("model", "grid") if isinstance(agent, dict) else "grid"
        search["lookahead"] = unset_lookahead(
            est.get("likelihood", "paper"),
            model,
            int(est.get("max_sources", 1)),
            world.empty,
            est.get("plume", "open") == "walls",
        )
    sensor, truth = out.get("sensor"), out.get("truth")
    if isinstance(sensor, dict) and "dropout" not in sensor and isinstance(truth, dict):
        # stored before sensor.dropout existed, when the instrument missed 1 − pd of the
        # readings on every truth: the default now does so on the isotropic truth only
        if truth.get("model", "isotropic") != "isotropic":
            sensor["dropout"] = round(1.0 - float(sensor.get("pd", 0.7)), 12)
        else:
            sensor["dropout"] = None
    for path, default in LATER_DEFAULTS.items():
        node = out
        for key in path[:-1]:
            node = node.get(key) if isinstance(node, dict) else None
        if isinstance(node, dict) and node.get(path[-1], default) == default:
            node.pop(path[-1], None)
    return out


def first_difference(a: Any, b: Any, path: str = "") -> str:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if a.get(k) != b.get(k):
                return first_difference(a.get(k), b.get(k), f"{path}.{k}" if path else k)
    return f"{path or 'settings'}: stored {a!r}, now {b!r}"
