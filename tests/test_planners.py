import math

import numpy as np
import pytest

from dcee import DceeInputError, GridAgent, IsotropicPlume, SearchVolume, Sensor, planners
from dcee.planning import Belief, PredictionContext
from dcee.planning.predicted_reference import predicted_posterior_stats_reference
from tests.helpers import compiled_predicted_stats, stratified_readings_reference, theta_at

AGENT = GridAgent(SearchVolume((0.0, 0.0, 0.0), (40.0, 40.0, 0.0)), step=2.0)
START = np.array([10.0, 10.0, 0.0])


def _belief(points, weights=None, **kw) -> Belief:
    theta = theta_at([(*p, 0.0) for p in points], **kw)
    w = np.full(len(points), 1 / len(points)) if weights is None else np.asarray(weights, float)
    return Belief(theta, w / w.sum(), Sensor.paper_exact(), IsotropicPlume())


def _two_point_belief(n_each=500):
    # Hypothesis A just east of the agent (reachable by a reading), B far north. No wind,
    # a weak release: only a sensor within ~1.5 m of A detects it.
    pts = [(13.0, 10.0)] * n_each + [(10.0, 30.0)] * n_each
    return _belief(pts, q=0.02, u=0.0)


def test_registry_lists_all_strategies_and_rejects_unknown():
    assert set(planners.names()) >= {"dcee", "dcee-ms", "mpc", "entrotaxis", "infotaxis"}
    assert planners.get("dcee").name == "dcee"
    with pytest.raises(DceeInputError, match="strategy"):
        planners.get("nope")


def test_new_planner_registers_without_editing_a_dispatcher():
    @planners.register("test-stay-west")
    class West(planners.Planner):
        def costs(self, belief, position, candidates, agent, rng):
            return candidates[:, 0], {}

    try:
        d = planners.get("test-stay-west").decide(
            _belief([(20, 20)]), START, AGENT, np.random.default_rng(0)
        )
        assert d.heading == 4  # 180°: west
        assert "test-stay-west" in planners.names()
    finally:
        planners.unregister("test-stay-west")  # the registry is process-wide
    assert "test-stay-west" not in planners.names()


class PluginPlanner(planners.Planner):
    """A planner as another package would ship it (west, always)."""

    def costs(self, belief, position, candidates, agent, rng):
        return candidates[:, 0], {}


def test_planners_from_other_packages_come_through_entry_points(monkeypatch):
    """A package declaring ``[project.entry-points."dcee.planners"]`` appears in the registry
    (and so in ``dcee strategies`` and every --strategy option) without editing dcee."""
    from importlib.metadata import EntryPoint

    import dcee.planning.base as base

    ep = EntryPoint("test-plugin-mpc", "tests.test_planners:PluginPlanner", base.ENTRY_POINT_GROUP)
    monkeypatch.setattr(base, "_entry_points_loaded", False)
    monkeypatch.setattr(
        "importlib.metadata.entry_points",
        lambda group=None: [ep] if group == base.ENTRY_POINT_GROUP else [],
    )
    try:
        assert "test-plugin-mpc" in planners.names()
        d = planners.get("test-plugin-mpc").decide(
            _belief([(20, 20)]), START, AGENT, np.random.default_rng(0)
        )
        assert d.heading == 4
    finally:
        planners.unregister("test-plugin-mpc")


def test_mpc_moves_towards_the_posterior_mean_with_hand_computed_costs():
    belief = _two_point_belief()
    d = planners.get("mpc").decide(belief, START, AGENT, np.random.default_rng(0))
    mean = np.array([11.5, 20.0, 0.0])
    expected = np.sum((d.candidates - mean) ** 2, axis=1)
    np.testing.assert_allclose(d.costs, expected, rtol=1e-12)
    assert d.heading == 2  # north: (10, 12) is closest to (11.5, 20)


@pytest.mark.parametrize("name", ["dcee", "dcee-ms", "mpc"])
def test_concentrated_belief_leads_straight_to_the_source(name):
    belief = _belief([(20.0, 20.0)] * 50, q=5.0, u=4.0, phi=math.radians(225))
    d = planners.get(name).decide(belief, START, AGENT, np.random.default_rng(0))
    assert d.heading == 1  # 45°: north-east, straight at (20, 20)


