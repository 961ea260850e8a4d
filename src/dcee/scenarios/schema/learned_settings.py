"""The settings the fluctuation likelihood may learn (``estimator.learn``): their names, the
values each may take, the grid and prior it weighs when ``learn`` is unset, and the wall-aware
plume's banks (its diffusivity and its wake's eddy viscosity). Resolved against a scenario by
:mod:`dcee.scenarios.schema.learn`."""

from __future__ import annotations

from typing import Literal

LearnedName = Literal[
    "meander",
    "log_sd",
    "log_sd_near",
    "intermittency",
    "near_source_length",
    "decay",
    "backflow",
    "source_radius",
    "vertical_ratio",
    "ground",
    "vertical_meander",
    "wall_diffusivity",
    "wall_viscosity",
]
"""The reading model's nuisance parameters ``estimator.learn`` may weigh."""
PLUME_SHAPE_SETTINGS = (
    "meander",
    "decay",
    "backflow",
    "source_radius",
    "vertical_ratio",
    "ground",
    "vertical_meander",
)
"""The open plume's shape settings (:class:`~dcee.models.plume.IsotropicPlume`): the wall-aware
plume has none of them, so ``estimator.plume = "walls"`` learns none."""
LEARN_RANGES: dict[str, tuple[float, float]] = {
    "meander": (0.0, 2.0),
    "log_sd": (1e-3, 5.0),
    "log_sd_near": (0.0, 10.0),
    "intermittency": (1e-3, 1.0),
    "near_source_length": (0.0, 1000.0),
    "decay": (0.25, 2.0),
    "backflow": (0.0, 0.5),
    "source_radius": (0.0, 10.0),
    "vertical_ratio": (0.1, 10.0),
    "ground": (0.0, 1.0),
    "vertical_meander": (0.0, 2.0),
    "wall_diffusivity": (1e-3, 1000.0),
    "wall_viscosity": (1e-3, 100.0),
}
"""Allowed values of each learned setting (as for the fixed setting)."""
LEARN_DEFAULT: dict[str, dict[str, list[float]]] = {
    "paper": {},
    "fluctuation": {"backflow": [0.0, 0.05], "source_radius": [0.0, 1.0]},
}
"""``estimator.learn`` when not given, per likelihood (a setting fixed by hand, e.g.
``estimator.backflow = 0.05``, is not learned unless asked; the others still are). The
fluctuation likelihood weighs a member with gas upwind of the release (w = 0.05: a planar plume
at turbulence intensity 0.6, a 3-D one at 0.9) beside the plain plume, chosen on the tuning
range random:13-40 (filament + puffs, ``dcee-cl``, 56 paired searches, rule written before the
run): 56/56 acquired either way, the truth in the 95 % region in 100 % against 95 % (+3 / −0),
the final error unchanged at the median pair (−0.00 m, Wilcoxon p = 0.59)
(docs/results/tuning-backflow-13-40); and a release spread over a disc of radius 1 m beside the
point release, at prior odds 9 : 1 against (:data:`LEARN_PRIOR_DEFAULT`), with the bank's region
the members' mixture's, chosen on the same range released at a point and over an area
(``truth.model.puff_radius = 0.5``), 112 paired searches, rule written before the run
(docs/plumes.md, docs/results/mixture-region-prior-13-40)."""
LEARN_PRIOR_DEFAULT: dict[str, dict[str, list[float]]] = {
    "paper": {},
    "fluctuation": {"source_radius": [0.9, 0.1]},
}
"""``estimator.learn_prior`` when neither it nor ``estimator.learn`` is given, per likelihood:
the disc member leads only where the readings favour it by a Bayes factor above 9, about where
Jeffreys' scale calls evidence strong (the value from that convention, not from a search; the
equal prior let the disc lead on point releases: docs/results/tuning-source-radius-13-40)."""


WALL_DIFFUSIVITY_FACTORS = (1.0, 3.0, 10.0)
"""The wall-aware plume's diffusivity K the fluctuation likelihood weighs by default, as
multiples of the fixed one (the scenario's ζ1 unless ``estimator.wall_diffusivity`` is set): a
decade in steps of about √10: the spread of a plume among buildings (wakes, channelling; the
fluid solver's eddies) is not known before the search, and each member is a filter updated at
every reading. A fourth member at 30 × was tried on the tuning sites and not taken (13/20
acquired either way, median final error 0.54 against 0.52 m;
docs/results/sites-walls-tune/diffusivity-bank)."""

WALL_VISCOSITY_FACTORS = (1.0, 0.2)
"""The wake wind's eddy viscosity ν_t the fluctuation likelihood weighs by default beside the
fixed one (``estimator.wall_viscosity``, else :data:`~dcee.models.site_flow.WAKE_VISCOSITY`),
as multiples of it; each value is its own wake, solved once, and each (K, ν_t) a member. A
lower ν_t gives a longer, stronger recirculation that carries gas from a release in a
building's lee back upwind, as the fluid solver's truth does on the sites searches failed on
(docs/results/site-upwind-gas); a fixed lower ν_t did no better over all (0.25 and 0.5 m²/s:
14/20 against 13/20, docs/results/sites-walls-tune/viscosity): the readings choose per site.
The factor 0.2 from a look at the model's field for the true release at 1, 0.2 and
0.05 m²/s on five failed sites of the tuning range, not from a search. Chosen on the tuning
sites ``random-site:101-120`` (``dcee-cl``, rule written before the run: more acquired, wins >
losses, the median final error no higher by more than 0.1 m): 17/20 against 13/20 (+4 / −0),
median final error 0.61 against 0.97 m (paired −0.11 m, Wilcoxon p = 0.03). Flown once on
``random-site:201-220``, never flown before: 15/20 against 11/20 (+4 / −0, McNemar
p = 0.125), the truth in the 95 % region 17/20 against 13/20, paired −0.10 m (p = 0.04). A
small cost on the four built-in sites (39/40 against 40/40, paired +0.08 m), a large gain on
the real block of ``area:fontvieille`` (9/10 against 2/10); docs/results/lee-viscosity."""
