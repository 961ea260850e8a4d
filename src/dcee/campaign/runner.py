"""Run every (configuration, repeat, strategy) search of a campaign, resumably.

Layout of a campaign folder (hive-style partitions, values URI-encoded: ``paper:1`` is
``paper%3A1``)::

    campaign.json                       settings, resolved scenarios, strategies, code versions
    runs/config=<config>/strategy=<strategy>/seed=<k>/
        summary.json                    written last: marks the search done
        config.json                     resolved scenario, strategy, seed, planner options, code
        steps.parquet                   per-step record
        posterior.npz                   final posterior sample (+ snapshots, repeat 0)
        error.json                      why a search failed (retried on the next run)

Every search folder is the one :meth:`dcee.runs.EpisodeResult.save` writes (``dcee run``
writes the same), so one reader serves both: :func:`dcee.analysis.results.load_summaries` and
``load_steps`` load a whole study in one call, and ``pyarrow.dataset.dataset(DIR / "runs",
format="parquet", partitioning="hive", exclude_invalid_files=True)`` reads every record with
config, strategy and seed columns.

Every file is written atomically by the worker that ran the search, so an interrupted or
killed driver loses only the searches in flight; the searches of a killed local worker are rerun
(see ``_local_results``). A search counts as done only when its summary parses
and names record and posterior files that exist with the recorded row count; anything else is
redone. Common random numbers: the seed of a search is its repeat index, and the seed alone
drives the truth's noise, so one (configuration, repeat) gives every strategy the same truth.

Code versions: ``campaign.json`` records the code (version, commit, dirty flag, source hash) of
every session that ran searches in it; resuming with different code is refused unless asked for
(``allow_code_change``), because a study that mixes code versions silently is not one study.
"""

from __future__ import annotations

import os
import signal
import time
import traceback
from collections.abc import Callable, Iterator
from typing import Any

from dcee.campaign.folder import Campaign, SearchTask, is_done
from dcee.errors import DceeInputError
from dcee.io import write_json


def run_search(task: SearchTask) -> dict[str, Any]:
    """Run one search and write its folder; returns {"status": "done"|"failed", ...}.

    Never raises for a failing search: the error is recorded where the result would be.
    """
    from dcee.runs import run_episode, snapshot_times
    from dcee.scenarios import Scenario
    from dcee.simulation import make_truth

    folder = task.folder
    t0 = time.perf_counter()
    try:
        scenario = Scenario.model_validate(task.scenario)
        truth = make_truth(scenario, task.seed)
        keep_snapshots = task.seed == 0  # repeat 0 feeds the report's comparison grid
        result = run_episode(
            scenario,
            task.strategy,
            task.seed,
            truth=truth,
            snapshot_at=snapshot_times(scenario.search.budget) if keep_snapshots else None,
        )
        result.summary.update(config=task.config, wall_seconds=time.perf_counter() - t0)
        result.save(folder, keep_snapshots=keep_snapshots)
        (folder / "error.json").unlink(missing_ok=True)
        return {"status": "done", "task": task, "seconds": result.summary["wall_seconds"]}
    except Exception as exc:  # recorded, the campaign goes on
        error = {
            "config": task.config,
            "strategy": task.strategy,
            "seed": task.seed,
            "error": f"{type(exc).__name__}: {exc}",
            "traceback": traceback.format_exc(),
        }
        write_json(folder / "error.json", error)
        return {"status": "failed", "task": task, "error": error["error"]}


_STARTED: Any = None  # in a local worker: shared flags, set when a search starts
_POLL_SECONDS = 0.5  # the driver wakes at least this often (signals are handled when it wakes)


