"""The random streams of a search: every draw of a search comes from one seed.

``SeedSequence(seed)`` is split into a *truth* stream (sensor noise of the real readings), an
*agent* stream (split again into filter and planner) and a *figures* stream (particle
subsamples for plots only); child 3 of the seed drives a stochastic truth such as the filament
plume (:func:`dcee.simulation.truth.plume_stream`), child 4 the localisation errors. The truth
stream draws the same numbers at every step whatever the agent does, so two strategies run with
the same seed see identical truth noise (common random numbers).
"""

from __future__ import annotations

import numpy as np


def streams(seed: int) -> tuple[np.random.Generator, ...]:
    """(truth, filter, planner, figures) generators derived from one seed. The figures stream
    only subsamples particles for plots, so plotting never changes a search."""
    truth_ss, agent_ss, figure_ss = np.random.SeedSequence(seed).spawn(3)
    filter_ss, planner_ss = agent_ss.spawn(2)
    return tuple(np.random.default_rng(s) for s in (truth_ss, filter_ss, planner_ss, figure_ss))


MOTION_STREAM = 4
"""Child of the seed that draws the localisation errors (children 0-2 are :func:`streams`, 3 the
stochastic truth's), so adding localisation noise changes no other draw."""


ANEMOMETER_STREAM = 5
"""Child of the seed that draws the anemometer's noise (so a measured wind changes no other
draw: a search with and without it is paired exactly up to the first wind reading)."""


def anemometer_stream(seed: int) -> np.random.Generator:
    """The generator of the simulated anemometer's noise for episode ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(ANEMOMETER_STREAM,)))


def motion_stream(seed: int) -> np.random.Generator:
    """The generator of the robots' localisation errors for episode ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(MOTION_STREAM,)))
