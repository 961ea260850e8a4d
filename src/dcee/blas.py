"""One BLAS thread while dcee computes (issue 17).

OpenBLAS keeps its worker threads spinning for a while after every multi-threaded call. NumPy
sends a filter's small matrix products (the MCMC move's covariance and proposals, a weighted
mean) to BLAS, and on a machine with few cores the spinning threads then take the cores from
numba's threads in the kernels that follow: measured on this 2-core machine, an infotaxis
decision on Stone Soup's workload took 14.9 ms with OpenBLAS's default threads and 8.2 ms with
one. :func:`one_blas_thread` limits BLAS to one thread for the duration of a block (the
:class:`~dcee.searcher.Searcher` wraps ``tell`` and ``ask`` in it) and restores the caller's
setting afterwards; campaign worker processes, which are ours, use one thread throughout.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

_controller: Any = None
_whole_process = False  # set by limit_process_blas: nothing left to limit per block


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Limit BLAS libraries loaded in this process to one thread inside the block."""
    global _controller
    if _whole_process:
        # threadpoolctl's limit and restore cost 0.1 ms per block, twice per step of a search
        yield
        return
    if _controller is None:
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController().select(user_api="blas")
    if all(lib.num_threads == 1 for lib in _controller.lib_controllers):
        # already one thread (a caller's limit, or a single-threaded build): asking the
        # libraries costs a microsecond, limiting and restoring 8-50 µs per block
        yield
        return
    with _controller.limit(limits=1):
        yield


def limit_process_blas() -> None:
    """One BLAS thread for the rest of this process (campaign workers: one search per core)."""
    from threadpoolctl import threadpool_limits

    global _whole_process
    threadpool_limits(limits=1, user_api="blas")
    _whole_process = True
