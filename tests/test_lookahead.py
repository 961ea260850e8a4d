"""``search.lookahead``: how many moves ``dcee-cl`` looks ahead. Unset, it follows the expected
plume: three moves where it was chosen (the grid UAV, the fluctuation likelihood, one release, in
open terrain and at a site with the wall-aware estimator), one everywhere else (every search
there unchanged)."""

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.planning import get as get_planner
from dcee.runs import planner_defaults, scenario_identity
from dcee.scenarios import (
    AUTO_LOOKAHEAD,
    SITE_LOOKAHEAD,
    load_scenario,
    to_toml,
    unset_lookahead,
)


def _turbulent():
    return load_scenario("random:16").with_overrides(**{"estimator.likelihood": "fluctuation"})


def test_an_unset_lookahead_is_three_only_where_it_was_chosen():
    paper = load_scenario("random:16")
    turbulent = _turbulent()
    assert AUTO_LOOKAHEAD == 3
    assert paper.search.lookahead is None and paper.lookahead == 1
    assert turbulent.lookahead == 3
    # not measured with several releases, on a site or on the ground robot: one move, as before
    several = {"estimator.max_sources": 2, "estimator.calm_prior": 0.0, "estimator.learn": {}}
    assert turbulent.with_overrides(**several).lookahead == 1
    assert turbulent.with_overrides(**{"agent.model": "unicycle"}).lookahead == 1
    site = load_scenario("site:wall").with_overrides(**{"estimator.plume": "open"})
    assert site.lookahead == 1  # the wall-blind estimator at a site: not measured there
    # the wall-aware estimator at a site (its default there since issue 84): chosen on the
    # tuning sites (SITE_LOOKAHEAD)
    aware = load_scenario("site:wall")
    assert aware.plume_model == "walls" and aware.estimator.likelihood == "fluctuation"
    assert aware.lookahead == SITE_LOOKAHEAD
    assert aware.with_overrides(**{"agent.model": "unicycle"}).lookahead == 1
    # a value set is kept everywhere
    assert paper.with_overrides(**{"search.lookahead": 3}).lookahead == 3
    assert turbulent.with_overrides(**{"search.lookahead": 1}).lookahead == 1
    assert unset_lookahead("fluctuation", "grid", 1, True) == 3
    assert unset_lookahead("paper", "grid", 1, True) == 1
    assert unset_lookahead("fluctuation", "grid", 1, False) == 1
    assert unset_lookahead("fluctuation", "grid", 1, False, wall_aware=True) == SITE_LOOKAHEAD
    assert unset_lookahead("paper", "grid", 1, False, wall_aware=True) == 1
    assert unset_lookahead("fluctuation", "grid", 2, False, wall_aware=True) == 1


def test_only_dcee_cl_follows_it_and_a_spec_overrides_it():
    turbulent = _turbulent()
    assert planner_defaults("dcee-cl", turbulent, None)["horizon"] == 3
    assert get_planner("dcee-cl", **planner_defaults("dcee-cl", turbulent, None)).horizon == 3
    spec = "dcee-cl:horizon=1"
    assert get_planner(spec, **planner_defaults(spec, turbulent, None)).horizon == 1
    # the paper's likelihood: the planner's own one move
    paper = load_scenario("random:16")
    assert get_planner("dcee-cl", **planner_defaults("dcee-cl", paper, None)).horizon == 1
    # infotaxis, the multistage DCEE and the scenario tree keep their own
    for name, own in (("infotaxis", 1), ("dcee-ms", 2), ("dcee-cl-tree", 1)):
        options = planner_defaults(name, turbulent, None)
        assert "horizon" not in options
        assert get_planner(name, **options).horizon == own
    # the tree search takes one stage of its cost at a time, whatever the scenario says
    assert "horizon" not in planner_defaults("dcee-mcts", turbulent, None)


def test_the_resolved_lookahead_is_shown_and_decides_a_campaign_identity():
    turbulent = _turbulent()
    assert "# lookahead = 3  (unset: the default for this scenario)" in to_toml(turbulent)
    stored = turbulent.model_dump(mode="json")
    explicit = turbulent.with_overrides(**{"search.lookahead": 3}).model_dump(mode="json")
    one = turbulent.with_overrides(**{"search.lookahead": 1}).model_dump(mode="json")
    two = turbulent.with_overrides(**{"search.lookahead": 2}).model_dump(mode="json")
    assert scenario_identity(stored) == scenario_identity(explicit)
    assert scenario_identity(stored) != scenario_identity(one)
    assert scenario_identity(stored) != scenario_identity(two)
    # a turbulent campaign stored before the setting existed flew one move ahead: it resumes
    # only with the look-ahead pinned to 1
    before = turbulent.model_dump(mode="json")
    del before["search"]["lookahead"]
    assert scenario_identity(before) == scenario_identity(one)
    assert scenario_identity(before) != scenario_identity(stored)
    # a campaign of the paper's likelihood stored before it: unchanged
    paper = load_scenario("random:16")
    old = paper.model_dump(mode="json")
    del old["search"]["lookahead"]
    assert scenario_identity(old) == scenario_identity(paper.model_dump(mode="json"))
    # at a site, the wall-aware estimator's unset look-ahead compares as SITE_LOOKAHEAD
    aware = load_scenario("site:wall").with_overrides(
        **{"estimator.likelihood": "fluctuation", "estimator.plume": "walls"}
    )
    pinned = aware.with_overrides(**{"search.lookahead": SITE_LOOKAHEAD})
    one_move = aware.with_overrides(**{"search.lookahead": 1})
    assert scenario_identity(aware.model_dump(mode="json")) == scenario_identity(
        pinned.model_dump(mode="json")
    )
    assert scenario_identity(aware.model_dump(mode="json")) != scenario_identity(
        one_move.model_dump(mode="json")
    )


@pytest.mark.parametrize("bad", [0, 4, 1.5, "two"])
def test_a_lookahead_out_of_range_is_refused(bad):
    with pytest.raises(DceeInputError, match=r"search\.lookahead"):
        load_scenario("random:16").with_overrides(**{"search.lookahead": bad})


def test_the_unset_lookahead_is_the_three_move_planner_decision_for_decision():
    """A turbulent scenario's dcee-cl with the look-ahead unset decides as dcee-cl:horizon=3."""
    from dcee.runs import run_episode

    scenario = _turbulent().with_overrides(
        **{"search.particles": 300, "search.hypotheses": 8, "search.budget": 40.0}
    )
    auto = run_episode(scenario, "dcee-cl", seed=3)
    spec = run_episode(scenario, "dcee-cl:horizon=3", seed=3)
    two = run_episode(scenario, "dcee-cl:horizon=2", seed=3)

    def path(result):
        return np.array([[r["x"], r["y"], r["z"]] for r in result.records])

    np.testing.assert_array_equal(path(auto), path(spec))
    np.testing.assert_array_equal(auto.final_theta, spec.final_theta)
    assert not np.array_equal(path(auto), path(two))
