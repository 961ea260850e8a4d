"""Searcher checkpoints: a restored search continues exactly as the uninterrupted one."""

from __future__ import annotations

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.planning import get as get_planner
from dcee.runs import SearchSimulation, planner_defaults
from dcee.scenarios import load_scenario
from dcee.searcher import Searcher


def _sim(strategy: str, particles: int = 1500) -> SearchSimulation:
    sc = load_scenario("lab:upwind").with_overrides(
        **{"search.particles": particles, "search.hypotheses": 10, "agent.model": "unicycle"}
    )
    planner = get_planner(strategy, **planner_defaults(strategy, sc, None))
    return SearchSimulation(sc, seed=3, planner=planner)


def _run(sim: SearchSimulation, searcher: Searcher, steps: int) -> list[np.ndarray]:
    """Drive ``steps`` sense/ask/move cycles with ``searcher`` as the simulation's searcher."""
    sim.searcher = searcher
    sim.filter = searcher.filter
    out = []
    for _ in range(steps):
        sim.sense()
        waypoint = searcher.ask()
        out.append(waypoint)
        sim.move(waypoint)
    return out


@pytest.mark.parametrize("strategy", ["infotaxis", "dcee"])
def test_restored_searcher_makes_the_same_decisions(tmp_path, strategy: str) -> None:
    a, b = _sim(strategy), _sim(strategy)
    first = _run(a, a.searcher, 12)
    _run(b, b.searcher, 12)  # the same world state in b
    path = b.searcher.save(tmp_path / "search.ckpt")
    restored = Searcher.load(path)
    assert restored.checkpoint_code is not None
    assert restored is not b.searcher
    # the uninterrupted search (a) and the restored one (b's world, restored searcher) go on
    cont_a = _run(a, a.searcher, 15)
    cont_b = _run(b, restored, 15)
    assert len(first) == 12
    for wa, wb in zip(cont_a, cont_b, strict=True):
        np.testing.assert_array_equal(wa, wb)
    np.testing.assert_array_equal(a.filter.theta, restored.filter.theta)
    np.testing.assert_array_equal(a.filter.weights, restored.filter.weights)
    assert a.filter.n_resamples == restored.filter.n_resamples > 0


def test_checkpoint_write_errors(tmp_path) -> None:
    sim = _sim("mpc", particles=200)
    sim.sense()
    (tmp_path / "bad.ckpt").write_text("a file where a folder is needed")
    with pytest.raises(DceeInputError, match="cannot write checkpoint"):
        sim.searcher.save(tmp_path / "bad.ckpt" / "sub" / "x.ckpt")
    with pytest.raises(DceeInputError, match=r"is a folder; give the checkpoint a file name"):
        sim.searcher.save(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.ckpt"]  # no temporary left


@pytest.mark.parametrize(
    "strategy", ["infotaxis", "entrotaxis", "dcee", "dcee-cl", "mpc", "dcee-ms", "dcee-mcts"]
)
def test_every_planner_resumes_from_a_checkpoint(tmp_path, strategy: str) -> None:
    """Each registered planner's searcher goes through the data-only format and decides as the
    searcher that was saved (a state the format cannot hold fails here, naming the attribute)."""
    a = _sim(strategy, particles=300)
    _run(a, a.searcher, 3)
    restored = Searcher.load(a.searcher.save(tmp_path / "s.ckpt"))
    b = _sim(strategy, particles=300)
    _run(b, b.searcher, 3)
    np.testing.assert_array_equal(_run(a, a.searcher, 2), _run(b, restored, 2))
