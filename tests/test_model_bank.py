"""The filter's model evidence and the model bank that estimates the turbulence level online."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dcee import DceeInputError, ParticleFilter
from dcee.estimation.grid import location_grid_posterior
from dcee.estimation.model_bank import ModelBank
from dcee.planning import get as get_planner
from dcee.runs import make_searcher, run_episode, scenario_identity, streams
from dcee.scenarios import load_scenario
from dcee.searcher import Searcher
from tests.test_robust_estimation import _xy_prior

PAPER1 = load_scenario("paper:1")
# the calm and the fluctuation member only (the default also weighs a backflow member, tested
# below with readings where it matters)
FLUCT = PAPER1.with_overrides(**{"estimator.likelihood": "fluctuation", "estimator.learn": {}})


def _lawnmower(n: int = 40) -> np.ndarray:
    xs = np.linspace(5, 45, 8)
    rows = [(x, y, 4.0) for y in (5.0, 15.0, 25.0, 35.0, 45.0) for x in xs]
    return np.array(rows[:n])


def _readings(sensor, positions, seed: int, plume=None, at_distance: bool = False) -> np.ndarray:
    """Readings of ``sensor`` on ``positions``; ``at_distance``: the terms that depend on the
    distance to the source (near-source spread and intermittency) at the true distance (else
    far from it)."""
    from dcee.models.plume import IsotropicPlume

    truth = PAPER1.truth_theta()
    conc = (plume or IsotropicPlume()).concentration(truth, positions)[0]
    rng = np.random.default_rng(seed)
    if not at_distance:
        return sensor.simulate(conc, rng)
    distance = np.linalg.norm(positions - truth[:3], axis=1)
    return sensor.simulate_from(conc, sensor.draw_noise(rng, conc.shape), distance)


def test_log_evidence_matches_the_exact_grid_integral():
    """x, y unknown: the filter's running SMC estimate of log p(z₁…z_k) against the exact
    integral of prior × likelihood on a grid, after 10, 25 and 40 readings."""
    sensor = PAPER1.make_sensor()
    ps = _lawnmower()
    zs = _readings(sensor, ps, seed=3)
    assert (zs > 0).sum() >= 5  # the test needs detections
    pf = ParticleFilter(_xy_prior(), sensor, n_particles=20_000, seed=1)
    for k, (p, z) in enumerate(zip(ps, zs, strict=True), start=1):
        info = pf.update(p, z)
        assert math.isfinite(info.log_evidence)
        if k in (10, 25, 40):
            exact = location_grid_posterior(
                PAPER1.truth_theta(), (0, 0), (50, 50), 0.25, ps[:k], zs[:k], sensor, refine=5
            )
            assert pf.log_evidence == pytest.approx(exact.log_evidence, abs=0.3), k


def test_log_evidence_of_the_first_reading_by_hand():
    """Before any reading the weights are the prior's: the first increment is log of the
    prior-mean likelihood of that reading."""
    sensor = PAPER1.make_sensor()
    pf = ParticleFilter(_xy_prior(), sensor, n_particles=4000, seed=0)
    theta = pf.theta.copy()
    p = np.array([30.0, 12.5, 4.0])
    info = pf.update(p, 0.004)
    by_hand = math.log(np.mean(np.exp(pf.log_likelihood(theta, p, 0.004))))
    assert info.log_evidence == pytest.approx(by_hand, rel=1e-9)
    assert pf.log_evidence == info.log_evidence


def _rings(radii: tuple[float, ...]) -> np.ndarray:
    """(12 · len(radii), 3) m: twelve points on each ring round the true source, at its height."""
    x0, y0, z0 = PAPER1.truth_theta()[:3]
    angles = np.linspace(0.0, 2.0 * np.pi, 12, endpoint=False)
    return np.array([(x0 + r * np.cos(a), y0 + r * np.sin(a), z0) for r in radii for a in angles])


def _bank_on_simulated_readings(
    scenario,
    generating: str,
    seed: int,
    copies: int,
    priors: bool = True,
    path: np.ndarray | None = None,
) -> ModelBank:
    """A bank of the scenario's reading models (3000 particles each, x and y unknown) after the
    lawnmower path (or ``path``, (K, 3) m) flown ``copies`` times with readings drawn from model
    ``generating``; equal prior probabilities unless ``priors``."""
    ps = np.vstack([_lawnmower(40) if path is None else path] * copies)
    zs = _readings(
        scenario.make_estimator_sensor(generating),
        ps,
        seed,
        plume=scenario.make_plume(generating),
        at_distance=path is not None,
    )
    filters = [
        ParticleFilter(
            _xy_prior(),
            scenario.make_estimator_sensor(m),
            scenario.make_plume(m),
            n_particles=3000,
            seed=i,
        )
        for i, m in enumerate(scenario.reading_models)
    ]
    probabilities = scenario.reading_model_priors if priors else None
    bank = ModelBank(filters, scenario.reading_models, probabilities)
    for p, z in zip(ps, zs, strict=True):
        bank.update(p, z)
    return bank


@pytest.mark.parametrize("generating", ["paper", "fluctuation"])
def test_bank_selects_the_model_that_made_the_readings(generating):
    """Readings drawn from one of the two reading models (the same mean plume) on a fixed
    path: the bank gives that model a posterior probability above 0.99."""
    bank = _bank_on_simulated_readings(FLUCT, generating, seed=11, copies=2, priors=False)
    assert bank.selected_name == generating
    assert bank.probabilities[bank.selected] > 0.99
    assert bank.probabilities.sum() == pytest.approx(1.0)
    # everything the searcher reads comes from the selected member
    assert bank.theta is bank.members[bank.selected].theta
    assert bank.sensor == FLUCT.make_estimator_sensor(generating)
    np.testing.assert_array_equal(bank.source_mean(), bank.current.source_mean())


def test_bank_prior_probabilities_and_bad_input():
    pf = [
        ParticleFilter(_xy_prior(), PAPER1.make_sensor(), n_particles=100, seed=s) for s in (0, 1)
    ]
    bank = ModelBank(pf, ("a", "b"), prior_probabilities=(1.0, 3.0))
    np.testing.assert_allclose(bank.probabilities, [0.25, 0.75])
    assert bank.selected_name == "b" and bank.switches == 0
    with pytest.raises(DceeInputError, match="unique"):
        ModelBank(pf, ("a", "a"))
    with pytest.raises(DceeInputError, match="prior_probabilities"):
        ModelBank(pf, ("a", "b"), prior_probabilities=(1.0, 0.0))


def _clouds(centres_x: tuple[float, ...], n: int = 4000) -> list[ParticleFilter]:
    """One filter per centre, its particles by hand: x ~ N(centre, 0.3²), y ~ N(25, 0.3²) m,
    equal weights (no reading)."""
    rng = np.random.default_rng(3)
    filters = []
    for i, cx in enumerate(centres_x):
        pf = ParticleFilter(_xy_prior(), PAPER1.make_sensor(), n_particles=n, seed=i)
        pf.theta[:, 0] = rng.normal(cx, 0.3, n)
        pf.theta[:, 1] = rng.normal(25.0, 0.3, n)
        filters.append(pf)
    return filters


def test_the_region_is_the_models_mixture_weighted_by_their_probabilities():
    """Two members whose beliefs sit 6 m apart: with equal probabilities the region of their
    mixture holds the second member's centre (the selected, first member's does not); at 99 : 1
    the second member holds 1 % of the mass, less than the 5 % outside a 95 % region, so its
    centre falls outside; one member: its own region, truth by truth."""
    a, b = _clouds((10.0, 16.0))
    at_b = np.array([16.0, 25.0, 1.0])
    even = ModelBank([a, b], ("a", "b"))
    assert even.selected_name == "a" and not a.in_credible_region(at_b)
    assert even.in_credible_region(at_b) and even.in_credible_region(np.array([10, 25, 1.0]))
    assert not even.in_credible_region(np.array([10.0, 28.0, 1.0]))  # 10 sd across
    assert not ModelBank([a, b], ("a", "b"), (99.0, 1.0)).in_credible_region(at_b)
    assert ModelBank([a, b], ("a", "b"), (1.0, 99.0)).in_credible_region(at_b)
    alone = ModelBank([a], ("a",))
    for dx in np.linspace(-1.5, 1.5, 13):
        truth = np.array([10.0 + dx, 25.0 + dx / 2, 1.0])
        assert alone.in_credible_region(truth) == a.in_credible_region(truth)


def test_fluctuation_likelihood_runs_the_calm_model_unless_told_not_to():
    assert PAPER1.reading_models == ("paper",)
    assert FLUCT.reading_models == ("fluctuation", "paper")
    assert FLUCT.reading_model_priors == (0.9, 0.1)
    assert FLUCT.with_overrides(**{"estimator.calm_prior": 0.2}).reading_model_priors == (
        0.8,
        0.2,
    )
    assert FLUCT.with_overrides(**{"estimator.calm_prior": 0}).reading_models == ("fluctuation",)
    # the calm member is the paper's model with the fluctuation likelihood's outlier weight
    calm = FLUCT.make_estimator_sensor("paper")
    assert calm.family == "gaussian" and calm.pd == PAPER1.make_sensor().pd
    assert calm.outlier == FLUCT.outlier == 0.01
    assert FLUCT.make_plume("paper").meander == 0 and FLUCT.make_plume().meander == 0.15
    with pytest.raises(DceeInputError, match="model"):
        PAPER1.make_estimator_sensor("fluctuation")
    _, filter_rng, planner_rng, _ = streams(0)
    searcher = make_searcher(FLUCT, None, filter_rng, planner_rng)
    assert isinstance(searcher.filter, ModelBank)
    _, filter_rng, planner_rng, _ = streams(0)
    assert isinstance(make_searcher(PAPER1, None, filter_rng, planner_rng).filter, ParticleFilter)


def test_campaigns_stored_before_the_calm_model_resume_only_without_it():
    """A fluctuation campaign stored before ``calm_prior`` existed ran without the calm model:
    its identity equals calm_prior = 0, not the new default; under the paper's likelihood the
    setting decides nothing."""
    stored = FLUCT.model_dump(mode="json")
    del stored["estimator"]["calm_prior"]
    off = FLUCT.with_overrides(**{"estimator.calm_prior": 0}).model_dump(mode="json")
    assert scenario_identity(stored) == scenario_identity(off)
    assert scenario_identity(stored) != scenario_identity(FLUCT.model_dump(mode="json"))
    paper_stored = PAPER1.model_dump(mode="json")
    del paper_stored["estimator"]["calm_prior"]
    assert scenario_identity(paper_stored) == scenario_identity(PAPER1.model_dump(mode="json"))


def test_campaigns_stored_before_the_spread_option_keep_their_identity():
    """``log_sd_near`` / ``log_sd_length`` at 0 are what ran before they existed; a non-zero
    spread is another campaign."""
    stored = FLUCT.model_dump(mode="json")
    del stored["estimator"]["log_sd_near"], stored["estimator"]["log_sd_length"]
    assert scenario_identity(stored) == scenario_identity(FLUCT.model_dump(mode="json"))
    spread = FLUCT.with_overrides(
        **{"estimator.log_sd_near": 2.0, "estimator.log_sd_length": 3.0}
    ).model_dump(mode="json")
    assert scenario_identity(spread) != scenario_identity(stored)
    sensor = FLUCT.with_overrides(
        **{"estimator.log_sd_near": 2.0, "estimator.log_sd_length": 3.0}
    ).make_estimator_sensor()
    assert (sensor.log_sd_near, sensor.log_sd_length) == (2.0, 3.0)


def test_search_with_the_bank_records_the_model_and_is_reproducible():
    sc = FLUCT.with_overrides(**{"search.particles": 1500, "search.budget": 40.0})
    a = run_episode(sc, "infotaxis", seed=4)
    b = run_episode(sc, "infotaxis", seed=4)
    assert [r["x"] for r in a.records] == [r["x"] for r in b.records]
    assert a.summary["model"] in ("fluctuation", "paper")
    assert 0.5 <= a.summary["model_probability"] <= 1.0
    assert a.summary["reading_models"] == "fluctuation+paper"
    assert all("model" in r and "log_evidence" in r for r in a.records)


def test_a_bank_searcher_checkpoint_resumes_identically(tmp_path):
    _, filter_rng, planner_rng, _ = streams(2)
    sc = FLUCT.with_overrides(**{"search.particles": 1000})
    searcher = make_searcher(sc, get_planner("infotaxis", n_hypotheses=10), filter_rng, planner_rng)
    pos = np.array(sc.agent.start, dtype=float)
    rng = np.random.default_rng(0)
    for k in range(6):
        searcher.tell(pos, float(rng.choice([0.0, 0.002])), float(k))
        pos = searcher.ask()
    searcher.save(tmp_path / "c.pkl")
    restored = Searcher.load(tmp_path / "c.pkl")
    for k in range(6, 10):
        z = float(rng.choice([0.0, 0.003]))
        searcher.tell(pos, z, float(k))
        restored.tell(pos, z, float(k))
        a, b = searcher.ask(), restored.ask()
        np.testing.assert_array_equal(a, b)
        pos = a
    assert restored.filter.selected_name == searcher.filter.selected_name


def test_the_calm_model_changes_nothing_while_it_is_not_selected():
    """The preferred member draws from the same generator as a lone filter: with a calm prior
    too small ever to be selected, the search is the one without the calm model, step by step."""
    sc = FLUCT.with_overrides(**{"search.particles": 1500, "search.budget": 40.0})
    alone = run_episode(sc.with_overrides(**{"estimator.calm_prior": 0}), "infotaxis", seed=3)
    bank = run_episode(sc.with_overrides(**{"estimator.calm_prior": 1e-300}), "infotaxis", seed=3)
    assert all(r["model"] == "fluctuation" for r in bank.records)
    assert [r["x"] for r in bank.records] == [r["x"] for r in alone.records]
    assert [r["rmse"] for r in bank.records] == [r["rmse"] for r in alone.records]


def test_the_bank_survives_absurd_readings():
    """Readings over eight decades up to the physical maximum, and a spike: both members stay
    alive, the model probabilities stay finite and sum to 1."""
    rng = np.random.default_rng(7)
    filters = [
        ParticleFilter(
            _xy_prior(), FLUCT.make_estimator_sensor(m), FLUCT.make_plume(m), 2000, seed=i
        )
        for i, m in enumerate(FLUCT.reading_models)
    ]
    bank = ModelBank(filters, FLUCT.reading_models, FLUCT.reading_model_priors)
    for _ in range(60):
        pos = np.array([rng.uniform(0, 50), rng.uniform(0, 50), 4.0])
        z = 0.0 if rng.random() < 0.5 else float(10 ** rng.uniform(-3.3, 4))
        info = bank.update(pos, z)
        assert math.isfinite(info.log_evidence) and not info.rejected
        p = bank.probabilities
        assert np.all(np.isfinite(p)) and p.sum() == pytest.approx(1.0)
    for f in bank.members:
        assert np.all(np.isfinite(f.weights)) and f.ess >= 1.0


def test_report_tables_which_model_the_searches_ended_with():
    import pandas as pd

    from dcee.analysis.report import model_selection_markdown

    runs = pd.DataFrame(
        {
            "strategy": ["a", "a", "a", "b"],
            "model": ["paper", "paper", "fluctuation", "paper"],
            "model_probability": [1.0, 0.9, 0.8, 1.0],
            "model_switches": [1, 3, 2, 0],
        }
    )
    md = model_selection_markdown(runs)
    assert "| a | paper | 2/3 (67 [21, 94]%) | 0.950 | 2.0 |" in md
    assert "| a | fluctuation | 1/3" in md and "| b | paper | 1/1" in md
    assert model_selection_markdown(runs.drop(columns="model")) is None


LEARNED = FLUCT.with_overrides(
    **{"estimator.learn": {"meander": [0.15, 0.5], "log_sd": [1.3, 2.0]}, "estimator.calm_prior": 0}
)


@pytest.mark.parametrize("generating", ["fluctuation[meander=0.5,log_sd=2]", "fluctuation"])
def test_learned_bank_finds_the_nuisance_values_that_made_the_readings(generating):
    """estimator.learn: readings drawn from the fluctuation model at one (meander, log_sd) of
    the grid on a fixed path; the bank's posterior probability of that member is the largest
    and above the other three together (from 1/4 each: statistics of simulated data, the same
    mean plume up to the meander)."""
    assert LEARNED.reading_models == (
        "fluctuation",
        "fluctuation[meander=0.15,log_sd=2]",
        "fluctuation[meander=0.5,log_sd=1.3]",
        "fluctuation[meander=0.5,log_sd=2]",
    )
    assert LEARNED.reading_model_priors == pytest.approx((0.25,) * 4)
    bank = _bank_on_simulated_readings(LEARNED, generating, seed=5, copies=3)
    assert bank.selected_name == generating
    assert bank.probabilities[bank.selected] > 0.5


def test_learn_is_checked_before_any_work():
    with pytest.raises(DceeInputError, match=r"estimator\.learn.*fluctuation"):
        PAPER1.with_overrides(**{"estimator.learn": {"meander": [0.0, 0.3]}})
    with pytest.raises(DceeInputError, match=r"estimator\.learn\.meander.*fixed value 0\.15"):
        FLUCT.with_overrides(**{"estimator.learn": {"meander": [0.3, 0.5]}})
    with pytest.raises(DceeInputError, match=r"estimator\.learn\.log_sd.*distinct"):
        FLUCT.with_overrides(**{"estimator.learn": {"log_sd": [1.3, 9.0]}})
    with pytest.raises(DceeInputError, match=r"estimator\.learn: 16 combinations"):
        FLUCT.with_overrides(
            **{"estimator.learn": {"log_sd": [1.3, 1, 2, 3], "meander": [0.15, 0.2, 0.3, 0.4]}}
        )


def test_learn_prior_weighs_the_members_by_hand_computed_products():
    """estimator.learn_prior: each value's probability (normalised), members' priors the
    products, the calm member's share apart; a setting it does not name weighs equally."""
    prior = LEARNED.with_overrides(**{"estimator.learn_prior": {"log_sd": [3.0, 1.0]}})
    # members: (0.15, 1.3), (0.15, 2), (0.5, 1.3), (0.5, 2); meander equal, log_sd 3/4 : 1/4
    assert prior.reading_model_priors == pytest.approx((0.375, 0.125, 0.375, 0.125))
    both = LEARNED.with_overrides(
        **{
            "estimator.learn_prior": {"meander": [0.9, 0.1], "log_sd": [0.5, 0.5]},
            "estimator.calm_prior": 0.2,
        }
    )
    assert both.reading_models[-1] == "paper"
    assert both.reading_model_priors == pytest.approx(
        (0.8 * 0.45, 0.8 * 0.45, 0.8 * 0.05, 0.8 * 0.05, 0.2)
    )
    # the default grid (backflow x source_radius) with its default prior: odds 9 : 1 against
    # the disc, backflow equal, calm 0.1
    default = PAPER1.with_overrides(**{"estimator.likelihood": "fluctuation"})
    assert default.reading_models == (
        "fluctuation",
        "fluctuation[backflow=0,source_radius=1]",
        "fluctuation[backflow=0.05,source_radius=0]",
        "fluctuation[backflow=0.05,source_radius=1]",
        "paper",
    )
    assert default.learn_prior == {"source_radius": [0.9, 0.1]}
    assert default.reading_model_priors == pytest.approx(
        (0.9 * 0.45, 0.9 * 0.05, 0.9 * 0.45, 0.9 * 0.05, 0.1)
    )
    # the default grid weighed without restating it: a prior given replaces the default one
    # (source_radius then equal)
    weighed = default.with_overrides(**{"estimator.learn_prior": {"backflow": [1.0, 4.0]}})
    assert weighed.reading_model_priors == pytest.approx(
        (0.9 * 0.1, 0.9 * 0.1, 0.9 * 0.4, 0.9 * 0.4, 0.1)
    )
    # a grid given: no default prior (every value equally likely)
    given = default.with_overrides(**{"estimator.learn": {"source_radius": [0.0, 1.0]}})
    assert given.learn_prior == {}
    assert given.reading_model_priors == pytest.approx((0.45, 0.45, 0.1))


