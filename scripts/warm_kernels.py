"""Compile dcee's numerical kernels into numba's on-disk cache before the test suite runs
(scripts/test.sh): toy searches that between them reach every family of kernels (each
planner, both likelihoods, all eight parameters unknown, a measured wind, several releases, a
site with walls, the turbulent truths).

Why: on a fresh machine the kernels compile on first use (2026-12-05: the core job 45 s of
one core, the two shards 30 s beside each other; 58-62 s and 33 s while the kernels that read
the particles compiled twice, once for a frozen copy: ``dcee.numeric.read_only_view``), and in a
suite run on two processes, whose campaign tests start worker processes of their own, the same
kernel was compiled by several processes at once: the suite took 265 s there against 124 s
with the cache filled. ``core`` compiles what every search uses on one core (the other installs
the ROS 2 venv meanwhile), then two shards side by side compile the rest, each kernel about
once. A kernel the searches below miss is still compiled where a test first needs it; this
only moves work, it checks nothing."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

from dcee.planning import names
from dcee.runs import run_episode
from dcee.scenarios import load_scenario

TOY = {"search.particles": 300, "search.hypotheses": 4, "search.budget": 12.0}


def _search(name: str, overrides: dict, planner: str) -> Callable[[], object]:
    def fly() -> object:
        return run_episode(load_scenario(name).with_overrides(**(TOY | overrides)), planner, 0)

    return fly


def _floor() -> object:
    """``dcee perf``'s plain compiled loop (:mod:`dcee.perf.floor`) on a small posterior."""
    from dcee.perf.decision_workloads import posterior_filter, reference_inputs, searcher_for
    from dcee.perf.floor import floor_decision

    belief, candidates, readings = reference_inputs(searcher_for(posterior_filter(500), "dcee"))
    return floor_decision(
        belief.theta, belief.weights, candidates, readings, belief.sensor, belief.plume
    )


def jobs() -> list[Callable[[], object]]:
    """Every warm-up job, in a fixed order: a toy search per planner and per family of
    settings, and the perf floor."""
    out = [_search(f"random:{1000 + k}", {}, planner) for k, planner in enumerate(names())]
    fluctuation = {"estimator.likelihood": "fluctuation"}
    out += [
        _search("paper:1", {"unknown": "full", "anemometer.enabled": True}, "dcee-cl"),
        _search("paper:1", {"unknown": "full"}, "infotaxis"),
        _search("random:3", {"truth.model": "filament", **fluctuation}, "dcee-cl"),
        _search("random:4", {"truth.model": "puffs", **fluctuation}, "infotaxis"),
        _search("random:5", {"estimator.max_sources": 3}, "dcee-cl"),
        # the kernels, not the truth: the paper's plume (a site's default, the solver's plume,
        # takes a minute to compute the first time), the site's estimator: wall-aware, open
        _search("site:wall", {"truth.model": "isotropic"}, "dcee-cl"),
        _search(
            "site:passage", {"truth.model": "isotropic", "estimator.plume": "open"}, "infotaxis"
        ),
        _floor,
    ]
    return out


def main(argv: list[str]) -> int:
    """``core``: the first job alone (the kernels every search uses: the filter's history
    likelihood, the planners' position rows and statistics); ``SHARD SHARDS``: that shard's
    share of the rest; nothing: every job."""
    every = jobs()
    if argv == ["core"]:
        chosen, what = every[:1], "core"
    elif argv:
        shard, shards = (int(a) for a in argv)
        chosen = [job for i, job in enumerate(every[1:]) if i % shards == shard]
        what = f"shard {shard + 1}/{shards}"
    else:
        chosen, what = every, "all"
    t0 = time.perf_counter()
    for job in chosen:
        job()
    print(f"warm_kernels: {what} in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
