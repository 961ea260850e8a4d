import json
import subprocess
import sys

import pandas as pd
import pytest

from tests.helpers import SUMMARY_KEYS, run_cli


def test_run_writes_all_outputs(tmp_path, capsys):
    out = tmp_path / "r"
    argv = "run --scenario lab:downwind --strategy dcee --seed 1 --particles 1000 --budget 60"
    code, stdout, _ = run_cli(
        [*argv.split(), "--out", str(out), "--json", str(tmp_path / "s.json"), "--quiet"], capsys
    )
    assert code == 0, stdout
    summary = json.loads((tmp_path / "s.json").read_text())
    assert SUMMARY_KEYS <= set(summary)
    assert summary["scenario"] == "lab:downwind" and summary["seed"] == 1
    steps = pd.read_parquet(out / "steps.parquet")
    assert len(steps) == summary["steps"] + 1
    config = json.loads((out / "config.json").read_text())
    assert config["scenario"]["search"]["particles"] == 1000
    assert (out / "figure.png").stat().st_size > 10_000
    assert not list(out.glob(".*"))  # no temporary files left behind


def test_animation(tmp_path, capsys):
    out = tmp_path / "a"
    code, _, _ = run_cli(
        [
            *"run --scenario lab:upwind --particles 300 --budget 30 --out".split(),
            str(out),
            *"--animate --no-figure -q".split(),
        ],
        capsys,
    )
    assert code == 0
    assert (out / "animation.gif").read_bytes()[:3] == b"GIF"


BAD = [
    (["--particles", "-5"], "search.particles"),
    (["--strategy", "nope"], "strategy"),
    (["--strategy", "dcee-cl:reach=-2"], "reach"),
    (["--strategy", "dcee:hypotheses"], "strategy"),
    (["--budget", "nan"], "search.budget"),
    (["--hypotheses", "0"], "search.hypotheses"),
    (["--seed", "-1"], "seed"),
    (["--likelihood", "gauss"], "likelihood"),
    (["--set", "estimator.log_sd=-1"], "estimator.log_sd"),
    (["--set", "nonsense"], "set"),
    (["--set", "estimator.nope=1"], "estimator.nope"),
    (["--set", "sensor.average=9"], "sensor.average"),
    (["--set", "sensor.max_reading=1e-9"], "sensor.max_reading"),
]


@pytest.mark.parametrize("extra,field", BAD)
def test_bad_options_exit_2_with_one_line(tmp_path, capsys, extra, field):
    out = tmp_path / "bad"
    code, _, err = run_cli(["run", "--scenario", "paper:1", "--out", str(out), *extra], capsys)
    assert code == 2
    assert err.count("\n") == 1 and field in err and "Traceback" not in err
    assert not out.exists()


def test_bad_scenarios_exit_2(tmp_path, capsys):
    bad_toml = tmp_path / "bad.toml"
    bad_toml.write_text("[volume\nlow = 1")
    outside = tmp_path / "outside.toml"
    outside.write_text(
        "[volume]\nlow=[0,0,0]\nhigh=[20,20,3]\n"
        "[truth]\nx=25\ny=5\nz=1\nq=2\nu=3\nphi=90\nzeta1=1\nzeta2=8\n[agent]\nstart=[1,1,2]\n"
    )
    for scenario, needle in [
        ("paper:99", "unknown built-in"),
        (str(tmp_path / "no.toml"), "no such file"),
        (str(bad_toml), "malformed TOML"),
        (str(outside), "outside the search volume"),
    ]:
        code, _, err = run_cli(
            ["run", "--scenario", scenario, "--out", str(tmp_path / "o")], capsys
        )
        assert code == 2 and needle in err and err.count("\n") == 1
    code, _, err = run_cli(["run", "--bogus"], capsys)
    assert code == 2 and "bogus" in err


def test_scenarios_and_show(capsys):
    code, out, _ = run_cli(["scenarios"], capsys)
    assert code == 0 and out.count("\n") == 26 and "lab:upwind" in out
    code, out, _ = run_cli(["show", "paper:3"], capsys)
    assert code == 0 and json.loads(out)["truth"]["y"] == 40.0


def test_console_script_is_installed():
    res = subprocess.run(
        [sys.executable, "-m", "dcee.cli", "show", "nope:1"], capture_output=True, text=True
    )
    assert res.returncode == 2 and res.stderr.startswith("dcee: error: scenario")


def test_strategies_lists_the_registry_with_options(capsys):
    from dcee.planning import names

    code, out, _ = run_cli(["strategies"], capsys)
    assert code == 0
    listed = [line.split()[0] for line in out.splitlines() if not line.startswith(" ")]
    assert listed == names() and "reach=8.0" in out


def test_a_planner_spec_runs_and_is_recorded(tmp_path, capsys):
    argv = "run --scenario paper:1 --strategy dcee-cl:reach=4:hypotheses=8 --particles 500"
    code, out, _ = run_cli(
        [
            *argv.split(),
            "--budget",
            "20",
            "-q",
            "--json",
            str(tmp_path / "s.json"),
            "--out",
            str(tmp_path / "o"),
        ],
        capsys,
    )
    assert code == 0, out
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["strategy"] == "dcee-cl:reach=4:hypotheses=8"
    assert summary["planner_options"]["reach"] == 4.0
    assert summary["planner_options"]["n_hypotheses"] == 8