def test_a_setting_fixed_by_hand_leaves_the_default_grid():
    """A setting of the default grid fixed by hand is not learned (and its prior goes with
    it); the other setting still is, at its default prior; fixed at the plain model's value it
    is still learned."""
    fluct = PAPER1.with_overrides(**{"estimator.likelihood": "fluctuation"})
    disc = fluct.with_overrides(**{"estimator.source_radius": 0.5})
    assert disc.learn == {"backflow": [0.0, 0.05]} and disc.learn_prior == {}
    assert disc.reading_model_priors == pytest.approx((0.45, 0.45, 0.1))
    upwind = fluct.with_overrides(**{"estimator.backflow": 0.05})
    assert upwind.learn == {"source_radius": [0.0, 1.0]}
    assert upwind.learn_prior == {"source_radius": [0.9, 0.1]}
    assert upwind.reading_model_priors == pytest.approx((0.9 * 0.9, 0.9 * 0.1, 0.1))
    both = fluct.with_overrides(**{"estimator.backflow": 0.05, "estimator.source_radius": 1.0})
    assert both.learn == {} and both.reading_models == ("fluctuation", "paper")
    plain = fluct.with_overrides(**{"estimator.source_radius": 0.0})
    assert plain.learn == fluct.learn


def test_learn_prior_is_checked_before_any_work():
    for prior, says in (
        ({"decay": [1.0, 1.0]}, r"learn_prior\.decay: decay is not learned"),
        ({"log_sd": [1.0]}, r"learn_prior\.log_sd: one positive probability per value"),
        ({"log_sd": [1.0, 0.0]}, r"learn_prior\.log_sd: one positive probability per value"),
    ):
        with pytest.raises(DceeInputError, match=says):
            LEARNED.with_overrides(**{"estimator.learn_prior": prior})
    with pytest.raises(DceeInputError, match=r"learn_prior\.backflow: backflow is not learned"):
        PAPER1.with_overrides(**{"estimator.learn_prior": {"backflow": [1.0, 1.0]}})