def _init_worker(started: Any = None, own_process: bool = False) -> None:
    """Worker processes: one numba thread each (parallel kernels degrade badly when several
    searches share the cores; one search per core is the efficient layout). The local workers
    are processes this module started, so their allocator is tuned and BLAS limited to one
    thread too (:mod:`dcee.allocator`, :mod:`dcee.blas`); a Dask cluster's workers are not ours
    to retune (their searches still limit BLAS inside each update and decision)."""
    import numba

    global _STARTED
    _STARTED = started
    numba.set_num_threads(1)
    if own_process:
        # Ctrl-C reaches the whole process group. The driver stops its workers itself
        # (_local_results); a worker that took the KeyboardInterrupt could take it anywhere, even
        # inside a finaliser (numba's, say), where Python prints a traceback and carries on.
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        from dcee.allocator import tune_allocator
        from dcee.blas import limit_process_blas

        tune_allocator()
        limit_process_blas()  # spinning OpenBLAS threads would take the other worker's core


def _run_marked(index: int, task: SearchTask, search: Callable[[SearchTask], dict]) -> dict:
    """Flag search ``index`` as started (so the driver knows which were in flight when a worker
    died), then run it."""
    _STARTED[index] = 1
    return search(task)


def _worker_lost(task: SearchTask) -> dict[str, Any]:
    error = "its worker process died while running it alone (out of memory? killed?)"
    write_json(
        task.folder / "error.json",
        {"config": task.config, "strategy": task.strategy, "seed": task.seed, "error": error},
    )
    return {"status": "failed", "task": task, "error": f"worker lost: {error}"}


def _local_results(
    tasks: list[SearchTask], workers: int, search: Callable[[SearchTask], dict] = run_search
) -> Iterator[dict[str, Any]]:
    """Run ``tasks`` on ``workers`` spawned processes and yield each result as it comes.

    A dead worker breaks a ``ProcessPoolExecutor``: every pending future fails with it and the
    other workers are stopped. So after a break the queued searches go to a fresh pool, and the
    ones that were in flight (shared flags set by the worker tell them apart from the queued
    ones) become suspects, each rerun alone on a pool of one: a suspect that kills its worker
    even alone is recorded as failed (it is what kills it: out of memory, say); the others were
    bystanders of an external kill and simply finish. A break with no search in flight and no
    result (a worker that cannot even start) fails what is left, so this always ends.
    """
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    # Not os.environ["NUMBA_NUM_THREADS"]: numba in *this* process re-reads it at its next
    # compilation and refuses a value different from its running pool. The initializer limits
    # each worker instead.
    ctx = mp.get_context("spawn")
    todo = list(range(len(tasks)))
    suspects: list[int] = []
    while todo or suspects:
        if suspects:
            batch, alone = [suspects.pop(0)], True
        else:
            batch, alone, todo = todo, False, []
        started = ctx.Array("b", len(tasks), lock=False)
        pool = ProcessPoolExecutor(
            max_workers=min(workers, len(batch)),
            mp_context=ctx,
            initializer=_init_worker,
            initargs=(started, True),
        )
        futures = {pool.submit(_run_marked, i, tasks[i], search): i for i in batch}
        lost: list[int] = []
        pending = set(futures)
        try:
            while pending:
                # a bounded wait: Python runs signal handlers only when the main thread wakes,
                # so this guarantees `kill` is answered within half a second whichever thread
                # the signal landed on (a driver that had been stopped and continued once kept
                # waiting after SIGTERM; not reproduced in a test; tests/test_campaign.py checks the
                # answer time)
                done, pending = wait(pending, timeout=_POLL_SECONDS, return_when=FIRST_COMPLETED)
                for fut in done:
                    i = futures[fut]
                    try:
                        yield fut.result()
                    except BrokenProcessPool:
                        lost.append(i)
                    except Exception as exc:  # not the search (it never raises): pickling, say
                        yield {"status": "failed", "task": tasks[i], "error": repr(exc)}
        except KeyboardInterrupt:
            # the workers ignore SIGINT: stop them now rather than wait for their searches
            # (a search writes its results atomically, so a killed one leaves nothing half done)
            for process in list((getattr(pool, "_processes", None) or {}).values()):
                process.terminate()
            raise
        finally:
            for f in futures:
                f.cancel()
            pool.shutdown(wait=True, cancel_futures=True)
        progressed = len(lost) < len(batch) or any(started[i] for i in lost)
        for i in sorted(lost):
            if (started[i] and alone) or not progressed:
                yield _worker_lost(tasks[i])
            elif started[i]:
                suspects.append(i)
            else:
                todo.append(i)


