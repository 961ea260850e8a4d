import math

import numpy as np
import pytest

from dcee import DceeInputError
from dcee.scenarios import builtin_scenarios, load_scenario


def test_all_builtins_validate():
    names = list(builtin_scenarios())
    assert [f"paper:{k}" for k in range(1, 13)] == names[:12]
    assert {"lab:downwind", "lab:upwind"} <= set(names)
    for n in names:
        load_scenario(n)


def test_paper_scenarios_use_the_papers_parameters():
    s = load_scenario("paper:1")
    t = s.truth
    assert (t.x, t.y, t.z, t.q, t.u, t.phi, t.zeta1, t.zeta2) == (37.5, 12.5, 1, 5, 4, 0, 1, 8)
    assert s.agent.start == (2, 2, 4) and s.agent.step == 2 and s.agent.speed == 2
    assert s.search.particles == 20_000 and s.search.hypotheses == 40 and s.search.budget == 900
    assert s.unknown_names == ("x", "y", "z", "q")
    assert s.prior["q"].shape == 2 and s.prior["q"].scale == 5


def test_paper_plumes_are_long_varied_and_half_point_away_from_the_chord():
    start = np.array([2.0, 2.0])
    away, directions = [], set()
    for k in range(1, 13):
        t = load_scenario(f"paper:{k}").truth
        src = np.array([t.x, t.y])
        axis = -np.array([math.cos(math.radians(t.phi)), math.sin(math.radians(t.phi))])
        inside = [src + r * axis for r in np.arange(1.0, 80.0, 0.5)]
        inside = [p for p in inside if np.all((p >= 0) & (p <= 50))]
        assert len(inside) * 0.5 >= 24, f"paper:{k}: plume axis too short inside the area"
        chord = (start - src) / np.linalg.norm(start - src)
        if math.degrees(math.acos(np.clip(axis @ chord, -1, 1))) > 45:
            away.append(k)  # the plume does not lie along the chord from the start
        directions.add(t.phi)
    assert away == [4, 5, 7, 8, 11, 12] and len(directions) >= 8


def test_lab_scenarios_have_seven_unknowns_in_two_dimensions():
    for start in ("downwind", "upwind"):
        s = load_scenario(f"lab:{start}")
        assert s.dimensions == 2
        assert s.unknown_names == ("x", "y", "q", "u", "phi", "zeta1", "zeta2")
        assert s.make_prior().unknown_names == s.unknown_names
        assert s.agent.step == 0.3


def test_overrides_are_revalidated():
    s = load_scenario("paper:2").with_overrides(**{"search.particles": 500, "unknown": "full"})
    assert s.search.particles == 500 and len(s.unknown_names) == 8
    with pytest.raises(DceeInputError, match=r"search\.particles"):
        s.with_overrides(**{"search.particles": -1})


def test_only_the_final_combination_of_overrides_must_hold():
    # the order the refusal's advice gives: more releases, then one reading model
    changes = {
        "estimator.likelihood": "fluctuation",
        "estimator.max_sources": 3,
        "estimator.calm_prior": 0.0,
        "estimator.learn": {},
    }
    s = load_scenario("random2:1").with_overrides(**changes)
    assert s.estimator.max_sources == 3 and s.reading_models == ("fluctuation",)
    # a final combination that does not hold is still refused, with its own reason
    with pytest.raises(DceeInputError, match="need one reading model"):
        load_scenario("random2:1").with_overrides(**{**changes, "estimator.calm_prior": 0.5})
    # a later path into a section the invalid halfway state never made: the real reason
    with pytest.raises(DceeInputError, match=r"search\.particles"):
        load_scenario("paper:1").with_overrides(
            **{
                "search.particles": -1,
                "truth.model": "filament",
                "truth.model.meander_intensity": 1,
            }
        )


