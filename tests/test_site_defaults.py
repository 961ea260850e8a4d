"""Walls by default wherever there are walls (issue 84, item 3): at a site with walls the unset
truth is the fluid solver's plume, whose gas flows round them, with the likelihood chosen for
it, and the unset estimator plume the wall-aware one where it applies; open terrain and a site
with no-go zones only are unchanged. Validation only: no plume is computed here."""

from __future__ import annotations

import pytest

from dcee.errors import DceeInputError
from dcee.runs.identity import scenario_identity
from dcee.scenarios import load_scenario, validate_scenario
from dcee.scenarios.files import to_toml

WALLED = ["site:wall", "site:passage", "site:canyon", "site:block", "random-site:1"]


@pytest.mark.parametrize("name", WALLED)
def test_a_site_with_walls_resolves_to_gas_round_them(name: str) -> None:
    sc = load_scenario(name)
    assert sc.truth.model_name == "lbm"
    assert sc.truth.z == sc.agent.start[2]  # the solver's plume is planar: its source in the plane
    assert sc.estimator.likelihood == "fluctuation"
    assert sc.estimator.plume is None and sc.plume_model == "walls"
    assert sc.resolved_settings()["estimator_plume"] == "walls"
    text = to_toml(sc)
    assert '# plume = "walls"  (unset: the default for this scenario)' in text
    assert 'kind = "lbm"' in text


@pytest.mark.parametrize("name", ["site:nogo", "paper:1", "random:1", "lab:upwind"])
def test_open_terrain_and_no_go_zones_are_unchanged(name: str) -> None:
    sc = load_scenario(name)
    assert sc.plume_model == "open"
    if name != "lab:upwind":  # the lab's own truth and fitted likelihood
        assert sc.truth.model_name == "isotropic" and sc.estimator.likelihood == "paper"


def test_the_wall_aware_plume_is_the_default_only_where_it_applies() -> None:
    site = load_scenario("site:wall")
    # a wind or ζ to estimate, several releases: one flow cannot serve, the open plume does
    assert site.with_overrides(unknown="full").plume_model == "open"
    several = {"estimator.likelihood": "paper", "estimator.max_sources": 2}
    assert site.with_overrides(**several).plume_model == "open"
    # set by hand, kept
    assert site.with_overrides(**{"estimator.plume": "open"}).plume_model == "open"
    # the truth set by hand is kept too (the gas then passes through the wall)
    assert site.with_overrides(**{"truth.model": "isotropic"}).truth.model_name == "isotropic"


def test_a_site_file_without_a_truth_model_gets_the_solver_plume_or_one_line() -> None:
    raw = load_scenario("site:wall").model_dump(mode="json")
    raw["truth"].pop("model")
    raw["estimator"].pop("likelihood")
    sc = validate_scenario(raw)
    assert sc.truth.model_name == "lbm" and sc.estimator.likelihood == "fluctuation"
    raw["truth"]["z"] = 1.0  # a release below the UAV: the planar plume cannot hold it
    with pytest.raises(DceeInputError, match=r"^truth\.z: 1 m is off the flight plane.*isotropic"):
        validate_scenario(raw)
    raw["truth"]["model"] = "isotropic"
    assert validate_scenario(raw).plume_model == "walls"


def test_a_campaign_stored_with_the_open_plume_set_still_resumes_in_open_terrain() -> None:
    """Stored before issue 84 every scenario held ``plume = "open"``; in open terrain the unset
    plume resolves to the same, so the identity is the same. At a site it is not."""
    paper = load_scenario("paper:1").model_dump(mode="json")
    before = {**paper, "estimator": {**paper["estimator"], "plume": "open"}}
    assert paper["estimator"]["plume"] is None
    assert scenario_identity(before) == scenario_identity(paper)
    site = load_scenario("site:wall").model_dump(mode="json")
    old = {**site, "estimator": {**site["estimator"], "plume": "open"}}
    assert scenario_identity(old) != scenario_identity(site)
