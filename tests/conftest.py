"""Shared fixtures, and one compute thread per test process when pytest-xdist runs the suite
on several processes (``scripts/test.sh`` runs it on two: one per core)."""

from __future__ import annotations

import os

import pytest

from dcee.models.sensor import Sensor


def pytest_configure(config: pytest.Config) -> None:
    """In an xdist worker, numba's and BLAS's thread pools are sized to one thread: two workers
    each running two threads on two cores oversubscribe them, and the threads' spin-waiting made
    the suite slower in parallel than in series (measured: 312 s against 287 s). A test that
    needs two threads sets them itself (``numba.set_num_threads``); subprocesses keep the
    defaults."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return
    import numba
    from threadpoolctl import threadpool_limits

    numba.set_num_threads(1)
    config._dcee_blas_limit = threadpool_limits(limits=1)  # kept alive for the session


@pytest.fixture
def sensor() -> Sensor:
    return Sensor.paper_exact()
