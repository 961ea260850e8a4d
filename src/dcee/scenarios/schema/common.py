"""What every part of the scenario schema shares: immutable, strict models and number types."""

from __future__ import annotations

from typing import Annotated

from pydantic import ConfigDict, Field

FROZEN = ConfigDict(frozen=True, extra="forbid", use_attribute_docstrings=True)
Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]

__all__ = ["FROZEN", "Finite", "Positive"]