def test_infotaxis_is_indifferent_when_nothing_is_left_to_learn():
    # Every particle agrees: no reading can change the belief, so every expected KL is 0.
    # (Entrotaxis is not indifferent here: sensor noise alone has entropy, its known weakness.)
    belief = _belief([(30.0, 30.0)] * 50, q=5.0, u=4.0, phi=math.radians(45))
    d = planners.get("infotaxis").decide(belief, START, AGENT, np.random.default_rng(0))
    np.testing.assert_allclose(d.costs, 0.0, atol=1e-9)


def test_dcee_cost_equals_its_definition_for_a_point_belief():
    belief = _belief([(20.0, 20.0)] * 10, q=5.0, u=4.0, phi=math.radians(225))
    d = planners.get("dcee").decide(belief, START, AGENT, np.random.default_rng(0))
    # All particles at one location: s̄' = s, tr P' = 0, so J(u) = ‖p − s‖² exactly.
    expected = np.sum((d.candidates - np.array([20.0, 20.0, 0.0])) ** 2, axis=1)
    np.testing.assert_allclose(d.costs, expected, rtol=1e-9)


def test_dcee_expected_cost_is_mpc_cost_plus_trace_by_total_variance():
    # With hypotheses drawn from the predictive distribution, E[‖p − s̄'‖² + tr P'] equals
    # ‖p − s̄‖² + tr P (law of total variance). Check the Monte Carlo machinery reproduces it.
    rng = np.random.default_rng(2)
    pts = np.column_stack([rng.normal(14, 2, 400), rng.normal(12, 2, 400)])
    belief = _belief(pts, q=0.5, u=1.0, phi=math.radians(30))
    dcee = planners.get("dcee", n_hypotheses=20_000)
    d = dcee.decide(belief, START, AGENT, np.random.default_rng(1))
    s = belief.source
    mean = belief.source_mean()
    trace = belief.weights @ np.sum((s - mean) ** 2, axis=1)
    expected = np.sum((d.candidates - mean) ** 2, axis=1) + trace
    np.testing.assert_allclose(d.costs, expected, rtol=0.02)


def test_entrotaxis_and_infotaxis_sample_where_the_reading_discriminates():
    belief = _two_point_belief()
    for name in ("entrotaxis", "infotaxis"):
        d = planners.get(name).decide(belief, START, AGENT, np.random.default_rng(0))
        assert d.heading == 0, name  # east: 1 m from hypothesis A
    # The east point (1 m from A) resolves the 50/50 belief most often; the diagonals (2.1 m
    # from A) sometimes; the other moves almost never.
    d = planners.get("infotaxis", n_hypotheses=4000).decide(
        belief, START, AGENT, np.random.default_rng(0)
    )
    gain = -d.costs
    assert gain[0] > 0.2 and gain[1:].max() < 0.5 * gain[0]
    assert np.all(gain[2:7] < 0.05 * gain[0])


def test_location_infotaxis_values_only_what_a_reading_tells_about_the_location():
    # Two release rates at one location: a reading discriminates them (joint KL > 0) but the
    # location is certain, so the location information is 0 for every move.
    pts = [(13.0, 10.0, 0.0)] * 400
    theta = np.vstack([theta_at(pts[:200], q=0.02, u=0.0), theta_at(pts[200:], q=2.0, u=0.0)])
    rates = Belief(theta, np.full(400, 1 / 400), Sensor.paper_exact(), IsotropicPlume())
    rng = np.random.default_rng
    joint = planners.get("infotaxis").decide(rates, START, AGENT, rng(0))
    location = planners.get("infotaxis:about=location").decide(rates, START, AGENT, rng(0))
    assert -joint.costs.min() > 0.05
    np.testing.assert_allclose(location.costs, 0.0, atol=1e-12)
    # Where the parameters differ only by location, the two are the same information.
    belief = _two_point_belief()
    joint = planners.get("infotaxis").decide(belief, START, AGENT, rng(0))
    location = planners.get("infotaxis:about=location:cell=0.5").decide(
        belief, START, AGENT, rng(0)
    )
    np.testing.assert_allclose(location.costs, joint.costs, rtol=1e-9, atol=1e-12)
    assert location.heading == 0


def test_a_belief_of_the_wrong_shape_is_refused():
    theta = theta_at([(1.0, 2.0, 0.0)] * 3)
    with pytest.raises(DceeInputError, match="theta"):
        Belief(theta[:, :7], np.full(3, 1 / 3), Sensor.paper_exact(), IsotropicPlume())
    with pytest.raises(DceeInputError, match="weights"):
        Belief(theta, np.full(4, 1 / 4), Sensor.paper_exact(), IsotropicPlume())


