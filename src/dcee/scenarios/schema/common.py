"""What every part of the scenario schema shares: immutable, strict models and number types."""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import ConfigDict, Field

from dcee.models.compass import bearing_from_phi, phi_from_bearing

FROZEN = ConfigDict(frozen=True, extra="forbid", use_attribute_docstrings=True)
Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]

FIELD_MARK = "@field "
"""Prefix of a cross-field check's message that names the field at fault (``@field
agent.step: …``): :func:`~dcee.scenarios.schema.validate_scenario` reports that field instead
of the model's."""

__all__ = ["FIELD_MARK", "FROZEN", "Finite", "Positive", "phi_fields", "phi_prior_from_bearing"]


def phi_fields(data: dict[str, Any], where: str) -> dict[str, Any]:
    """A ``where`` table (``truth``) given with ``wind_from`` (a compass bearing, °): the
    ``phi`` it means and ``wind_from`` cleared (:mod:`dcee.models.compass`); both given:
    ValueError unless they agree."""
    bearing = data["wind_from"]
    number = isinstance(bearing, int | float) and not isinstance(bearing, bool)
    if not (number and math.isfinite(bearing) and 0.0 <= bearing <= 360.0):
        raise ValueError(
            f"{FIELD_MARK}{where}.wind_from: a compass bearing in degrees, in [0, 360], "
            f"got {bearing!r}"
        )
    phi = phi_from_bearing(float(bearing))
    given = data.get("phi")
    if given is not None and abs((float(given) - phi + 180.0) % 360.0 - 180.0) > 1e-9:
        raise ValueError(
            f"{FIELD_MARK}{where}.wind_from: give {where}.phi or {where}.wind_from, not both "
            f"(phi {given} is the bearing {bearing_from_phi(float(given)):g}, not {bearing:g})"
        )
    return {"phi": phi if given is None else given, "wind_from": None}


def phi_prior_from_bearing(spec: Any) -> Any:
    """A prior on the wind direction given as a compass bearing (``prior.wind_from``, °) as the
    same prior on ``phi``: a normal's mean mapped (its sd kept), a uniform's range mirrored
    ([a, b] → [90 − b, 90 − a])."""
    if not isinstance(spec, dict):
        return spec
    out = dict(spec)
    if isinstance(out.get("mean"), int | float):
        out["mean"] = phi_from_bearing(float(out["mean"]))
    if isinstance(out.get("low"), int | float) and isinstance(out.get("high"), int | float):
        out["low"], out["high"] = 90.0 - float(out["high"]), 90.0 - float(out["low"])
    return out
