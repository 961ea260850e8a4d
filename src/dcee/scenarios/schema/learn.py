"""The learned grid of the fluctuation likelihood (``estimator.learn``, ``estimator.learn_prior``)
resolved against a scenario: what an unset grid or prior weighs, whether a prior fits its grid,
and each member's prior weight."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from dcee.scenarios.schema.learned_settings import (
    LEARN_DEFAULT,
    LEARN_PRIOR_DEFAULT,
    PLUME_SHAPE_SETTINGS,
    WALL_DIFFUSIVITY_FACTORS,
    WALL_VISCOSITY_FACTORS,
)


def default_learn(likelihood: str, fixed: Mapping[str, float]) -> dict[str, list[float]]:
    """What an unset ``estimator.learn`` weighs: :data:`LEARN_DEFAULT` for the likelihood,
    without the settings fixed by hand (``fixed``: the estimator's settings by name; one of the
    grid's whose value is not its grid's first, the plain model's, is not learned; one absent
    counts as the plain model's), and without the open plume's shape settings under the
    wall-aware plume (``fixed["plume"] == "walls"``), which weighs its diffusivity
    (:data:`WALL_DIFFUSIVITY_FACTORS` × ``fixed["wall_diffusivity"]``) and, in the wake wind
    (``fixed["wall_wind"] == "wake"``), its eddy viscosity (:data:`WALL_VISCOSITY_FACTORS` ×
    ``fixed["wall_viscosity"]``) instead."""
    grid = LEARN_DEFAULT[likelihood]
    walls = fixed.get("plume") == "walls"
    # a copy: callers may edit it
    out = {
        key: list(v)
        for key, v in grid.items()
        if fixed.get(key, v[0]) == v[0] and not (walls and key in PLUME_SHAPE_SETTINGS)
    }
    if walls and likelihood == "fluctuation":
        if fixed.get("wall_diffusivity") is not None:
            k0 = float(fixed["wall_diffusivity"])
            out["wall_diffusivity"] = [k0 * f for f in WALL_DIFFUSIVITY_FACTORS]
        if fixed.get("wall_wind") == "wake":
            nu0 = float(fixed["wall_viscosity"])
            out["wall_viscosity"] = [nu0 * f for f in WALL_VISCOSITY_FACTORS]
    return out


def default_learn_prior(
    likelihood: str, fixed: Mapping[str, float], learn: dict[str, list[float]] | None
) -> dict[str, list[float]]:
    """What an unset ``estimator.learn_prior`` says: :data:`LEARN_PRIOR_DEFAULT` with the
    default grid (``learn`` None), nothing (every value equally likely) with a grid given."""
    if learn is not None:
        return {}
    grid = default_learn(likelihood, fixed)
    prior = LEARN_PRIOR_DEFAULT[likelihood]
    return {key: list(probs) for key, probs in prior.items() if key in grid}


LEARN_MEMBERS_MAX = 12
"""Most fluctuation members a learned grid may make (each costs one filter update per reading)."""


def learn_prior_problem(
    learn_prior: dict[str, list[float]] | None, learn: dict[str, list[float]]
) -> str | None:
    """Why ``estimator.learn_prior`` does not fit the resolved ``learn`` grid (a message naming
    the field), or None."""
    for key, probs in (learn_prior or {}).items():
        values = learn.get(key)
        if values is None:
            return f"estimator.learn_prior.{key}: {key} is not learned (estimator.learn)"
        if len(probs) != len(values) or not all(np.isfinite(p) and p > 0 for p in probs):
            return (
                f"estimator.learn_prior.{key}: one positive probability per value of "
                f"estimator.learn.{key} {values} (got {probs})"
            )
    return None


def learn_member_weight(
    settings: dict[str, float],
    learn: dict[str, list[float]],
    learn_prior: dict[str, list[float]] | None,
) -> float:
    """The prior weight of the fluctuation member with these learned ``settings``: the product,
    over the settings ``learn_prior`` names, of each value's normalised probability (a setting it
    does not name weighs its values equally: the same factor for every member)."""
    weight = 1.0
    for key, probs in (learn_prior or {}).items():
        values = learn[key]
        index = int(np.argmin([abs(v - settings[key]) for v in values]))
        weight *= probs[index] / sum(probs)
    return weight
