"""What each measured default was chosen on: the truths and configurations, so that a reader
knows which results are independent of it (``dcee show`` prints it beside the value; the
README's cross-truth table and docs/scenarios.md say the same).

The rule (DEVELOPERS.md): a default is chosen on a tuning set, on at most two truth families,
and reported on the others. The truth families are ``isotropic`` (the paper's model, its own
likelihood), ``filament`` and ``puffs`` (written here, with the fluctuation likelihood) and
``lbm`` (a fluid solver's plume, :mod:`dcee.simulation.lbm`) and ``lbm3d`` (its 3-D surface-layer
sibling, :mod:`dcee.simulation.lbm3d`): no open-terrain default was chosen on either; the
wall-aware estimator's settings at a site were (the tuning sites, lbm).
"""

from __future__ import annotations

from dataclasses import dataclass

TRUTH_FAMILIES = ("isotropic", "filament", "puffs", "lbm", "lbm3d", "gaden")
"""Every truth family the studies report on."""


@dataclass(frozen=True)
class Provenance:
    """What one default was chosen on."""

    truths: tuple[str, ...]
    """truth families the choice looked at (empty: not chosen by measurement, e.g. the paper's
    value or a physical constant)"""
    configurations: str
    """which configurations (the tuning range) and by what"""

    def line(self) -> str:
        """One line for ``dcee show``."""
        if not self.truths:
            return self.configurations
        held_out = [t for t in TRUTH_FAMILIES if t not in self.truths]
        return (
            f"chosen on {' + '.join(self.truths)} ({self.configurations}); "
            f"independent on {', '.join(held_out)}"
        )


PAPER = Provenance((), "the paper's value (Chen, Rhodes & Liu, table 2)")
DEFAULTS: dict[tuple[str, str], Provenance] = {
    ("agent", "dwell"): Provenance(
        ("filament",), "4 s hold on a time-varying truth: infotaxis, paper configurations, 12 x 3"
    ),
    ("agent", "climb"): Provenance(
        ("isotropic", "filament", "puffs"),
        "1 m with the fluctuation likelihood, filament + puffs random:13-40, dcee-cl; 1 m with "
        "the count of releases unknown, isotropic random2/3:1-60, dcee-cl; 0 on a planar truth, "
        "where nothing tells altitude",
    ),
    ("estimator", "intermittency"): Provenance(
        ("filament",), "maximum-likelihood fit to 4 s holds, studies/fluctuation_stats.py"
    ),
    ("estimator", "log_sd"): Provenance(
        ("filament",), "maximum-likelihood fit to 4 s holds, studies/fluctuation_stats.py"
    ),
    ("estimator", "near_source_length"): Provenance(
        ("filament", "puffs"), "random:13-40, dcee-cl, with repeat_power 0.5 (issue 42)"
    ),
    ("estimator", "conserve_mean"): Provenance(("filament", "puffs"), "random:13-40, dcee-cl"),
    ("estimator", "learn"): Provenance(
        ("filament", "puffs"),
        "backflow = [0, 0.05] and source_radius = [0, 1] weighed beside the fixed 0: "
        "random:13-40 released at a point and over an area, dcee-cl (issue 42)",
    ),
    ("estimator", "learn_prior"): Provenance(
        (), "prior odds 9:1 against the disc: Jeffreys' 'strong' evidence, not a search"
    ),
    ("estimator", "meander"): Provenance(("filament",), "the filament truth's time mean"),
    ("estimator", "reading_weight"): Provenance(
        ("filament", "puffs"), "random:1-12, dcee-cl and infotaxis"
    ),
    ("estimator", "repeat_radius"): Provenance(("filament", "puffs"), "random:13-40, dcee-cl"),
    ("estimator", "repeat_power"): Provenance(
        ("filament", "puffs"), "random:13-40, dcee-cl, with near_source_length 0.5 (issue 42)"
    ),
    ("estimator", "region_floor"): Provenance(
        ("filament", "puffs"),
        "the fluctuation likelihood's: random:13-40, dcee-cl, the smallest floor of the grid "
        "calibrating the 95 % region on each truth (issue 42); the paper's likelihood: 0",
    ),
    ("estimator", "outlier"): Provenance(
        ("isotropic",), "random:1-6, dcee-cl, one 10^6 x reading, studies/spike_study.py"
    ),
    ("estimator", "calm_prior"): Provenance(
        ("isotropic", "filament"), "which model the evidence selects, docs/scenarios.md"
    ),
    ("estimator", "max_sources"): Provenance(
        (), "1: the paper's one release; the unknown-count estimator is opt-in (issue 45)"
    ),
    ("estimator", "count_prior"): Provenance(
        (), "unset: every count 0 … max_sources equally likely (no count is preferred)"
    ),
    ("estimator", "plume"): Provenance(
        ("lbm",),
        '"walls" wherever there are walls and it applies (the wall-aware estimator against the '
        "wall-blind one on the sites site:wall, passage, canyon, block, 10 seeds, dcee-cl: 40/40 "
        "against 21/40 acquired (39/40 with site:passage flown again on its corrected plume), "
        'issue 44; the default since issue 84), else "open"',
    ),
    ("estimator", "wall_lifetime"): Provenance(
        ("lbm",), "random-site:1-20 (the tuning sites), dcee-cl, docs/results/sites-walls-tune"
    ),
    ("estimator", "wall_wind"): Provenance(
        ("lbm", "gaden"),
        "at a site: random-site:1-20 (the tuning sites), dcee-cl, docs/results/sites-walls-tune; "
        'in a GADEN room "room", its own wind field: GADEN\'s two sample rooms, ten starts, '
        "dcee-cl, docs/plumes.md",
    ),
    ("estimator", "wall_viscosity"): Provenance(
        ("lbm",),
        "random-site:1-20 (the tuning sites), dcee-cl, docs/results/sites-walls-tune/viscosity",
    ),
    ("estimator", "wall_diffusivity"): Provenance(
        ("gaden",),
        "unset: in a GADEN room's own wind 0.002 m²/s (the room's plume against GADEN's "
        "time-mean gas in its two sample rooms, docs/results/gaden/room-fit.json); elsewhere the "
        "scenario's ζ1 (not chosen by measurement); weighed with 3 and 10 times it",
    ),
    ("search", "explore_guard"): Provenance(
        (),
        "unset: on with several releases or on a site ([world] not empty), off in open terrain "
        "(open-terrain searches unchanged; measured on the sites, docs/scenarios.md)",
    ),
    ("search", "lookahead"): Provenance(
        ("filament", "puffs"),
        "3 (dcee-cl looks three moves ahead) with the fluctuation likelihood, one release, open "
        "terrain, grid UAV: random:13-40, dcee-cl, two against one then three against two "
        "(issue 42); at a site with the wall-aware estimator 3, chosen on lbm round the tuning "
        "sites random-site:1-20 among 1, 2, 3 (issue 44; lbm then not independent of it at a "
        "site); 1 elsewhere (not measured there)",
    ),
    ("search", "stall_guard"): Provenance(("isotropic",), "held-out tuning, docs/held-out.md"),
    ("search", "guard_share"): Provenance(("filament", "puffs"), "random:13-40, dcee-cl"),
    ("search", "stop_hold"): Provenance(("isotropic",), "random-tune, 40 configurations"),
    ("sensor", "threshold"): PAPER,
    ("sensor", "pd"): PAPER,
    ("sensor", "sigma_min"): PAPER,
    ("sensor", "sigma_frac"): PAPER,
}
"""(section, setting) → what its default was chosen on."""


__all__ = ["DEFAULTS", "TRUTH_FAMILIES", "Provenance"]
