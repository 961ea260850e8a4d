"""The load beside a timing (dcee.perf.machine): a process spinning next to the timed block is
seen as other processes' cores, this process's own work as its own, and the stored speed tables
mark a run that was not idle."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from dcee.perf.machine import IDLE_OTHER_CORES, LoadMonitor, load_warning, machine_record
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


def test_the_speed_table_marks_a_shared_run():
    timed = _script("publish_tables")._timed
    machine = {"cpus": 2, "code": {"commit": "0123456789abcdef"}}
    shared = {"started": "2026-11-26T16:00:00+00:00", "other_cores": 1.3, "idle": False}
    idle = {"started": "2026-11-26T16:00:00+00:00", "other_cores": 0.05, "idle": True}
    assert timed({"machine": machine, "load": shared}) == (
        "2026-11-26, 2 CPUs, **shared** (other processes 1.3 cores), `0123456`"
    )
    assert timed({"machine": machine, "load": idle}) == "2026-11-26, 2 CPUs, idle, `0123456`"
    assert load_warning(idle) is None and IDLE_OTHER_CORES < 1