def test_multistage_plans_through_an_intermediate_point():
    # Source 4 m north: horizon 2 ends exactly on it by going north twice.
    belief = _belief([(10.0, 14.0)] * 20, q=5.0, u=4.0, phi=math.radians(270))
    planner = planners.get("dcee-ms", horizon=2, beam_width=3)
    d = planner.decide(belief, START, AGENT, np.random.default_rng(0))
    assert d.heading == 2
    assert d.info["sequences_evaluated"] == 8 + 3 * 8
    assert np.isfinite(d.costs).sum() <= 3


def test_candidates_are_compared_on_common_random_numbers():
    belief = _two_point_belief(50)
    ctx = PredictionContext(belief, 40, 1, np.random.default_rng(0))
    twice = np.array([[[12.0, 10.0, 0.0]], [[12.0, 10.0, 0.0]]])
    st = ctx.stats(twice)
    np.testing.assert_array_equal(st.readings[0], st.readings[1])
    np.testing.assert_array_equal(st.mean[0], st.mean[1])


@pytest.mark.parametrize("false_alarm", [0.0, 0.05])
def test_compiled_predicted_stats_match_reference(false_alarm):
    rng = np.random.default_rng(9)
    n = 3000
    pts = np.column_stack([rng.uniform(0, 20, n), rng.uniform(0, 20, n)])
    belief = _belief(pts, weights=rng.random(n), q=2.0, u=2.0, phi=0.5)
    sensor = Sensor.paper_exact(false_alarm=false_alarm)
    positions = np.array([[5.0, 5.0, 0.0], [8.0, 12.0, 0.0], [15.0, 3.0, 0.0]])
    conc = np.ascontiguousarray(belief.plume.concentration(belief.theta, positions).T)
    task_pos = np.array([[0, 1], [1, 2], [2, 2], [0, 0]])
    task_z = np.array([[0.0, 0.0], [3e-3, 0.0], [1e-2, 2e-3], [6e-4, 0.05]])
    out = compiled_predicted_stats(conc, belief.source, belief.weights, task_pos, task_z, sensor)
    ref = predicted_posterior_stats_reference(
        conc, belief.source, belief.weights, task_pos, task_z, sensor
    )
    for fast, slow in zip(out, ref, strict=True):
        np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-12)


def test_bad_planner_options_are_user_errors():
    with pytest.raises(DceeInputError, match="hypotheses"):
        planners.get("dcee", n_hypotheses=0)
    with pytest.raises(DceeInputError, match="horizon"):
        planners.get("dcee-ms", horizon=7)
    with pytest.raises(DceeInputError, match="mpc: no option 'n_hypotheses'"):
        planners.get("mpc", n_hypotheses=3)


def _spread_belief(seed=2, n=400):
    rng = np.random.default_rng(seed)
    pts = np.column_stack([rng.normal(14, 2, n), rng.normal(12, 2, n)])
    return _belief(pts, q=0.5, u=1.0, phi=math.radians(30))


def test_stratified_and_sampled_expectations_agree_for_many_hypotheses():
    # Both estimate the same E_ẑ[·]; with many hypotheses they agree for every loss.
    belief = _spread_belief()
    for name in ("dcee", "infotaxis", "entrotaxis"):
        costs = {}
        for expectation in ("sampled", "stratified"):
            planner = planners.get(name, n_hypotheses=8000, expectation=expectation)
            costs[expectation] = planner.decide(
                belief, START, AGENT, np.random.default_rng(5)
            ).costs
        scale = np.abs(costs["sampled"]).max()
        np.testing.assert_allclose(costs["stratified"], costs["sampled"], atol=0.03 * scale)