def test_changes_into_existing_sections_are_validated_once_with_the_same_result(monkeypatch):
    """Changes that all go into sections the scenario has are applied at once and validated
    once; the scenario is the one the change-by-change path makes. A change into a section an
    earlier change makes (a model given by name, then one of its settings) takes that path."""
    from dcee.scenarios.schema import scenario as schema

    calls = []
    real = schema.validate_scenario

    def counted(data):
        calls.append(1)
        return real(data)

    monkeypatch.setattr(schema, "validate_scenario", counted)
    base = load_scenario("random:3")
    changes = {
        "search.particles": 4000,
        "unknown": "full",
        "truth.wind_from": 200.0,
        "agent.step": 1.5,
        "estimator.likelihood": "fluctuation",
    }
    fast = base.with_overrides(**changes)
    assert len(calls) == 1
    assert fast.model_dump() == base._with_overrides_stepwise(changes).model_dump()
    calls.clear()
    named = {"truth.model": "filament", "truth.model.meander_intensity": 0.3}
    stepwise = base.with_overrides(**named)
    assert len(calls) == 2 and stepwise.truth.model.meander_intensity == 0.3


def test_toml_file_errors(tmp_path):
    good = tmp_path / "site.toml"
    good.write_text(
        "[volume]\nlow=[0,0,0]\nhigh=[20,20,3]\n"
        "[truth]\nx=5\ny=5\nz=1\nq=2\nu=3\nphi=90\nzeta1=1\nzeta2=8\n"
        "[agent]\nstart=[1,1,2]\n"
    )
    s = load_scenario(str(good))
    assert s.name == "site" and s.search.particles == 20_000
    outside = tmp_path / "outside.toml"
    outside.write_text(good.read_text().replace("x=5", "x=50"))
    with pytest.raises(DceeInputError, match="outside the search volume"):
        load_scenario(str(outside))
    typo = tmp_path / "typo.toml"
    typo.write_text(good.read_text() + "[search]\nparticle=10\n")
    with pytest.raises(DceeInputError, match=r"search\.particle: unknown field"):
        load_scenario(str(typo))
    full = tmp_path / "full.toml"
    full.write_text('unknown = "full"\n' + good.read_text())
    with pytest.raises(DceeInputError, match="phi"):
        load_scenario(str(full))


BASE_TOML = """
unknown = "full"
[volume]
low = [0, 0, 0]
high = [50, 50, 5]
[truth]
x = 25
y = 5
z = 1
q = 2
u = 3
phi = 90
zeta1 = 1
zeta2 = 8
[agent]
start = [1, 1, 2]
{agent}
[prior]
q = {q}
u = {u}
phi = {{ kind = "normal", mean = 90.0, sd = 3.0 }}
zeta1 = {{ kind = "normal", mean = 1.0, sd = 1.4 }}
zeta2 = {{ kind = "normal", mean = 8.0, sd = 1.4 }}
"""
GOOD_Q = '{ kind = "gamma", shape = 2.0, scale = 5.0 }'
GOOD_U = '{ kind = "normal", mean = 4.0, sd = 1.4 }'


@pytest.mark.parametrize(
    "changes, field, needle",
    [
        ({"u": '{ kind = "normal", mean = 4.0, sd = 1.4, low = nan }'}, "prior.u.low", "nan"),
        ({"q": '{ kind = "uniform", low = 0.0, high = inf }'}, "prior.q", "finite low and high"),
        ({"q": '{ kind = "uniform", low = 5.0, high = 1.0 }'}, "prior.q", "high > low"),
        ({"agent": "step = 80.0"}, "agent.step", "every heading"),
        ({"agent": "step = 2.0\nspeed = 0.001"}, "search.budget", "shorter than one move"),
    ],
)
def test_cross_field_errors_name_the_field_and_say_why(tmp_path, changes, field, needle):
    """Each names the field at fault (not the model or the distribution class) and says why."""
    values = {"agent": "", "q": GOOD_Q, "u": GOOD_U, **changes}
    path = tmp_path / "s.toml"
    path.write_text(BASE_TOML.format(**values))
    with pytest.raises(DceeInputError) as exc:
        load_scenario(str(path))
    assert exc.value.field == field and needle in exc.value.message


