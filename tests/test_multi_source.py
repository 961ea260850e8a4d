"""Truths with several releases (``truth.extra_sources``, issue 45) and the OSPA distance that
scores an estimated set of sources against the true set."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dcee import DceeInputError
from dcee.models.plume import IsotropicPlume
from dcee.runs import run_episode
from dcee.runs.metrics import ospa
from dcee.scenarios import load_scenario
from dcee.simulation import IsotropicTruth, make_truth, plume_stream
from tests.helpers import run_cli

PAPER1 = load_scenario("paper:1")
SECOND = {"x": 15.0, "y": 35.0, "z": 1.0, "q": 2.5}
TWO = PAPER1.with_overrides(**{"truth.extra_sources": [SECOND]})
POINTS = np.array([[10.0, 35.0, 1.0], [30.0, 12.5, 4.0], [5.0, 20.0, 2.0], [14.0, 35.0, 1.5]])


def test_one_release_is_todays_truth():
    """No extra source: the truth's one source term is the scenario's."""
    truth = make_truth(PAPER1, 0)
    assert type(truth) is IsotropicTruth
    np.testing.assert_array_equal(truth.theta, PAPER1.truth_theta()[None])
    assert PAPER1.truth_thetas().shape == (1, 8)
    np.testing.assert_array_equal(PAPER1.truth_thetas()[0], PAPER1.truth_theta())


def test_isotropic_releases_add_by_hand():
    """Two isotropic releases: the field is the paper's eq. 1 of each source term, summed; the
    second's own row carries its location and rate and shares the wind and dispersion."""
    thetas = TWO.truth_thetas()
    np.testing.assert_array_equal(thetas[1], [15.0, 35.0, 1.0, 2.5, 4.0, 0.0, 1.0, 8.0])
    truth = make_truth(TWO, 0)
    plume = IsotropicPlume()
    expected = (
        plume.concentration(thetas[:1], POINTS)[0] + plume.concentration(thetas[1:], POINTS)[0]
    )
    np.testing.assert_allclose(truth.field(POINTS, 0.0), expected, rtol=1e-12)
    for p, c in zip(POINTS, expected, strict=True):
        assert truth.concentration(p, 0.0) == pytest.approx(c, rel=1e-12)
    # 1 m downwind of the second release its own plume dominates the sum
    assert expected[0] > 100 * plume.concentration(thetas[:1], POINTS[:1])[0, 0]


@pytest.mark.parametrize("model", ["filament", "puffs"])
def test_turbulent_releases_puff_into_one_flow(model):
    """A stochastic truth with two releases is one truth (one wind field, one meander): each
    release puffs on the truth's schedule with its own rate, its puffs start at its location,
    and the field is every puff's sum; one release is today's truth, draw for draw."""
    one = PAPER1.with_overrides(**{"truth.model": model})
    two = TWO.with_overrides(**{"truth.model": model})
    truth = make_truth(two, 3)
    centres, _radii, masses = truth.puffs(300.0)
    origins = truth._state.origins
    rate = truth.spec.puff_rate
    np.testing.assert_array_equal(truth.puff_masses, [5.0 / rate, 2.5 / rate])
    if model == "puffs":  # Gaussian puffs of each release's own mass
        np.testing.assert_array_equal(masses, truth.puff_masses[origins])
    else:  # the filament's puffs also decay with age
        np.testing.assert_allclose(
            masses, truth.puff_masses[origins] * np.exp(-truth._state.ages / 8.0), rtol=1e-12
        )
    for origin, source in enumerate(([37.5, 12.5, 1.0], [15.0, 35.0, 1.0])):
        young = (origins == origin) & (truth._state.ages < 0.5)
        assert young.sum() >= 2  # both release, every step or two
        assert np.all(np.linalg.norm(centres[young] - source, axis=1) < 4.0)
    # just downwind of the second release the gas is (almost) all its own
    near = np.array([[13.5, 35.0, 1.0]])
    alone = make_truth(one, 3)
    times = np.arange(100.0, 400.0, 5.0)
    assert np.mean([truth.field(near, t)[0] for t in times]) > 1e3 * np.mean(
        [alone.field(near, t)[0] for t in times]
    )
    # one release: the same truth as a single-source scenario's, draw for draw
    direct = type(alone)(PAPER1.truth_theta(), alone.spec, plume_stream(3), alone.low, alone.high)
    for t in (0.0, 150.0):
        np.testing.assert_array_equal(direct.field(POINTS, t), alone.field(POINTS, t))


@pytest.mark.parametrize(
    ("extra", "says"),
    [
        ([SECOND] * 4, r"5 releases in all; at most 4"),
        ([{"x": 37.9, "y": 12.5, "z": 1.0, "q": 1.0}], r"releases 0 and 1 are 0\.4 m apart"),
        ([SECOND, {**SECOND, "x": 15.5}], r"releases 1 and 2 are 0\.5 m apart"),
        ([{**SECOND, "x": 60.0}], r"release \(60, 35, 1\) is outside the search volume"),
        ([{**SECOND, "q": 0.0}], r"greater than 0"),
        ([{**SECOND, "z": float("nan")}], r"finite"),
    ],
)
def test_bad_releases_are_refused_in_one_line(extra, says):
    with pytest.raises(DceeInputError, match=says) as exc:
        PAPER1.with_overrides(**{"truth.extra_sources": extra})
    assert "truth.extra_sources" in str(exc.value) and "\n" not in str(exc.value)


