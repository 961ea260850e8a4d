"""`dcee perf`: the table and the JSON contract (timings themselves are not asserted here: the
machine is shared; targets are checked by running the command, see docs/performance.md)."""

import json
import sys

import numpy as np

from tests.helpers import run_cli


def test_perf_quick_writes_every_standard_workload(tmp_path, capsys):
    path = tmp_path / "perf.json"
    code, stdout, err = run_cli(["perf", "--quick", "--json", str(path)], capsys)
    assert code == 0, err
    data = json.loads(path.read_text())
    by_name = {w["name"]: w for w in data["workloads"]}
    absolute = {"dcee-ms-decision-20k": 100.0, "filter-update-20k": 1.0}
    for name, target in absolute.items():
        w = by_name[name]
        assert w["target_ms"] == target and w["ratio_target"] is None
        assert w["median_ms"] > 0 and w["min"] <= w["median_ms"] <= w["max"]
        assert w["passed"] == (w["median_ms"] <= target)
        assert name in stdout
    # targets that are ratios to a reference timed in the same run: judged by the ratio alone
    ratios = {
        "dcee-decision-20k": ("floor", 1.5),
        "entrotaxis-decision-20k": ("floor", 1.5),
        "infotaxis-decision-20k": ("floor", 1.5),
        "resample-mcmc-500-readings-20k": ("filter-update", 76.0),
        "cli-help-startup": ("full-import", 0.35),
    }
    for name, (reference, bound) in ratios.items():
        w = by_name[name]
        assert w["target_ms"] is None and w["ratio_target"] == [reference, bound]
        assert w["passed"] == (w["ratio_to"][reference] <= bound)
        assert name in stdout
    assert "≤ 1.5× floor" in stdout
    for n in ("2k", "20k", "100k"):
        assert by_name[f"dcee-decision-{n}"]["median_ms"] > 0
    cl = by_name["dcee-cl-decision-20k"]
    ratio = cl["median_ms"] / by_name["dcee-decision-20k"]["median_ms"]
    assert cl["note"].startswith(f"{ratio:.2f}× the dcee decision in this run; ")
    # issue 46: the default (interpolated sums) and precision=single against the exact
    # double-precision decision, and the tree search against that exact decision, same run
    double = by_name["dcee-cl-double-decision-20k"]
    for name in ("dcee-cl-decision-20k", "dcee-cl-single-decision-20k"):
        w = by_name[name]
        assert w["ratio_to"]["dcee-cl-double-decision"] == w["median_ms"] / double["median_ms"]
    tree = by_name["dcee-mcts-decision-20k"]
    assert tree["ratio_target"] == ["dcee-cl-decision", 3.0]
    assert tree["ratio_to"]["dcee-cl-decision"] == tree["median_ms"] / double["median_ms"]
    # issue 17: decisions as ratios to the plain compiled loop and the NumPy reference, and the
    # move as a ratio to the update, each from medians timed in the same run
    floor, numpy_ref = by_name["floor-decision-20k"], by_name["numpy-decision-20k"]
    for name in ("dcee-decision-20k", "infotaxis-decision-20k"):
        w = by_name[name]
        assert w["ratio_to"]["floor"] == w["median_ms"] / floor["median_ms"]
        assert w["ratio_to"]["numpy"] == w["median_ms"] / numpy_ref["median_ms"]
        assert "the plain compiled loop" in w["note"]
    move = by_name["resample-mcmc-500-readings-20k"]
    assert move["ratio_to"]["filter-update"] == (
        move["median_ms"] / by_name["filter-update-20k"]["median_ms"]
    )
    mem = by_name["memory-dcee-decision-100k"]
    assert mem["unit"] == "MB" and 0 < mem["median"] < 200
    assert data["machine"]["cpus"] >= 1
    # what it ran on and beside: versions, the code, the load (dcee.perf.machine)
    assert data["machine"]["code"]["source_hash"] and "numba" in data["machine"]["versions"]
    load = data["load"]
    assert load["wall_seconds"] > 0 and load["idle"] in (True, False)
    assert (load["idle"] is False) == ("marked shared" in stdout.replace("\n", " "))


def test_compare_stonesoup_without_the_extra_is_a_clear_error(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "stonesoup", None)  # makes `import stonesoup...` fail
    for key in [k for k in sys.modules if k.startswith("stonesoup.")]:
        monkeypatch.setitem(sys.modules, key, None)
    code, _, err = run_cli(["perf", "--compare-stonesoup", "--decisions", "1"], capsys)
    assert code == 2
    assert err.strip().count("\n") == 0
    assert "stonesoup" in err.lower() and "dcee[bench]" in err


def test_compare_stonesoup_refuses_a_repeat_count_below_one(capsys):
    code, _, err = run_cli(["perf", "--compare-stonesoup", "--repeats", "0"], capsys)
    assert code == 2
    assert err.strip().count("\n") == 0 and "repeats" in err and ">= 1" in err


def test_compare_reports_the_median_run_of_several(monkeypatch):
    """--repeats: each run alternates fresh generators; the summary is the median over runs
    (the ratio the median of the runs' ratios), every run kept."""
    import itertools

    from dcee.perf import stonesoup_compare as sc

    ours = itertools.cycle([[1.0, 1.0, 9.0], [2.0, 2.0, 2.0], [0.5, 0.5, 0.5]])
    monkeypatch.setattr(sc, "stonesoup_decisions", lambda n: iter([50.0, 40.0, 60.0]))
    monkeypatch.setattr(sc, "dcee_decisions", lambda n: iter(next(ours)))
    result = sc.compare(3, repeats=3)
    assert [r["speedup"] for r in result["runs"]] == [50.0, 25.0, 100.0]
    assert result["speedup"] == 50.0 and result["speedup_range"] == [25.0, 100.0]
    assert result["stonesoup_median_ms"] == 50.0 and result["dcee_infotaxis_median_ms"] == 1.0
    assert result["repeats"] == 3 and result["decisions"] == 3


def test_stone_soup_s_weights_are_read_from_its_log_weights():
    """The MCTS comparison reads a Stone Soup state's weights from ``log_weight``: its
    ``weight`` property caches an object array that every tree node's deepcopy then copies
    (it made Stone Soup's decisions several times dearer than its published example's)."""
    from dcee.perf.stonesoup_mcts import normalised_weights

    class State:
        log_weight = np.log(np.array([1.0, 3.0, 4.0])) - 50.0

        @property
        def weight(self):
            raise AssertionError("state.weight read")

    np.testing.assert_allclose(normalised_weights(State()), [0.125, 0.375, 0.5])


def test_the_machine_is_named_by_its_cpu_and_simd_width():
    """A stored timing names its CPU (model, SIMD width, cache) from /proc/cpuinfo, and the
    one-line identity `dcee perf` prints beside each ratio carries it with the versions."""
    from dcee.perf.machine import cpu_identity, machine_identity

    text = (
        "processor\t: 0\nmodel name\t: Example CPU 9000\ncache size\t: 512 KB\n"
        "flags\t\t: fpu sse2 avx avx2\n\nprocessor\t: 1\nmodel name\t: Example CPU 9000\n"
    )
    cpu = cpu_identity(text)
    assert cpu == {"cpu_model": "Example CPU 9000", "vector_bits": 256, "cache": "512 KB"}
    assert cpu_identity("") == {}
    line = machine_identity({"cpus": 2, **cpu, "versions": {"numpy": "2.4", "numba": "0.6"}})
    assert line == "Example CPU 9000, 2 CPUs, 256-bit SIMD, numpy 2.4, numba 0.6"
