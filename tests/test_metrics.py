"""Summary metrics against hand calculations: the longest stall."""

import numpy as np

from dcee.runs.metrics import longest_stall, search_stall


def _stall(xy, acquired=None, step=2.0, dt=2.0):
    xy = np.asarray(xy, float)
    times = dt * np.arange(len(xy))
    acq = np.zeros(len(xy), bool) if acquired is None else np.asarray(acquired, bool)
    return longest_stall(times, xy, acq, step)


def test_pacing_between_two_cells_is_a_stall_and_moving_on_is_not():
    pacing = [(0, 0), (2, 0)] * 10  # 20 readings 2 s apart, never more than a step away
    assert _stall(pacing) == 38.0
    straight = [(2 * k, 0) for k in range(20)]  # each reading one step further
    assert _stall(straight) == 2.0  # one move: the reading before and the one after
    diagonal = [(0, 0), (2, 0), (2, 2), (0, 2)] * 3  # a 2 m square: (2, 2) is 2.83 m away
    assert _stall(diagonal) == 2.0
    assert _stall([(0, 0)]) == 0.0


def test_pacing_after_the_source_is_acquired_is_not_a_stall():
    pacing = [(0, 0), (2, 0)] * 10
    acquired = [False] * 6 + [True] * 14
    assert _stall(pacing, acquired) == 10.0  # readings 0-5
    assert _stall(pacing, [True] * 20) == 0.0


def test_a_team_stalls_as_long_as_its_longest_stalling_robot():
    rows = []
    for k in range(10):  # robot 0 paces, robot 1 moves on, both read every 2 s
        rows.append({"robot": 0, "time": 2.0 * k, "x": 2.0 * (k % 2), "y": 0.0, "rmse": 9.0})
        rows.append({"robot": 1, "time": 2.0 * k, "x": 2.0 * k, "y": 9.0, "rmse": 9.0})
    assert search_stall(rows, 2.0, 3.0) == 18.0
    assert search_stall(rows[1::2], 2.0, 3.0) == 2.0


def test_stall_start_is_the_first_of_the_latest_run_within_one_step():
    from dcee.models.agent import stall_start

    assert stall_start(np.array([[0, 0], [2, 0], [0, 0], [2, 0]]), 2.0) == 0
    assert stall_start(np.array([[9, 9], [0, 0], [2, 0], [0, 0]]), 2.0) == 1
    assert stall_start(np.array([[0, 0], [2, 0], [4, 0]]), 2.0) == 1  # moved on: its last move
    assert stall_start(np.array([[5, 5]]), 2.0) == 0


def test_circling_in_one_region_is_a_wander_but_not_a_stall():
    from dcee.runs.metrics import WANDER_RADIUS, search_wander

    # 2 m steps round a square of side 8 m (every corner within 7.5 m of the first), 5 s apart,
    # for 200 s; then straight away east; then the source acquired in one region
    square = [(10, 10), (12, 10), (14, 10), (16, 10), (16, 12), (16, 14), (16, 16), (14, 16),
              (12, 16), (10, 16), (10, 14), (10, 12)]  # fmt: skip
    xy = [square[k % len(square)] for k in range(41)]
    xy += [(16 + 2 * k, 10) for k in range(1, 11)]
    rows = [
        {"time": 5.0 * k, "x": x, "y": y, "rmse": 5.0, "spread": 12.0}
        for k, (x, y) in enumerate(xy)
    ]
    assert search_wander(rows, 3.0) == 200.0
    assert search_stall(rows, 2.0, 3.0) <= 10.0  # never more than a corner within one step
    # staying there once the source is acquired is not wandering, nor with a belief narrower
    # than the region (closing in, or stuck on a wrong estimate: the final error counts that)
    assert search_wander([dict(r, rmse=1.0) for r in rows], 3.0) == 0.0
    assert search_wander([dict(r, spread=WANDER_RADIUS) for r in rows], 3.0) == 0.0
    assert WANDER_RADIUS == 7.5


def test_the_exploration_guard_is_on_at_a_site_and_off_in_open_terrain():
    from dcee.scenarios import load_scenario

    assert not load_scenario("paper:1").explore_guard
    assert load_scenario("paper:1").with_overrides(**{"search.explore_guard": True}).explore_guard
    assert load_scenario("site:wall").explore_guard and load_scenario("site:nogo").explore_guard
    assert (
        not load_scenario("site:wall")
        .with_overrides(**{"search.explore_guard": False})
        .explore_guard
    )
    assert load_scenario("random2:1").with_overrides(**{"estimator.max_sources": 2}).explore_guard