@pytest.mark.parametrize("generating", ["fluctuation[decay=0.5]", "fluctuation"])
def test_learned_decay_tells_a_planar_plume_from_a_point_source(generating):
    """estimator.learn = {decay = [1, 0.5]}: readings from the plume model with the planar
    fall (1/√r) or the point source's (1/r); the bank finds which (simulated data)."""
    learned = FLUCT.with_overrides(
        **{"estimator.learn": {"decay": [1.0, 0.5]}, "estimator.calm_prior": 0}
    )
    assert learned.reading_models == ("fluctuation", "fluctuation[decay=0.5]")
    assert learned.make_plume("fluctuation[decay=0.5]").decay == 0.5
    bank = _bank_on_simulated_readings(learned, generating, seed=8, copies=3)
    assert bank.selected_name == generating
    assert bank.probabilities[bank.selected] > 0.9


@pytest.mark.parametrize("generating", ["fluctuation[log_sd_near=4]", "fluctuation"])
def test_learned_near_source_spread_is_found_from_the_readings(generating):
    """estimator.learn = {log_sd_near = [0, 4]} (log_sd_length 5 m): readings drawn with the
    spread that grows towards the source, or with the same spread everywhere; the bank finds
    which (simulated data), and the member's sensor carries the learned value."""
    learned = FLUCT.with_overrides(
        **{
            "estimator.log_sd_length": 5.0,
            "estimator.learn": {"log_sd_near": [0.0, 4.0]},
            "estimator.calm_prior": 0,
        }
    )
    assert learned.reading_models == ("fluctuation", "fluctuation[log_sd_near=4]")
    near = learned.make_estimator_sensor("fluctuation[log_sd_near=4]")
    assert (near.log_sd_near, near.log_sd_length) == (4.0, 5.0)
    assert learned.make_estimator_sensor("fluctuation").log_sd_near == 0.0
    # rings round the source at its height, 1.5 to 6 m out, where the two spreads differ
    ring = _rings((1.5, 3.0, 6.0))
    bank = _bank_on_simulated_readings(learned, generating, seed=8, copies=3, path=ring)
    assert bank.selected_name == generating
    assert bank.probabilities[bank.selected] > 0.9