def test_stratified_dcee_reproduces_the_total_variance_identity_tightly():
    # E[s̄'] = s̄ and E[‖p − s̄'‖² + tr P'] = ‖p − s̄‖² + tr P hold for the stratified estimate
    # too, and its error at J = 2000 is far below the sampled estimate's at 20,000.
    belief = _spread_belief()
    mean = belief.source_mean()
    trace = belief.weights @ np.sum((belief.source - mean) ** 2, axis=1)
    ctx = PredictionContext(belief, 2000, 1, np.random.default_rng(1), "stratified")
    cands = AGENT.candidates(START)[0]
    stats = ctx.stats(cands[:, None, :])
    np.testing.assert_allclose(stats.probability.sum(axis=1), 1.0, rtol=1e-12)
    for s in range(len(cands)):
        np.testing.assert_allclose(stats.probability[s] @ stats.mean[s], mean, atol=0.02)
    d = planners.get("dcee", n_hypotheses=2000, expectation="stratified").decide(
        belief, START, AGENT, np.random.default_rng(1)
    )
    expected = np.sum((d.candidates - mean) ** 2, axis=1) + trace
    np.testing.assert_allclose(d.costs, expected, rtol=0.005)


def test_stratified_expectation_has_lower_variance_when_detections_are_rare():
    # A stall: a weak source believed 6 m north, plume blowing south; P(detection) is 0–10 % per
    # move. Over independent decisions the stratified infotaxis cost varies far less (measured:
    # 16× less) than the sampled one.
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.normal(10, 1.5, 600), rng.normal(16, 1.5, 600)])
    belief = _belief(pts, q=0.3, u=1.0, phi=math.radians(270))
    spread = {}
    for expectation in ("sampled", "stratified"):
        planner = planners.get("infotaxis", n_hypotheses=40, expectation=expectation)
        costs = np.array(
            [
                planner.decide(belief, START, AGENT, np.random.default_rng(k)).costs
                for k in range(30)
            ]
        )
        spread[expectation] = costs.std(axis=0).mean()
    assert spread["stratified"] < 0.2 * spread["sampled"]


def test_closed_loop_dcee_limits():
    belief = _spread_belief()
    rng = np.random.default_rng
    # reach 0 and the location variance as the uncertainty: the open-loop DCEE loss,
    # hypothesis by hypothesis
    cl = planners.get("dcee-cl:info_share=0:spread_reach=0", reach=0.0, n_hypotheses=200).decide(
        belief, START, AGENT, rng(3)
    )
    op = planners.get("dcee", expectation="stratified", n_hypotheses=200).decide(
        belief, START, AGENT, rng(3)
    )
    np.testing.assert_allclose(cl.costs, op.costs, rtol=1e-12)
    # reach beyond every predicted mean: only the expected remaining variance E[tr P'] is left,
    # so the choice is the move whose reading discriminates (east, 1 m from hypothesis A),
    # where open-loop DCEE and MPC head north towards the mean
    two = _two_point_belief()
    far = planners.get("dcee-cl", reach=100.0).decide(two, START, AGENT, rng(0))
    assert far.heading == 0
    assert (
        planners.get("dcee", expectation="stratified").decide(two, START, AGENT, rng(0)).heading
        == 2
    )
    # far from the belief (beyond the reach) it moves like MPC
    remote = _belief([(30.0, 30.0)] * 50, q=5.0, u=4.0, phi=math.radians(45))
    assert planners.get("dcee-cl").decide(remote, START, AGENT, rng(0)).heading == 1


def test_planner_specs_set_options_and_reject_bad_ones():
    p = planners.get("dcee-cl:reach=4:hypotheses=25:expectation=sampled", n_hypotheses=40)
    assert (p.reach, p.n_hypotheses, p.expectation) == (4.0, 25, "sampled")
    assert planners.get("infotaxis:horizon=2").horizon == 2
    assert planners.planner_class("dcee-ms:beam_width=2").name == "dcee-ms"
    for bad, field in [
        ("dcee-cl:reach", "strategy"),
        ("dcee-cl:reach=-1", "reach"),
        ("dcee:expectation=exact", "expectation"),
        ("dcee:colour=red", "no option 'colour'"),
        ("nope:reach=3", "strategy"),
        ("infotaxis:horizon=4", "horizon"),
        ("dcee:hypotheses=abc", "hypotheses"),
        ("dcee:hypotheses=2.5", "hypotheses"),
        ("dcee-cl-tree:branch_hypotheses=0", "branch_hypotheses"),
        ("dcee-ms:beam_width=true", "beam_width"),
        ("infotaxis:about=wind", "about"),
        ("infotaxis:about=location:cell=0", "cell"),
        ("infotaxis:cell=nan", "cell"),
    ]:
        with pytest.raises(DceeInputError, match=field):
            planners.get(bad)


