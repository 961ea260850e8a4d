"""Wind directions as compass bearings (issue 43): by hand, in scenarios, in `dcee show`."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.models.compass import (
    bearing_from_phi,
    compass_point,
    estimated_bearing,
    phi_from_bearing,
    wind_from_words,
)
from dcee.scenarios import load_scenario
from dcee.scenarios.schema import validate_scenario
from tests.helpers import run_cli


@pytest.mark.parametrize(
    ("phi", "bearing", "point"),
    [(0.0, 90.0, "E"), (90.0, 0.0, "N"), (180.0, 270.0, "W"), (270.0, 180.0, "S"),
     (45.0, 45.0, "NE"), (135.0, 315.0, "NW"), (-30.0, 120.0, "ESE")],
)  # fmt: skip
def test_bearings_by_hand(phi, bearing, point):
    """φ counter-clockwise from east, the bearing clockwise from north, both where the wind
    comes from: a west wind (blowing towards +x, east) is φ = 180°, bearing 270°."""
    assert bearing_from_phi(phi) == pytest.approx(bearing)
    assert phi_from_bearing(bearing) == pytest.approx(phi % 360.0)
    assert compass_point(bearing) == point


def test_the_plume_goes_where_the_bearing_says():
    """A north wind (bearing 0) carries the plume south: the model's downwind direction
    −(cos φ, sin φ) at φ = phi_from_bearing(0) points to −y."""
    phi = math.radians(phi_from_bearing(0.0))
    np.testing.assert_allclose(-np.array([math.cos(phi), math.sin(phi)]), [0.0, -1.0], atol=1e-12)
    assert wind_from_words(90.0) == "wind from 000° (N)"
    assert wind_from_words(90.4) == "wind from 000° (N)"  # 359.6 rounds to north, not 360


def test_a_scenario_takes_the_bearing_and_stores_phi():
    base = load_scenario("paper:1")
    west = base.with_overrides(**{"truth.wind_from": 270.0})
    assert west.truth.phi == 180.0 and west.truth.wind_from is None
    prior = base.with_overrides(
        **{"prior.wind_from": {"kind": "uniform", "low": 200.0, "high": 290.0}}
    ).prior["phi"]
    assert (prior.low, prior.high) == (-200.0, -110.0)
    # the same scenario given either way is one scenario (old files load unchanged)
    assert base.with_overrides(**{"truth.wind_from": 90.0}) == base


@pytest.mark.parametrize(
    ("override", "message"),
    [({"truth.wind_from": 400.0}, "truth.wind_from: a compass bearing in degrees, in [0, 360]"),
     ({"truth.wind_from": "west"}, "truth.wind_from: a compass bearing")],
)  # fmt: skip
def test_bad_bearings_are_one_line_errors(override, message):
    with pytest.raises(DceeInputError, match=re.escape(message)):
        load_scenario("paper:1").with_overrides(**override)
    data = load_scenario("paper:1").model_dump()
    data["prior"]["wind_from"] = {"kind": "normal", "mean": 1.0, "sd": 2.0}
    with pytest.raises(DceeInputError, match=re.escape("prior.wind_from: give prior.phi or")):
        validate_scenario(data)


def test_both_angles_must_agree_in_a_file(tmp_path):
    path = tmp_path / "both.toml"
    from dcee.scenarios import to_toml

    toml = to_toml(load_scenario("paper:1")).replace("phi = 0.0\n", "phi = 0.0\nwind_from = 10.0\n")
    path.write_text(toml)
    with pytest.raises(
        DceeInputError, match=re.escape("give truth.phi or truth.wind_from, not both")
    ):
        load_scenario(str(path))
    path.write_text(toml.replace("wind_from = 10.0", "wind_from = 90.0"))
    assert load_scenario(str(path)).truth.phi == 0.0


def test_show_and_scenarios_print_the_bearing(capsys):
    out = run_cli(["show", "paper:4"], capsys)[1]  # phi 180: a west wind
    assert "# ^ wind from 270° (W)" in out and "wind_from = 270" in out
    listing = run_cli(["scenarios"], capsys)[1]
    assert "paper:1 " in listing and "wind from 090° (E)" in listing


def test_show_prints_a_uniform_priors_bearings():
    from dcee.scenarios import to_toml

    scenario = load_scenario("paper:1").with_overrides(
        **{"prior.wind_from": {"kind": "uniform", "low": 200.0, "high": 290.0}}
    )
    assert "# ^ wind from bearings 200° to 290° clockwise (compass)" in to_toml(scenario)


def test_a_beliefs_bearing_is_the_circular_mean():
    """Winds from bearings 10° and 350° (φ 80° and 100°) average to a north wind, bearing 0°,
    not to the arithmetic mean of the bearings, 180°."""
    phi = np.radians([80.0, 100.0])
    assert estimated_bearing(phi, np.array([0.5, 0.5])) == pytest.approx(0.0, abs=1e-9)
    # across φ = 0: 350° and 10° average to 0° (bearing 90°), not 180°
    phi = np.radians([350.0, 10.0])
    assert estimated_bearing(phi, np.array([0.5, 0.5])) == pytest.approx(90.0)
    assert estimated_bearing(phi, np.array([1.0, 0.0])) == pytest.approx(100.0)