def test_a_recording_holds_its_own_releases():
    with pytest.raises(DceeInputError, match=r"truth\.extra_sources: a lbm truth holds its own"):
        PAPER1.with_overrides(**{"truth.model": "lbm", "truth.extra_sources": [SECOND]})


def test_bad_release_on_the_command_line_exits_2_before_any_work(tmp_path, capsys):
    out = tmp_path / "run"
    code, _, err = run_cli(
        [
            "run",
            "--scenario",
            "paper:1",
            "--set",
            "truth.extra_sources=[{x=37.5,y=12.9,z=1.0,q=5.0}]",
            "--out",
            str(out),
            "-q",
        ],
        capsys,
    )
    assert code == 2 and "truth.extra_sources" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_search_over_two_releases_reports_them(tmp_path, capsys):
    """``dcee run`` over two releases: the table gives the OSPA to both, the summary counts
    them, the figure is written (it draws every release)."""
    out = tmp_path / "run"
    code, printed, err = run_cli(
        [
            "run",
            "--scenario",
            "paper:1",
            "--particles",
            "1000",
            "--set",
            "search.budget=60.0",
            "--set",
            "truth.extra_sources=[{x=15.0,y=35.0,z=1.0,q=2.5}]",
            "--out",
            str(out),
        ],
        capsys,
    )
    assert code == 0, err
    assert "OSPA to the 2 releases" in printed
    import json

    summary = json.loads((out / "summary.json").read_text())
    assert summary["true_sources"] == 2 and 0.0 < summary["final_ospa"] <= 3.0
    assert (out / "figure.png").stat().st_size > 0


def test_ospa_by_hand():
    """OSPA (cut-off c, order p) against hand calculations: a matched pair is its distance; a
    missed source costs c over the larger set's size; order 2 averages squares; the best
    assignment, not the order given; empty sets; symmetric."""
    o = np.zeros((1, 3))
    assert ospa(o, [[0.5, 0.0, 0.0]]) == pytest.approx(0.5)
    assert ospa(o, [[0.2, 0.0, 0.0], [10.0, 0.0, 0.0]]) == pytest.approx((0.2 + 3.0) / 2)
    assert ospa([[0.2, 0.0, 0.0], [10.0, 0.0, 0.0]], o) == pytest.approx(1.6)
    assert ospa(o, [[5.0, 0.0, 0.0]]) == pytest.approx(3.0)  # beyond the cut-off
    assert ospa(o, [[0.5, 0.0, 0.0], [9, 9, 9]], order=2) == pytest.approx(
        math.sqrt((0.25 + 9.0) / 2)
    )
    crossed = ospa([[0.0, 0.0], [4.0, 0.0]], [[4.1, 0.0], [0.1, 0.0]])
    assert crossed == pytest.approx(0.1)  # pairing in the given order would give 3.0
    assert ospa(np.empty((0, 3)), np.empty((0, 3))) == 0.0
    assert ospa(np.empty((0, 3)), o) == 3.0
    assert ospa(o, [[1.0, 1.0, 1.0]], cutoff=10.0) == pytest.approx(math.sqrt(3.0))


def test_summary_scores_the_releases():
    """Every summary counts the releases and gives the OSPA of the estimate (one source, at the
    posterior mean) against them: one release, the mean's error (under the cut-off); two, the
    estimate at the first release, about (error + 3 m) / 2."""
    short = {"search.budget": 120.0, "search.particles": 2000}
    one = run_episode(PAPER1.with_overrides(**short), "dcee-cl", 0).summary
    assert one["true_sources"] == 1
    assert one["final_ospa"] == pytest.approx(min(3.0, one["final_mean_error"]), rel=1e-9)
    two = run_episode(TWO.with_overrides(**short), "dcee-cl", 0).summary
    mean = np.array(two["final_mean"])
    first = np.linalg.norm(mean - [37.5, 12.5, 1.0])
    second = np.linalg.norm(mean - [15.0, 35.0, 1.0])
    assert two["true_sources"] == 2
    assert two["final_ospa"] == pytest.approx((min(3.0, min(first, second)) + 3.0) / 2)


def test_campaigns_stored_before_several_releases_keep_their_identity():
    """A scenario stored before ``truth.extra_sources`` existed is today's one-release scenario;
    one with a further release is another scenario (a campaign does not resume across them)."""
    from dcee.runs import scenario_identity

    now = PAPER1.model_dump(mode="json")
    before = {**now, "truth": {k: v for k, v in now["truth"].items() if k != "extra_sources"}}
    assert scenario_identity(before) == scenario_identity(now)
    assert scenario_identity(TWO.model_dump(mode="json")) != scenario_identity(now)
