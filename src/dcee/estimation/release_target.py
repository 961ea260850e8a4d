"""Which release the planners and the stop rule act on when the number of releases is
unknown (:class:`~dcee.estimation.source_count.SourceCountBank`): a decision on the posterior
over the count and each count's releases, kept apart from the inference that makes them.

The *target* is the most probable count's least-localised release until each of its releases
is found (spread √tr P at most ``found``), then the least-localised release among the counts
K ≥ 1 still plausible (P(K) ≥ ``plausible``) and the count one above the most probable, so the
robot looks where a further release could still be. The *settled* target, which the stop rule
and the estimate read, is the same without the count above and with ``localised`` for
``found`` (the module doc of :mod:`dcee.estimation.source_count` says why).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

DEFAULT_PLAUSIBLE = 0.05
"""P(K) at or above which a count's releases count for the target and the stop rule: a search
ends only when every count at least this probable has its releases localised."""


FOUND_SHARE = 1 / 3
"""A release whose spread √tr P is at most this share of ``search.acquired_rmse`` (1 m at the
default 3 m) counts as found for the planners' target: once every release of the most probable
count is found, they look for a further one
(:meth:`~dcee.estimation.source_count.SourceCountBank.target`). Chosen on the
tuning range random3:1-20 (docs/results/source-count-tune): with the stop rule's 0.45 m a
found release whose height stayed uncertain (spread 0.5-0.9 m) held the robot for the rest of
the search."""


def choose_targets(
    probabilities: np.ndarray,
    release_covs: Callable[[int], np.ndarray],
    plausible: float,
    found: float,
    localised: float,
) -> tuple[tuple[int, int], tuple[int, int]]:
    """((K, j) target, (K, j) settled target) from P(K) (K_max + 1,) for K = 0 … K_max and
    ``release_covs(k)`` (k, 3, 3) m², the K = k filter's release covariances (asked at most
    once per count). ``found`` and ``localised`` m; count 0 most probable: the one-release
    filter's release."""
    best_count = max(int(np.argmax(probabilities)), 1)
    max_sources = len(probabilities) - 1
    widest: dict[int, tuple[int, float]] = {}

    def widest_of(k: int) -> tuple[int, float]:
        if k not in widest:
            traces = np.trace(release_covs(k), axis1=1, axis2=2)
            widest[k] = int(np.argmax(traces)), float(traces.max())
        return widest[k]

    def choose(threshold: float, extra: int | None) -> tuple[int, int]:
        j, trace = widest_of(best_count)
        if trace > threshold**2:
            return best_count, j
        counts = [k for k in range(1, max_sources + 1) if probabilities[k] >= plausible]
        if extra is not None and extra <= max_sources and extra not in counts:
            counts = sorted([*counts, extra])
        if not counts:
            return best_count, j
        k = max(counts, key=lambda k: widest_of(k)[1])  # the first of equals
        return k, widest_of(k)[0]

    return choose(found, best_count + 1), choose(localised, None)


__all__ = ["DEFAULT_PLAUSIBLE", "FOUND_SHARE", "choose_targets"]