def test_the_base_of_those_cases_is_valid(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(BASE_TOML.format(agent="", q=GOOD_Q, u=GOOD_U))
    assert load_scenario(str(path)).unknown == "full"


def test_random_family_is_reproducible_covers_the_area_and_keeps_ranges_apart():
    from dcee.scenarios.builtin import RANDOM_RANGES, RANDOM_REPORTING_FROM

    a, b = load_scenario("random:17"), load_scenario("random:17")
    assert a.model_dump() == b.model_dump() and a.name == "random:17"
    # pinned values: the draw must not change across machines or releases (PCG64 is stable)
    assert (a.truth.x, a.truth.y, a.truth.phi) == (42.01, 2.99, 231.57)
    assert "tuning range" in a.description
    assert "reporting range" in load_scenario(f"random:{RANDOM_REPORTING_FROM}").description
    truths = [load_scenario(f"random:{k}").truth for k in range(1, 201)]
    for name, (low, high) in RANDOM_RANGES.items():
        values = np.array([getattr(t, name) for t in truths])
        assert values.min() >= low and values.max() <= high, name
        assert values.max() - values.min() > 0.8 * (high - low), name  # the whole range
    xy = np.array([(t.x, t.y) for t in truths])
    assert (xy < 4).any(axis=0).all() and (xy > 46).any(axis=0).all()  # near every edge
    s = load_scenario("random:5")
    assert s.prior["phi"].mean == s.truth.phi and s.agent.start == (2, 2, 4)


def test_random_start_keeps_the_source_and_draws_a_start():
    a, b = load_scenario("random:9"), load_scenario("random-start:9")
    assert a.truth == b.truth and b.agent.start != a.agent.start
    assert all(1 <= c <= 49 for c in b.agent.start[:2]) and b.agent.start[2] == 4


@pytest.mark.parametrize("name", ["random:0", "random:x", "random:-3", "random:1.5"])
def test_bad_random_names_are_user_errors(name):
    with pytest.raises(DceeInputError, match="scenario"):
        load_scenario(name)


def test_random_suites_keep_tuning_and_reporting_apart():
    from dcee.campaign.suites import SUITES

    tune = {int(n.split(":")[1]) for n in SUITES["random-tune"]["configs"]}
    report = {int(n.split(":")[1]) for n in SUITES["held-out"]["configs"]}
    assert len(report) == 200 and not tune & report
    assert max(tune) < 1000 <= min(report)


def test_expand_names_expands_integer_ranges_only():
    from dcee.scenarios import expand_names

    assert expand_names(["random:1000-1002", "paper:3"]) == [
        "random:1000",
        "random:1001",
        "random:1002",
        "paper:3",
    ]
    assert expand_names(["random:5-2", "my-file.toml", "lab:down-wind"]) == [
        "random:5-2",
        "my-file.toml",
        "lab:down-wind",
    ]


def test_one_angle_convention_checked_on_input():
    """phi: degrees in scenario files and on the command line (within ±360), radians in the
    Python API (within ±2π); a value in the wrong unit is refused with one line naming it."""
    import math

    from dcee.estimation.priors import Fixed, Normal, SourcePrior, Uniform
    from dcee.models.plume import PARAMETER_NAMES

    base = load_scenario("paper:1")
    with pytest.raises(DceeInputError, match=r"truth\.phi"):
        base.with_overrides(**{"truth.phi": 400.0})
    with pytest.raises(DceeInputError, match=r"prior.phi.sd: degrees in scenario files"):
        base.with_overrides(**{"unknown": "full", "prior.phi.sd": 500.0})
    full = base.with_overrides(unknown="full")
    assert full.make_prior().distributions[5].mean == pytest.approx(math.radians(base.truth.phi))

    dists = {name: Fixed(1.0) for name in PARAMETER_NAMES}
    dists["x"] = Uniform(0.0, 10.0)
    for phi, key in ((Fixed(90.0), "value"), (Normal(0.0, 20.0), "sd")):
        with pytest.raises(DceeInputError, match=rf"prior.phi.{key}: .*radians.*math.radians"):
            SourcePrior.from_dict({**dists, "phi": phi})
    SourcePrior.from_dict({**dists, "phi": Fixed(math.radians(90.0))})  # radians: accepted


def test_a_scenario_file_s_misspelt_section_is_named_before_what_it_leaves_missing(tmp_path):
    """``[agnet]`` for ``[agent]`` also leaves required sections missing; the line names the
    misspelling (the cause), and a section that is missing says so without echoing the file."""
    typo = tmp_path / "typo.toml"
    typo.write_text('name = "x"\n[agnet]\nstart = [1, 1, 1]\n')
    with pytest.raises(DceeInputError, match=r"did you mean 'agent'") as exc:
        load_scenario(str(typo))
    assert exc.value.field == "agnet"
    bare = tmp_path / "bare.toml"
    bare.write_text('name = "x"\n')
    with pytest.raises(DceeInputError, match=r"^volume: required: the scenario does not give it"):
        load_scenario(str(bare))