def test_learned_near_source_spread_needs_a_length():
    with pytest.raises(DceeInputError, match=r"estimator\.learn\.log_sd_near.*log_sd_length > 0"):
        FLUCT.with_overrides(**{"estimator.learn": {"log_sd_near": [0.0, 3.0]}})


@pytest.mark.parametrize("generating", ["fluctuation[backflow=0.1]", "fluctuation"])
def test_learned_backflow_is_found_from_the_readings(generating):
    """estimator.learn = {backflow = [0, 0.1]}: readings drawn from the plume model with gas
    upwind of the release (a tenth of the time the wind blows back) or without; on rings round
    the source the bank finds which (simulated data), and the member's plume carries it."""
    learned = FLUCT.with_overrides(
        **{"estimator.learn": {"backflow": [0.0, 0.1]}, "estimator.calm_prior": 0}
    )
    assert learned.reading_models == ("fluctuation", "fluctuation[backflow=0.1]")
    assert learned.make_plume("fluctuation[backflow=0.1]").backflow == 0.1
    assert learned.make_plume("fluctuation").backflow == 0.0
    ring = _rings((1.5, 3.0, 6.0))
    bank = _bank_on_simulated_readings(learned, generating, seed=8, copies=3, path=ring)
    assert bank.selected_name == generating
    assert bank.probabilities[bank.selected] > 0.9


@pytest.mark.parametrize("generating", ["fluctuation[source_radius=1.5]", "fluctuation"])
def test_learned_source_radius_is_found_from_the_readings(generating):
    """estimator.learn = {source_radius = [0, 1.5]}: readings drawn from a release spread over
    a disc of 1.5 m or from a point; on rings round the source the bank finds which (simulated
    data), and the member's plume carries the radius. A disc can mimic a point release more
    easily than the reverse: after 216 readings the point member holds 0.84 (measured), the
    disc member above 0.9."""
    learned = FLUCT.with_overrides(
        **{"estimator.learn": {"source_radius": [0.0, 1.5]}, "estimator.calm_prior": 0}
    )
    assert learned.reading_models == ("fluctuation", "fluctuation[source_radius=1.5]")
    assert learned.make_plume("fluctuation[source_radius=1.5]").radius == 1.5
    ring = _rings((1.0, 2.0, 4.0))
    bank = _bank_on_simulated_readings(learned, generating, seed=8, copies=6, path=ring)
    assert bank.selected_name == generating
    assert bank.probabilities[bank.selected] > (0.75 if generating == "fluctuation" else 0.9)
