"""The focus window (dcee.estimation.focus): hand-checkable masses and choices."""

import numpy as np

from dcee.estimation.focus import FOCUS_SPENT, densest_window, window_sums


def test_window_sums_by_hand():
    """A 4 × 3 grid of cells, one unit in each: every 3 × 3 window holds 9; a cell outside
    the grid is left out."""
    cells = np.array([(i, j) for i in range(4) for j in range(3)] + [(9, 9)])
    sums = window_sums(cells, np.ones(len(cells)), np.array([0.0, 0.0]), (4, 3))
    np.testing.assert_array_equal(sums, [[9.0], [9.0]])
    one = window_sums(np.array([[2, 1]]), np.array([5.0]), np.array([0.0, 0.0]), (4, 3))
    np.testing.assert_array_equal(one, [[5.0], [5.0]])


def _particles() -> tuple[np.ndarray, np.ndarray]:
    """Half the mass in a 4 m cluster at (31-35, 31-35) m, the rest spread over 50 m."""
    rng = np.random.default_rng(0)
    cluster = rng.uniform(31.0, 35.0, (2000, 2))
    spread = rng.uniform(0.0, 50.0, (2000, 2))
    return np.vstack([cluster, spread]), np.full(4000, 1 / 4000)


def test_densest_window_holds_the_cluster():
    xy, w = _particles()
    x, y = densest_window(xy, w)
    assert x <= 31.0 and x + 15.0 >= 35.0 and y <= 31.0 and y + 15.0 >= 35.0


def test_a_searched_window_is_left_for_the_next_densest():
    """Once FOCUS_SPENT readings were taken in the cluster's cell, no window holding that cell
    is chosen; a kept window is given up once searched."""
    xy, w = _particles()
    first = densest_window(xy, w)
    visits = {(6, 6): FOCUS_SPENT}  # the cell (30-35, 30-35) m
    x, y = densest_window(xy, w, keep=first, visits=visits)
    assert not (x <= 30.0 < x + 15.0 and y <= 30.0 < y + 15.0)
    fewer = {(6, 6): FOCUS_SPENT - 1}
    assert densest_window(xy, w, keep=first, visits=fewer) == first


def test_a_kept_window_stays_while_it_holds_half_the_densest_mass():
    """Keep a window with 40 % of the densest one's mass: given up; with 60 %: kept."""
    a = np.tile([[2.0, 2.0]], (100, 1))
    b = np.tile([[42.0, 42.0]], (100, 1))
    xy = np.vstack([a, b])
    for share_b, kept in ((0.4, False), (0.6, True)):
        w = np.r_[np.full(100, 1 / (1 + share_b)), np.full(100, share_b / (1 + share_b))] / 100
        keep = densest_window(b, np.full(100, 0.01))
        assert (densest_window(xy, w, keep=keep) == keep) is kept
