"""dcee.blas.one_blas_thread: one BLAS thread inside the block, the caller's setting after it."""

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from dcee.blas import one_blas_thread


def _blas_threads() -> list[int]:
    return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]


def test_one_thread_inside_and_the_callers_setting_restored() -> None:
    np.ones((2, 2)) @ np.ones((2, 2))  # BLAS loaded
    if not _blas_threads():
        pytest.fail("no BLAS library found: numpy should bring one")
    with threadpool_limits(limits=2, user_api="blas"):
        with one_blas_thread():
            assert set(_blas_threads()) == {1}
        assert set(_blas_threads()) == {2}  # restored
        with threadpool_limits(limits=1, user_api="blas"):
            with one_blas_thread():  # already one: nothing to limit or restore
                assert set(_blas_threads()) == {1}
            assert set(_blas_threads()) == {1}
        assert set(_blas_threads()) == {2}
