"""The wall-aware estimator (``estimator.plume = "walls"``): every consumer of a plume without
compiled constants (the filter's history likelihood, the planners' position terms, the
exploration guard) against its compiled open-plume path, through a plume that predicts the open
plume by its own method; the scenario checks; a search round a wall."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from dcee.estimation import ParticleFilter
from dcee.estimation.filter_kernels import history_log_likelihood_generic
from dcee.exploration import detection_information
from dcee.models.plume import IsotropicPlume, isotropic_concentration_reference
from dcee.models.site_plume import SitePlume
from dcee.planning.particle_terms import ParticleTerms
from dcee.runs import run_episode
from dcee.scenarios import load_scenario


class OwnMethodPlume:
    """The open plume predicting by its own (NumPy) method, as the wall-aware plume does: what
    the generic paths see, with the compiled paths as the reference."""

    def __init__(self, plume: IsotropicPlume) -> None:
        self.plume = plume

    def concentration_distance(self, theta: np.ndarray, positions: np.ndarray) -> tuple:
        p = self.plume
        conc = isotropic_concentration_reference(theta, positions, p.min_distance, *p.shape)
        d = positions[None, :, :] - theta[:, None, :3]
        return conc, np.maximum(np.sqrt(np.einsum("nki,nki->nk", d, d)), p.min_distance)


@pytest.fixture(scope="module")
def belief() -> tuple:
    sc = load_scenario("paper:2").with_overrides(**{"estimator.likelihood": "fluctuation"})
    sensor = sc.make_sensor()
    pf = ParticleFilter(sc.make_prior(), sensor, IsotropicPlume(), n_particles=3000, seed=4)
    for p, z in (((10.0, 10.0, 2.0), 0.0), ((20.0, 15.0, 2.0), 0.02), ((22.0, 15.0, 2.0), 0.0)):
        pf.update(np.array(p), z)
    return pf, sensor


def test_history_likelihood_of_a_plume_by_its_own_method_is_the_compiled_one(belief) -> None:
    pf, _ = belief
    positions = np.array([[10.0, 10.0, 2.0], [20.0, 15.0, 2.0], [30.0, 40.0, 4.0]])
    readings = np.array([0.0, 0.03, 1.5])
    mult = np.array([1.0, 0.5, 2.0])
    active = np.ones(len(pf.theta), bool)
    active[::7] = False
    compiled = np.empty(len(pf.theta))
    pf._history_ll(pf.theta, active, positions, readings, mult, compiled)
    generic = np.empty(len(pf.theta))
    history_log_likelihood_generic(
        OwnMethodPlume(pf.plume), pf.theta, active, positions, readings, mult, pf._sp, generic
    )
    assert np.all(generic[~active] == -np.inf)
    np.testing.assert_allclose(generic[active], compiled[active], rtol=1e-10, atol=1e-9)


def test_position_terms_of_a_plume_by_its_own_method_are_the_compiled_ones(belief) -> None:
    pf, sensor = belief
    positions = np.array([[12.0, 30.0, 2.0], [40.0, 5.0, 3.0], [25.0, 25.0, 1.0]])
    compiled, generic = ParticleTerms(), ParticleTerms()
    compiled.sync(pf.theta, sensor, pf.plume)
    generic.sync(pf.theta, sensor, OwnMethodPlume(pf.plume))
    rows_c, rows_g = compiled.rows(positions), generic.rows(positions)
    for a, b in zip(compiled.terms, generic.terms, strict=True):
        np.testing.assert_allclose(b[rows_g], a[rows_c], rtol=1e-9, atol=1e-12)
    # a subset keeps the plume's own method
    keep = np.arange(generic.n) % 3 == 0
    sub = generic.subset(keep)
    more = np.array([[5.0, 45.0, 2.0]])
    np.testing.assert_allclose(
        sub.terms.conc[sub.rows(more)][0],
        compiled.terms.conc[compiled.rows(more)][0][keep],
        rtol=1e-9,
    )


def test_exploration_information_of_a_plume_by_its_own_method_is_the_compiled_one(belief):
    pf, sensor = belief
    points = np.array([[5.0, 5.0, 2.0], [25.0, 20.0, 2.0], [45.0, 45.0, 2.0], [20.0, 15.0, 2.0]])
    a = detection_information(pf.theta, pf.weights, sensor, pf.plume, points)
    b = detection_information(pf.theta, pf.weights, sensor, OwnMethodPlume(pf.plume), points)
    np.testing.assert_allclose(b, a, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"scenario": "paper:1"}, "needs buildings or walls"),
        ({"unknown": "full"}, 'needs unknown = "source"'),
        # the paper's likelihood: one reading model, so the count's own check passes
        ({"estimator.likelihood": "paper", "estimator.max_sources": 2}, "max_sources = 1"),
        (
            {"scenario": "site:wall", "estimator.plume": "open", "estimator.wall_lifetime": 8.0},
            "wall_lifetime",
        ),
        (
            {"estimator.wall_wind": "potential", "estimator.wall_viscosity": 0.5},
            "wall_viscosity: is the wake wind's",
        ),
        (
            {"scenario": "site:wall", "estimator.plume": "open", "estimator.wall_viscosity": 0.5},
            "wall_viscosity",
        ),
        (
            {
                "estimator.likelihood": "fluctuation",
                "estimator.wall_wind": "potential",
                "estimator.learn": {"wall_viscosity": [1.0, 0.2]},
            },
            "wall_viscosity: is the wake wind's",
        ),
        (
            {
                "estimator.likelihood": "fluctuation",
                "estimator.learn": {"wall_viscosity": [0.5, 0.2]},
            },
            "must include the fixed value 1",
        ),
        (
            {"estimator.likelihood": "fluctuation", "estimator.learn": {"decay": [1.0, 0.5]}},
            "shape the open plume",
        ),
    ],
)
def test_combinations_that_cannot_work_get_one_line(changes, message) -> None:
    from dcee.errors import DceeInputError

    changes = dict(changes)
    name = changes.pop("scenario", "site:wall")
    with pytest.raises(DceeInputError, match=message):
        load_scenario(name).with_overrides(**{"estimator.plume": "walls", **changes})


def test_the_fluctuation_likelihood_learns_no_open_plume_shape_round_walls() -> None:
    sc = load_scenario("site:wall").with_overrides(
        **{"estimator.plume": "walls", "estimator.likelihood": "fluctuation"}
    )
    # the diffusivity weighed at 1, 3 and 10 times ζ1 and the wake's eddy viscosity at 1 and 0.2
    # times its own (no backflow or disc member), and the calm member with the first; no decay
    # (a conserved gas)
    assert sc.reading_models == (
        "fluctuation",
        "fluctuation[wall_diffusivity=1,wall_viscosity=0.2]",
        "fluctuation[wall_diffusivity=3,wall_viscosity=1]",
        "fluctuation[wall_diffusivity=3,wall_viscosity=0.2]",
        "fluctuation[wall_diffusivity=10,wall_viscosity=1]",
        "fluctuation[wall_diffusivity=10,wall_viscosity=0.2]",
        "paper",
    )
    plumes = [sc.make_plume(m) for m in sc.reading_models]
    assert all(isinstance(p, SitePlume) for p in plumes)
    assert [p.zeta1 for p in plumes] == [1.0, 1.0, 3.0, 3.0, 10.0, 10.0, 1.0]
    assert plumes[0] is plumes[6] and all(p.zeta2 == float("inf") for p in plumes)
    # one wake per viscosity, shared by the members of that viscosity
    assert plumes[0].face_u is plumes[2].face_u is plumes[4].face_u
    assert plumes[1].face_u is plumes[3].face_u is not plumes[0].face_u
    # a fixed viscosity by hand is the bank's first; the potential wind has none to weigh
    hand = sc.with_overrides(**{"estimator.wall_viscosity": 0.5})
    assert hand.learn["wall_viscosity"] == [0.5, 0.1]
    potential = sc.with_overrides(**{"estimator.wall_wind": "potential"})
    assert "wall_viscosity" not in potential.learn and len(potential.reading_models) == 4
    fixed = sc.with_overrides(**{"estimator.learn": {}, "estimator.wall_lifetime": 8.0})
    assert fixed.reading_models == ("fluctuation", "paper") and fixed.make_plume().zeta2 == 8.0


def test_a_search_round_a_wall_with_the_wall_aware_estimator() -> None:
    sc = load_scenario("site:wall").with_overrides(
        **{
            "truth.model": "isotropic",  # not the site's default: minutes to compute the first time
            "search.particles": 600,
            "search.hypotheses": 8,
            "search.budget": 200.0,
        }
    )
    res = run_episode(sc, "dcee-cl", seed=0)
    xy = np.array([[r["x"], r["y"]] for r in res.records])
    assert not sc.make_site().is_blocked(xy).any()
    assert np.isfinite(res.summary["final_rmse"])


def _map(tmp_path, resolution: float, edit) -> str:
    """A 50 m × 50 m free map at ``resolution`` with ``edit(pixels, cell)`` applied (pixels
    row 0 at the top: the largest y; ``cell(x, y)`` gives a pixel's (row, column))."""
    from PIL import Image

    n = round(50 / resolution)
    pixels = np.full((n, n), 254, np.uint8)

    def cell(x: float, y: float) -> tuple[int, int]:
        return n - 1 - int(y / resolution), int(x / resolution)

    edit(pixels, cell)
    Image.fromarray(pixels, mode="L").save(tmp_path / "m.png")
    (tmp_path / "m.yaml").write_text(
        f"image: m.png\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\n"
    )
    return str(tmp_path / "m.yaml")


def _box(pixels, cell, x0, y0, x1, y1, value=0):
    r1, c0 = cell(x0, y0)
    r0, c1 = cell(x1, y1)
    pixels[r0 : r1 + 1, c0 : c1 + 1] = value


ENCLOSURE = (
    (0.5, 0.5, 46.0, 1.0),
    (0.5, 20.0, 46.0, 21.0),
    (0.5, 0.5, 1.0, 21.0),
    (45.0, 0.5, 46.0, 21.0),
)
"""Walls round the start (2, 2) and the source (37.5, 12.5) of paper:1: the robot reaches the
source, the gas cannot leave."""


@pytest.mark.parametrize(
    ("resolution", "edit", "message"),
    [
        (2.0, lambda p, c: _box(p, c, 10, 10, 12, 30), "2 m cells"),
        (0.5, lambda p, c: _box(p, c, 38.6, 12.0, 39.6, 13.0, 205), "unknown"),
        (0.5, lambda p, c: [_box(p, c, *b) for b in ENCLOSURE], "no free path out"),
    ],
)
def test_a_map_the_gas_cannot_use_is_one_line_exit_2_before_any_work(
    tmp_path, capsys, resolution, edit, message
) -> None:
    """Too coarse, unknown round the source, the source's gas enclosed with the robot."""
    from tests.helpers import run_cli

    path = _map(tmp_path, resolution, edit)
    out = tmp_path / "run"
    code, _, err = run_cli(
        [
            "run", "--scenario", "paper:1", "--truth", "lbm", "--set", "truth.z=4",
            "--set", f'world.map="{path}"', "--out", str(out),
        ],
        capsys,
    )  # fmt: skip
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and message in lines[0], lines
    assert not out.exists()


def test_random_sites_are_reproducible_open_and_valid_for_the_gas() -> None:
    from dcee.scenarios.builtin import random_site_configuration

    for k in (1, 7, 20):
        a, b = random_site_configuration(k), random_site_configuration(k)
        assert a == b
        boxes = [(o["low"], o["high"]) for o in a["world"]["obstacles"]]
        assert 3 <= len(boxes) <= 6
        src = np.array([a["truth"]["x"], a["truth"]["y"]])
        for (lo, hi), (lo2, hi2) in itertools.combinations(boxes, 2):
            gap = np.hypot(
                max(lo[0] - hi2[0], lo2[0] - hi[0], 0), max(lo[1] - hi2[1], lo2[1] - hi[1], 0)
            )
            assert gap >= 2.9
        for lo, hi in boxes:
            assert (
                np.hypot(*np.maximum(np.maximum(np.array(lo) - src, src - np.array(hi)), 0)) >= 2.9
            )
        # it validates with the gas flowing round its buildings (reachable, open to the edge)
        load_scenario(f"random-site:{k}").with_overrides(
            **{"truth.model": "lbm", "truth.z": 4.0, "estimator.plume": "walls"}
        )


def test_a_robot_map_makes_the_gas_flow_round_its_walls() -> None:
    """The ROS node's switch (dcee.robot.map_gas): a map received becomes the scenario's map
    under the wall-aware plume, whose grid has the map's wall as walls; where the scenario
    cannot take the wall-aware plume (the wind to estimate) it stays as it was, with the
    reason."""
    from dcee.models.site import Rectangle, SiteMap
    from dcee.robot.map_gas import MapGas

    site = load_scenario("paper:1").with_overrides(
        **{"unknown": "source", "estimator.likelihood": "fluctuation"}
    )
    wall = Rectangle((20.0, 30.0), (40.0, 31.0))  # a wall north of the source, across the area
    grid = SiteMap.from_shapes((0.0, 0.0), (50.0, 50.0), [wall], resolution=0.5, name="robot")
    gas = MapGas()
    assert gas.scenario(site, True) == (site, None)  # no map yet
    gas.update(grid)
    assert gas.scenario(site, False) == (site, None)  # parameter gas_walls off
    walled, line = gas.scenario(site, True)
    assert walled.estimator.plume == "walls" and "flows round the map's walls" in line
    assert walled.world.map.endswith("map-1.yaml")
    plume = walled.make_plume()
    assert isinstance(plume, SitePlume)
    cells = np.array([[30.0, 30.5], [30.0, 25.0]])
    _, w = plume.weights(cells)
    assert w[0].sum() == 0 and w[1].sum() == pytest.approx(1.0)  # the wall is a wall for the gas
    # the wind unknown: one flow cannot be solved, the gas stays open, the reason is one line
    full = site.with_overrides(**{"unknown": "full"})
    same, line = gas.scenario(full, True)
    assert same is full and "open terrain" in line and "unknown" in line and "\n" not in line
