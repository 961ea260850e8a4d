"""The search's memory estimate and its refusal before any work (dcee.search_memory)."""

from __future__ import annotations

import pytest

from dcee import search_memory
from dcee.errors import DceeInputError
from tests.helpers import run_cli

GIB = 2**30


def test_the_estimate_by_hand_and_the_refusal_names_the_setting():
    # 10^6 particles, one source: 400 MiB + 1.2 GB (the measured peaks are 0.61-1.49 GB)
    assert search_memory.search_bytes(10**6) == 400 * 2**20 + 1_200_000_000
    assert search_memory.search_bytes(10**6, sources=3) == 400 * 2**20 + 3_600_000_000
    search_memory.check_search_memory(10**6, available=2 * GIB)  # fits
    with pytest.raises(DceeInputError, match=r"1,000,000 particles need about 1\.5 GiB") as e:
        search_memory.check_search_memory(10**6, available=1 * GIB)
    assert e.value.field == "search.particles" and "\n" not in str(e.value)
    with pytest.raises(DceeInputError, match=r"in each of 4 processes.*particles or workers"):
        search_memory.check_search_memory(10**6, processes=4, available=4 * GIB)


def test_available_memory_is_read_from_meminfo(tmp_path):
    meminfo = tmp_path / "meminfo"
    meminfo.write_text("MemTotal:       24000000 kB\nMemAvailable:    1000 kB\n")
    assert search_memory.available_bytes(meminfo) == 1000 * 1024
    meminfo.write_text("MemTotal:       24000000 kB\n")  # an old kernel: nothing checked
    assert search_memory.available_bytes(meminfo) is None
    assert search_memory.available_bytes(tmp_path / "missing") is None


@pytest.mark.parametrize("command", ["run", "bench"])
def test_a_search_that_would_not_fit_is_one_line_exit_2_before_any_work(
    tmp_path, capsys, monkeypatch, command
):
    monkeypatch.setattr(search_memory, "available_bytes", lambda: 1 * GIB)
    out = tmp_path / "out"
    if command == "run":
        args = ["run", "--scenario", "paper:1", "--particles", "1000000", "--out", str(out)]
    else:
        args = ["bench", "--suite", "smoke", "--particles", "300000", "--workers", "2"]
        args += ["--strategies", "mpc", "--out", str(out)]
    code, _, err = run_cli(args, capsys)
    assert code == 2 and err.count("\n") == 1 and "error: search.particles:" in err
    assert not out.exists()


def test_the_estimate_covers_every_stored_measurement_and_is_not_far_above_it():
    """docs/results/perf/search-memory.json (``python studies/search_memory.py``): peak memory
    of ``dcee run`` by planner at 2 x 10^4 and 10^6 particles. The estimate must lie above each
    peak (a refusal never lets through what the system would kill) and at 10^6 particles
    within 3 times it (nor refuse what fits with room to spare; mpc, the cheapest, needs 2.6)."""
    import json
    from pathlib import Path

    doc = json.loads(
        (Path(__file__).parent.parent / "docs/results/perf/search-memory.json").read_text()
    )
    assert len(doc["runs"]) >= 12
    for run in doc["runs"]:
        estimate = search_memory.search_bytes(run["particles"], run["sources"])
        assert estimate >= run["peak_bytes"], run
        if run["particles"] >= 10**6:
            assert estimate <= 3 * run["peak_bytes"], run
