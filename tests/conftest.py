"""Shared fixtures, and one compute thread per test process when pytest-xdist runs the suite
on several processes (``scripts/test.sh`` runs it on two: one per core).

In an xdist worker, numba's and BLAS's thread pools hold one thread, in the worker and in every
process a test starts (a command, a page's snippets, a campaign's workers), through the
environment, set here before anything imports numba: two workers each running two threads on
two cores oversubscribe them, and idle pool threads spin-wait. Measured on the 2-core machine:
the suite in parallel took 312 s against 287 s in series while each worker ran two threads;
with the worker at one thread but the processes it starts at two, a page's snippets took 5-7 s
beside the other worker against 2 s alone, and the whole suite 159-171 s against 138 s with
one thread everywhere. The tests that need two threads start a process with two
(:func:`tests.helpers.run_with_numba_threads`)."""

from __future__ import annotations

import os

if os.environ.get("PYTEST_XDIST_WORKER"):
    for _name in (
        "NUMBA_NUM_THREADS",
        "OPENBLAS_NUM_THREADS",
        "OMP_NUM_THREADS",
        "MKL_NUM_THREADS",
    ):
        os.environ[_name] = "1"

import pytest

from dcee.models.sensor import Sensor


@pytest.fixture
def sensor() -> Sensor:
    return Sensor.paper_exact()
