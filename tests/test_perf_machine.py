"""The load beside a timing (dcee.perf.machine): a process spinning next to the timed block is
seen as other processes' cores, this process's own work as its own, and the stored speed tables
mark a run that was not idle."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

from dcee.errors import DceeInputError
from dcee.perf.machine import (
    IDLE_OTHER_CORES,
    KERNEL_CACHE_VARIABLES,
    LoadMonitor,
    alternate_versions,
    alternation_args,
    code_at,
    load_warning,
    machine_record,
    package_env,
    store_timing,
)
from tests.test_study_tables import _script

pytestmark = pytest.mark.skipif(
    not sys.platform.startswith("linux"), reason="/proc/stat is Linux's"
)

SPIN = "import time\nt = time.perf_counter()\nwhile time.perf_counter() - t < 3: pass\n"


def test_a_process_spinning_beside_the_block_is_other_load():
    spinner = subprocess.Popen([sys.executable, "-c", SPIN])
    try:
        time.sleep(0.3)  # the spinner is running
        with LoadMonitor() as load:
            time.sleep(1.0)  # this process idles
        record = load.record()
    finally:
        spinner.kill()
        spinner.wait()
    # one core busy beside an idle block (the machine's own background only adds to it)
    assert record["other_cores"] > 0.6
    assert record["own_cores"] < 0.3
    assert record["idle"] is False
    assert "1." in load_warning(record) or "2." in load_warning(record)


def test_own_work_is_not_counted_as_other_load():
    with LoadMonitor() as load:
        t = time.perf_counter()
        while time.perf_counter() - t < 1.0:
            pass
    record = load.record()
    assert record["own_cores"] > 0.3  # a core, less what other processes take of it
    assert 0.9 < record["wall_seconds"] < 3.0


def test_record_before_the_block_ends_is_refused():
    monitor = LoadMonitor().__enter__()
    with pytest.raises(RuntimeError):
        monitor.record()


def test_machine_record_names_the_code_and_libraries():
    m = machine_record()
    assert m["cpus"] >= 1 and "numpy" in m["versions"] and "numba" in m["versions"]
    assert set(m["code"]) >= {"version", "commit", "source_hash"}


def test_the_boot_tells_two_machines_of_one_type_apart(tmp_path):
    from dcee.perf.machine import boot_id, machine_identity

    path = tmp_path / "boot_id"
    path.write_text("e14d7531-6620-4ab4-a7ea-63a07c0078d5\n")
    assert boot_id(path) == "e14d7531"
    assert boot_id(tmp_path / "missing") is None
    one = {"cpu_model": "Xeon", "cpus": 2, "versions": {"numpy": "2.4.6"}}
    assert machine_identity(one) == "Xeon, 2 CPUs, numpy 2.4.6"  # a record from before
    assert machine_identity({**one, "boot": "e14d7531"}).endswith("numpy 2.4.6, boot e14d7531")


def test_the_speed_table_marks_a_shared_run():
    _script("publish_tables")  # puts the studies package on the path, as the script does
    from studies.tables.performance import _timed as timed

    machine = {"cpus": 2, "code": {"commit": "0123456789abcdef"}}
    shared = {"started": "2026-11-26T16:00:00+00:00", "other_cores": 1.3, "idle": False}
    idle = {"started": "2026-11-26T16:00:00+00:00", "other_cores": 0.05, "idle": True}
    assert timed({"machine": machine, "load": shared}) == (
        "2026-11-26, 2 CPUs, **shared** (other processes 1.3 cores), `0123456`"
    )
    assert timed({"machine": machine, "load": idle}) == "2026-11-26, 2 CPUs, idle, `0123456`"
    assert load_warning(idle) is None and IDLE_OTHER_CORES < 1


def test_code_at_checks_out_a_commit_and_removes_it():
    """The "before" side of an alternated timing: this repository's HEAD in a temporary
    worktree (its package present), gone afterwards; an unknown commit is a one-line input
    error naming --before, with nothing left behind."""
    root = Path(__file__).resolve().parent.parent
    with code_at(root, "HEAD") as src:
        assert (src / "dcee" / "perf" / "machine.py").is_file()
    assert not src.exists()
    listed = subprocess.run(["git", "-C", str(root), "worktree", "list"], capture_output=True,
                            text=True, check=True).stdout  # fmt: skip
    assert str(src.parent) not in listed
    with pytest.raises(DceeInputError, match="--before") as info:
        with code_at(root, "no-such-commit-anywhere"):
            pass
    assert "\n" not in str(info.value)


def test_store_timing_writes_the_machine_the_load_and_the_fields(tmp_path, capsys):
    shared = {"idle": False, "other_cores": 1.2, "started": "2026-11-29T10:00:00+00:00"}
    store_timing(tmp_path / "t.json", shared, before="abc", speedup=2.0)
    stored = json.loads((tmp_path / "t.json").read_text())
    assert stored["load"] == shared and stored["before"] == "abc" and stored["speedup"] == 2.0
    assert stored["machine"]["cpus"] >= 1
    assert capsys.readouterr().out.strip() == load_warning(shared)
    store_timing(None, {"idle": True}, before="abc")  # nothing written, nothing said
    assert capsys.readouterr().out == ""


def test_alternation_args_checks_before_any_work(tmp_path):
    args = alternation_args(["--before", "abc", "--json", str(tmp_path / "t.json")], "d", 3)
    assert (args.before, args.rounds, args.json) == ("abc", 3, tmp_path / "t.json")
    for argv, field in (
        (["--before", "abc", "--rounds", "0"], "--rounds"),
        (["--before", "abc", "--json", str(tmp_path / "no" / "t.json")], "--json"),
    ):
        with pytest.raises(DceeInputError, match=field):
            alternation_args(argv, "d", 3)


def test_another_version_runs_without_this_process_s_kernel_cache(monkeypatch):
    """A process of another code version gets this one's environment with its package first on
    the path and without the kernel cache this process chose (an older version cannot import
    the locator it names: the perf recipe's move timing failed so)."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/tmp/ours")
    monkeypatch.setenv("NUMBA_CACHE_LOCATOR_CLASSES", "dcee.kernel_locator.PackageRelativeLocator")
    env = package_env(Path("/somewhere/src"), NUMBA_NUM_THREADS="1")
    assert env["PYTHONPATH"] == "/somewhere/src" and env["NUMBA_NUM_THREADS"] == "1"
    assert not set(KERNEL_CACHE_VARIABLES) & set(env)


def test_two_versions_alternate_round_by_round():
    """The uncounted first pass of each side, then before and after in turn, each reported."""
    root = Path(__file__).resolve().parents[1]
    seen: list[str] = []
    reported: list[tuple[str, int]] = []
    runs, load = alternate_versions(
        root, "HEAD", lambda src: seen.append(str(src)) or str(src), 2,
        lambda side, r, _: reported.append((side, r)),
    )  # fmt: skip
    assert reported == [("before", 0), ("after", 0), ("before", 1), ("after", 1)]
    assert len(seen) == 6 and runs["after"] == [str(root / "src")] * 2
    assert runs["before"][0] != runs["after"][0] and runs["before"][0].endswith("src")
    assert "other_cores" in load