SCHEDULER_TIMEOUT = "10s"
"""How long connecting to a Dask scheduler may take before the campaign is refused."""


def connect_scheduler(scheduler: Any) -> tuple[Any, bool]:
    """(client, whether this call opened it) for a Dask scheduler address
    (``tcp://host:8786``) or a ``distributed.Client``; a missing ``distributed``, a malformed
    address or a scheduler that does not answer within :data:`SCHEDULER_TIMEOUT` is
    :class:`DceeInputError` (checked before a campaign writes anything)."""
    try:
        from distributed import Client
    except ImportError:
        raise DceeInputError(
            "scheduler", "dask.distributed is not installed: pip install 'dcee[distributed]'"
        ) from None
    if isinstance(scheduler, Client):
        return scheduler, False
    try:
        return Client(scheduler, timeout=SCHEDULER_TIMEOUT), True
    except (ValueError, TypeError, OSError, TimeoutError) as exc:
        raise DceeInputError(
            "scheduler",
            f"cannot connect to {scheduler!r} ({exc}); give a running Dask scheduler's address, "
            "e.g. tcp://host:8786",
        ) from None


def _dask_results(tasks: list[SearchTask], client: Any) -> Iterator[dict[str, Any]]:
    """Run ``tasks`` on a Dask cluster through ``client``. Dask itself reschedules the
    searches of a lost worker and gives up on one after its ``allowed-failures`` losses
    (``KilledWorker``)."""
    from distributed import as_completed

    client.run(_init_worker)
    futures = {client.submit(run_search, t, pure=False): t for t in tasks}
    try:
        for fut in as_completed(futures):
            try:
                yield fut.result()
            except Exception as exc:  # KilledWorker, a lost connection, ...
                yield {"status": "failed", "task": futures[fut], "error": repr(exc)}
    finally:
        client.cancel(list(futures))


def check_workers(workers: int | None, scheduler: Any = None) -> None:
    """:class:`DceeInputError` for a local worker count below 1, or one given with a
    scheduler (whose cluster has its own workers)."""
    if workers is not None and workers < 1:
        raise DceeInputError("workers", f"must be >= 1, got {workers}")
    if workers is not None and scheduler is not None:
        raise DceeInputError("workers", "give either --workers or --scheduler, not both")


def run_campaign(
    campaign: Campaign,
    workers: int | None = None,
    scheduler: Any = None,
    on_result: Callable[[dict[str, Any], int, int], None] | None = None,
) -> dict[str, int]:
    """Run the searches not yet done; returns counts {total, skipped, done, failed}.

    ``scheduler``: a Dask scheduler address (``tcp://host:8786``) or ``distributed.Client``;
    otherwise ``workers`` local processes (default: all cores). The campaign folder must be on a
    file system the Dask workers share.
    """
    check_workers(workers, scheduler)
    client, own = connect_scheduler(scheduler) if scheduler is not None else (None, False)
    try:
        campaign.prepare()
        tasks = campaign.tasks()
        todo = [t for t in tasks if not is_done(t)]
        counts = {"total": len(tasks), "skipped": len(tasks) - len(todo), "done": 0, "failed": 0}
        if not todo:
            return counts
        if client is not None:
            results = _dask_results(todo, client)
        else:
            results = _local_results(todo, workers or os.cpu_count() or 1)
        for res in results:
            counts[res["status"]] += 1
            if on_result is not None:
                on_result(res, counts["done"] + counts["failed"], len(todo))
        return counts
    finally:
        if own:
            client.close()
