"""Whether a search's particles fit this machine's memory, checked before the search starts.

``search.particles`` may be set up to ten million, which a workstation holds and a robot's
computer does not: a search that outgrows the memory is killed by the system part way through,
with no message. :func:`check_search_memory` estimates a search's peak memory from its particle
count and refuses, in one line naming the setting, one that would not fit in the memory the
system reports available (``MemAvailable`` of ``/proc/meminfo``; elsewhere nothing is checked).

The estimate is measured, not derived (2026-12-05, ``paper:1``, peak resident memory; ``bash
studies/run.sh search-memory`` stores it in docs/results/perf/search-memory.json and
``tests/test_search_memory.py`` holds the estimate above every stored peak). A process with
its compiled kernels loaded holds 0.3 GB at 2 × 10⁴ particles; at 10⁶: ``mpc`` 0.59 GiB, ``dcee-cl``
1.07 GiB (4 % more after 40 decisions: the position terms are capped), ``infotaxis`` 1.05 GiB,
``dcee-mcts`` 1.42 GiB, the fluctuation likelihood 1.23 GiB, two sources (a bank of three
filters) 1.68 GiB. :data:`BYTES_PER_PARTICLE` is above the dearest single-source planner; a bank
for K sources counts K times as many.
"""

from __future__ import annotations

from pathlib import Path

from dcee.errors import DceeInputError

BASE_BYTES = 400 * 2**20
"""The process before any particle: Python, NumPy and the compiled kernels (0.3 GB
measured at 2 × 10⁴ particles)."""

BYTES_PER_PARTICLE = 1200
"""Peak bytes per particle of one filter and its planner (the dearest measured: ``dcee-mcts``
at 10⁶ particles, 1.1 kB; module docstring)."""


def available_bytes(meminfo: Path = Path("/proc/meminfo")) -> int | None:
    """Bytes the system says it can give new work without swapping (``MemAvailable``); None
    where it does not say (not Linux, an old kernel)."""
    try:
        for line in meminfo.read_text(encoding="ascii").splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def search_bytes(particles: int, sources: int = 1) -> int:
    """Estimated peak bytes of one search process with ``particles`` per filter and a bank for
    up to ``sources`` releases."""
    return BASE_BYTES + int(particles) * BYTES_PER_PARTICLE * max(1, int(sources))


def check_search_memory(
    particles: int,
    sources: int = 1,
    processes: int = 1,
    field: str = "search.particles",
    available: int | None = None,
) -> None:
    """:class:`DceeInputError` naming ``field`` when ``processes`` searches of ``particles``
    particles (a bank for up to ``sources`` releases) would need more memory than is available
    (``available`` bytes, default :func:`available_bytes`; nothing is checked where that is
    unknown)."""
    free = available_bytes() if available is None else available
    if free is None:
        return
    need = search_bytes(particles, sources) * max(1, int(processes))
    if need <= free:
        return
    each = f" in each of {processes} processes" if processes > 1 else ""
    raise DceeInputError(
        field,
        f"{particles:,} particles{each} need about {need / 2**30:.1f} GiB, more than the "
        f"{free / 2**30:.1f} GiB this machine has available; use fewer"
        + (" particles or workers" if processes > 1 else ""),
    )