def test_any_loss_takes_the_multistage_search():
    # Multistage infotaxis comes from the shared beam search with no code of its own.
    belief = _two_point_belief(100)
    d = planners.get("infotaxis:horizon=2:beam_width=2").decide(
        belief, START, AGENT, np.random.default_rng(0)
    )
    assert d.info["sequences_evaluated"] == 8 + 2 * 8
    assert np.isfinite(d.costs).sum() <= 2


def test_ablation_options_change_the_hypotheses_as_documented():
    belief = _two_point_belief(50)
    twice = np.array([[[12.0, 10.0, 0.0]], [[12.0, 10.0, 0.0]]])
    fresh = PredictionContext(belief, 40, 1, np.random.default_rng(0), noise="fresh")
    st = fresh.stats(twice)
    assert not np.array_equal(st.readings[0], st.readings[1])  # a new draw per candidate
    quiet = PredictionContext(belief, 200, 1, np.random.default_rng(0), readings="noise-free")
    z = quiet.readings(quiet.position_index(twice[0]))[0][:, 0]
    conc = quiet.conc[0, quiet.indices]
    det = z > 0
    np.testing.assert_array_equal(z[det], conc[det])  # a detection reads C exactly
    seen = PredictionContext(belief, 200, 1, np.random.default_rng(0), readings="miss-free")
    z = seen.readings(seen.position_index(twice[0]))[0][:, 0]
    c = seen.conc[0, seen.indices]
    assert np.all((z > 0) == (c + (0.5 * c + 1e-4) * seen.noise[:, 0, 1] >= 5e-4))
    with pytest.raises(DceeInputError, match="readings"):
        planners.get("dcee:expectation=stratified:readings=noise-free")
    with pytest.raises(DceeInputError, match="subsample"):
        planners.get("dcee:subsample=0")
    small = planners.get("dcee:subsample=0.2:noise=fresh:hypotheses=25")
    d = small.decide(_spread_belief(), START, AGENT, np.random.default_rng(0))
    assert np.all(np.isfinite(d.costs))


@pytest.mark.parametrize("reach", [0.0, 1.5])
def test_scenario_tree_cost_for_a_point_belief_is_the_best_second_move(reach):
    # Every particle at s: no reading changes the belief, so J(u1) = min over the moves u2
    # from p1 of dist(s, disk(p2, R))², computed here by hand.
    s = np.array([20.0, 20.0, 0.0])
    belief = _belief([tuple(s[:2])] * 30, q=5.0, u=4.0, phi=math.radians(225))
    planner = planners.get("dcee-cl-tree", reach=reach, n_hypotheses=6, branch_hypotheses=3)
    d = planner.decide(belief, START, AGENT, np.random.default_rng(0))
    expected = []
    for p1 in d.candidates:
        p2 = AGENT.candidates(p1)[0]
        gap = np.maximum(np.hypot(*(p2[:, :2] - s[:2]).T) - reach, 0.0)
        expected.append(np.min(gap**2))
    np.testing.assert_allclose(d.costs, expected, rtol=1e-9, atol=1e-9)
    assert d.heading == 1 and d.info["branches"] >= 8
    with pytest.raises(DceeInputError, match="horizon"):
        planners.get("dcee-cl-tree:horizon=2")


@pytest.mark.parametrize("expectation", ["sampled", "stratified"])
def test_a_branch_drops_negligible_particles_without_changing_its_statistics(expectation):
    belief = _spread_belief()
    w = belief.weights.copy()
    w[::2] = 0.0  # half the particles cannot explain the hypothesised reading
    w /= w.sum()
    seqs = AGENT.candidates(START)[0][:, None, :]
    parent = PredictionContext(belief, 10, 1, np.random.default_rng(0), expectation)
    parent.position_index(seqs[:, 0])
    pruned = parent.branch(w, 12, np.random.default_rng(4)).stats(seqs)
    direct_belief = Belief(belief.theta, w, belief.sensor, belief.plume)
    direct = PredictionContext(direct_belief, 12, 1, np.random.default_rng(4), expectation)
    full = direct.stats(seqs)
    np.testing.assert_allclose(pruned.readings, full.readings, rtol=1e-12)
    for a, b in [(pruned.mean, full.mean), (pruned.trace_cov, full.trace_cov)]:
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(pruned.kl, full.kl, rtol=1e-6, atol=1e-9)


