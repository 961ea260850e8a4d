"""Infotaxis in its KL form: move where the next reading is expected to teach the most."""

from __future__ import annotations

from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.planning.base import Belief, register
from dcee.planning.hypothesis import HypothesisPlanner
from dcee.planning.predicted import SequenceStats

INFORMATION_TARGETS = ("parameters", "location")
"""What Infotaxis' information gain is about: every unknown parameter (Θ: the joint KL divergence
over the particles, as in Ristic et al. 2016) or the source location alone (Vergassola et al.
2007; the other unknowns are marginalised, the location binned into cubes of side ``cell``)."""


@register("infotaxis")
class InfotaxisPlanner(HypothesisPlanner):
    """Maximise the expected information gain E_ẑ[KL(p(· | Z_k, ẑ) ‖ p(· | Z_k))] (the mutual
    information between the next reading and ``about``: every parameter or the source location).
    Loss = −KL.

    Options besides :class:`~dcee.planning.hypothesis.HypothesisPlanner`'s: ``about``
    (:data:`INFORMATION_TARGETS`) and ``cell`` (m), the side of the location cubes.
    """

    summary = "Infotaxis: maximise the expected information gain (KL)"

    needs_moments = False

    def __init__(self, about: str = "parameters", cell: float = 1.0, **options: Any) -> None:
        super().__init__(**options)
        if about not in INFORMATION_TARGETS:
            raise DceeInputError(
                "about", f"must be one of {', '.join(INFORMATION_TARGETS)}, got {about!r}"
            )
        if isinstance(cell, bool) or not (isinstance(cell, int | float) and 0 < cell < 1e6):
            raise DceeInputError("cell", f"must be a length in metres > 0, got {cell!r}")
        self.about = str(about)
        self.cell = float(cell)
        self.needs_kl = self.about == "parameters"
        self.location_cell = self.cell if self.about == "location" else None

    def options(self) -> dict[str, Any]:
        return {**super().options(), "about": self.about, "cell": self.cell}

    def loss(self, final_positions: np.ndarray, stats: SequenceStats, belief: Belief) -> np.ndarray:
        return -(stats.kl if self.about == "parameters" else stats.location_kl)