def test_spread_reach_scales_the_free_disk_with_the_belief():
    # Four equally weighted points at (±3, ±4) around (10, 10): var x + var y = 9 + 16 = 25.
    pts = [(7.0, 6.0), (13.0, 14.0), (7.0, 14.0), (13.0, 6.0)]
    belief = _belief(pts)
    assert planners.get("dcee-cl:reach=2:spread_reach=0").effective_reach(belief) == 2.0
    assert planners.get("dcee-cl:reach=2").effective_reach(belief) == 10.0  # the default 2 σ
    assert planners.get("dcee-cl:reach=2:spread_reach=1").effective_reach(belief) == 5.0
    assert planners.get("dcee-cl:reach=8:spread_reach=1").effective_reach(belief) == 8.0
    with pytest.raises(DceeInputError, match="spread_reach"):
        planners.get("dcee-cl:spread_reach=-1")


def test_vertical_reach_frees_the_height_error_only_for_a_climbing_agent():
    # The belief of the test above: σ_xy = 5 m, so R = max(2, 2 · 5) = 10 m. Two hypothesised
    # posterior means seen from (10, 10, 4): A 13 m east at height 0 (beyond the disk by 3 m,
    # 4 m below), B straight below at −2 m (6 m below); tr P' = 1.5 and 0.5 m².
    from dcee.planning.predicted import SequenceStats

    pts = [(7.0, 6.0), (13.0, 14.0), (7.0, 14.0), (13.0, 6.0)]
    belief = _belief(pts)
    mean = np.array([[[23.0, 10.0, 0.0], [10.0, 10.0, -2.0]]])
    nan = np.full((1, 2), np.nan)
    stats = SequenceStats(nan, np.array([[0.5, 0.5]]), nan, mean, np.array([[1.5, 0.5]]), nan, nan)
    final = np.array([[10.0, 10.0, 4.0]])
    planner = planners.get("dcee-cl:reach=2:info_share=0")
    volume = SearchVolume((0.0, 0.0, 0.0), (40.0, 40.0, 5.0))
    # fixed altitude: the height error is charged in full, 3² + 4² + 1.5 and 6² + 0.5
    planner.bind_agent(GridAgent(volume, step=2.0))
    np.testing.assert_allclose(planner.loss(final, stats, belief), [[26.5, 36.5]])
    # climb 1 m per 2 m step: R_z = 10 · 1 / 2 = 5 m; A's 4 m is free, B's 6 m costs 1²
    planner.bind_agent(GridAgent(volume, step=2.0, climb=1.0))
    assert planner.effective_vertical_reach(planner.effective_reach(belief)) == 5.0
    np.testing.assert_allclose(planner.loss(final, stats, belief), [[10.5, 1.5]])
    # vertical_reach 0 is the cost before: the height error charged in full, climbing or not
    before = planners.get("dcee-cl:reach=2:info_share=0:vertical_reach=0")
    before.bind_agent(GridAgent(volume, step=2.0, climb=1.0))
    np.testing.assert_allclose(before.loss(final, stats, belief), [[26.5, 36.5]])
    with pytest.raises(DceeInputError, match="vertical_reach"):
        planners.get("dcee-cl:vertical_reach=-1")


def test_a_climbing_dcee_cl_values_a_reading_at_another_height():
    # Two equally likely sources straight below the agent's column, at 0 m and 4 m, in a calm
    # (no wind, weak release): only a reading near one of them tells them apart. From 2 m, with
    # the old cost (vertical_reach 0) the height error cancels the height information and a
    # vertical move costs more than staying level (it leaves the believed mean height); with
    # the vertical reach the move towards one of them is the cheapest (it resolves the height,
    # which the agent can then act on).
    theta = theta_at([(10.0, 10.0, 0.0)] * 300 + [(10.0, 10.0, 4.0)] * 300, q=0.02, u=0.0)
    belief = Belief(theta, np.full(600, 1 / 600), Sensor.paper_exact(), IsotropicPlume())
    agent = GridAgent(SearchVolume((0.0, 0.0, 0.0), (40.0, 40.0, 5.0)), step=2.0, climb=1.0)
    position = np.array([10.0, 10.0, 2.0])
    new = planners.get("dcee-cl:hypotheses=12").decide(
        belief, position, agent, np.random.default_rng(0)
    )
    assert abs(new.candidates[new.index][2] - 2.0) == 1.0  # up or down, not level
    old = planners.get("dcee-cl:hypotheses=12:vertical_reach=0")
    before = old.decide(belief, position, agent, np.random.default_rng(0))
    assert before.candidates[before.index][2] == 2.0
    assert np.min(new.costs) < np.min(before.costs)


def test_info_share_charges_the_information_equivalent_location_variance():
    # Beyond every predicted mean (reach 100 m) the loss is the uncertainty term alone:
    # info_share=1 gives tr P · E_z[exp(−KL(w'(z) ‖ w))], checked here against the NumPy
    # reference posterior of each stratified hypothesis (independent of the compiled kernel).
    belief = _two_point_belief(200)
    planner = planners.get("dcee-cl:reach=100:info_share=1:hypotheses=12")
    assert planner.needs_kl and not planners.get("dcee-cl:info_share=0").needs_kl
    costs = planner.decide(belief, START, AGENT, np.random.default_rng(5)).costs
    ctx = PredictionContext(belief, 12, 1, np.random.default_rng(5), "stratified")
    candidates, _ = AGENT.candidates(START)
    d = belief.source - belief.source_mean()
    trace_p = float(belief.weights @ np.einsum("ij,ij->i", d, d))
    expected = []
    for p in candidates:
        idx = ctx.position_index(p[None, :])
        z, prob = ctx.readings(idx)
        conc, dist = ctx.terms.conc, ctx.terms.dist  # over the context's merged particles
        merged = ctx.belief
        _, _, _, kl = predicted_posterior_stats_reference(
            conc, merged.source, merged.weights, np.repeat(idx[None, :], len(z), 0), z,
            belief.sensor, dist,
        )  # fmt: skip
        expected.append(trace_p * prob @ np.exp(-kl))
    np.testing.assert_allclose(costs, expected, rtol=1e-9)
    # the term lies between "nothing learnt" (tr P) and "everything learnt" (0), and the move
    # whose reading discriminates between the two hypotheses (east) is preferred
    assert np.all((costs > 0) & (costs <= trace_p * (1 + 1e-12)))
    assert int(np.argmin(costs)) == 0
    # info_share interpolates linearly between the two uncertainty measures
    half = planners.get("dcee-cl:reach=100:info_share=0.5:hypotheses=12")
    zero = planners.get("dcee-cl:reach=100:info_share=0:hypotheses=12")
    c_half, c_zero = (
        pl.decide(belief, START, AGENT, np.random.default_rng(5)).costs for pl in (half, zero)
    )
    np.testing.assert_allclose(c_half, 0.5 * (c_zero + costs), rtol=1e-9)
    with pytest.raises(DceeInputError, match="info_share"):
        planners.get("dcee-cl:info_share=1.5")


@pytest.mark.parametrize("sensor", [Sensor(), Sensor.paper_exact(false_alarm=0.01)])
def test_stratified_hypotheses_of_every_sequence_at_once_are_those_one_at_a_time(sensor):
    """PredictionContext.stats draws the stratified hypotheses of all candidate sequences in one
    pass; they are the per-sequence loop's (tests/helpers.py) bit for bit, over one to five
    stages, with and without detections, and where no particle can be detected; a sequence
    asked for alone (``readings``) gets the same numbers."""
    rng = np.random.default_rng(11)
    theta = theta_at([(x, y, 0.0) for x, y in rng.uniform(0, 40, (600, 2))], q=1.0, u=2.0)
    w = rng.random(len(theta))
    belief = Belief(theta, w / w.sum(), sensor, IsotropicPlume())
    for horizon in (1, 3, 5):
        ctx = PredictionContext(belief, 12, horizon, rng, expectation="stratified")
        seqs = rng.uniform(0, 40, (9, horizon, 3))
        seqs[..., 2] = 0.0
        seqs[0] = [200.0, 200.0, 0.0]  # far outside: no particle can be detected there
        pos_idx = ctx.position_index(seqs.reshape(-1, 3)).reshape(9, horizon)
        readings, probability = ctx._stratified_batch(pos_idx)
        assert (readings[1:] > 0).any()
        for s in range(9):
            one_z, one_p = stratified_readings_reference(ctx, pos_idx[s])
            assert np.array_equal(one_z, readings[s]) and np.array_equal(one_p, probability[s])
            alone_z, alone_p = ctx.readings(pos_idx[s])
            assert np.array_equal(alone_z, one_z) and np.array_equal(alone_p, one_p)
