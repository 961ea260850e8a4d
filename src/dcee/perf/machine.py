"""What a timing was taken on, and whether anything else ran beside it.

Timings on a shared machine swing 3-5× from day to day, and a process running beside a timed
comparison slows its two sides differently, so every stored timing carries the machine, the
versions of the code and libraries it ran, and the load during the run
(:class:`LoadMonitor`): the cores that *other* processes used on average while it ran, read
from the kernel's CPU counters (``/proc/stat``) less this process's own CPU time. A run with
other processes using more than :data:`IDLE_OTHER_CORES` cores on average is marked shared.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import os
import platform
import resource
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from dcee.errors import DceeInputError
from dcee.io import write_json
from dcee.provenance import code_version

IDLE_OTHER_CORES = 0.25
"""Cores other processes may use on average during a run still called idle (a desktop's or a
CI runner's background; one busy process beside the run is a whole core)."""

LIBRARIES = ("numpy", "numba", "llvmlite", "scipy", "stonesoup")


def cpu_identity(cpuinfo: str | None = None) -> dict[str, Any]:
    """The CPU a timing ran on, from ``/proc/cpuinfo`` (Linux; ``cpuinfo`` its text, for
    tests): ``cpu_model`` (its model name), ``vector_bits`` (the widest SIMD its flags offer:
    512 with AVX-512F, 256 with AVX2, 128 with SSE2; a ratio can differ between machines by
    it) and ``cache`` (its last-level cache as the kernel reports it). Empty where there is
    no such file."""
    if cpuinfo is None:
        path = Path("/proc/cpuinfo")
        try:
            cpuinfo = path.read_text(errors="replace") if path.exists() else ""
        except OSError:
            cpuinfo = ""
    fields: dict[str, str] = {}
    for line in cpuinfo.splitlines():
        key, sep, value = line.partition(":")
        if sep and key.strip() not in fields:
            fields[key.strip()] = value.strip()
    if not fields:
        return {}
    flags = set(fields.get("flags", "").split())
    widths = (("avx512f", 512), ("avx2", 256), ("sse2", 128))
    bits = next((width for flag, width in widths if flag in flags), None)
    out: dict[str, Any] = {"cpu_model": fields.get("model name", "")}
    if bits is not None:
        out["vector_bits"] = bits
    if "cache size" in fields:
        out["cache"] = fields["cache size"]
    return out


def boot_id(path: Path = Path("/proc/sys/kernel/random/boot_id")) -> str | None:
    """The first 8 hex digits of the kernel's boot id (Linux), new at every boot: it tells
    runs on one booted machine from runs on another (two cloud VMs of one type report the
    same CPU, cores and cache). None where there is no such file."""
    try:
        return path.read_text().strip().replace("-", "")[:8] or None
    except OSError:
        return None


def machine_identity(machine: dict[str, Any]) -> str:
    """One line naming the machine of a stored :func:`machine_record`: CPU model, cores, SIMD
    width, numpy and numba versions, and the boot (:func:`boot_id`) where it was recorded."""
    versions = machine.get("versions", {})
    cpu = machine.get("cpu_model") or machine.get("processor") or machine.get("machine", "")
    parts = [cpu, f"{machine.get('cpus')} CPUs"]
    if machine.get("vector_bits"):
        parts.append(f"{machine['vector_bits']}-bit SIMD")
    parts += [f"{k} {versions[k]}" for k in ("numpy", "numba") if k in versions]
    if machine.get("boot"):
        parts.append(f"boot {machine['boot']}")
    return ", ".join(p for p in parts if p)


def machine_record() -> dict[str, Any]:
    """The machine and the software a timing ran on: CPU count, architecture, processor,
    the boot (:func:`boot_id`), Python, numba's thread count, library versions (absent ones
    omitted) and the code version (:func:`dcee.provenance.code_version`)."""
    import numba

    versions = {}
    for name in LIBRARIES:
        try:
            versions[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            continue
    return {
        "cpus": os.cpu_count(),
        "machine": platform.machine(),
        "processor": platform.processor() or platform.uname().processor,
        **cpu_identity(),
        "boot": boot_id(),
        "python": platform.python_version(),
        "numba_threads": int(numba.get_num_threads()),
        "versions": versions,
        "code": code_version(),
    }


def _busy_seconds() -> float | None:
    """CPU seconds all processors have spent busy since boot (``/proc/stat``: user, nice,
    system, irq, softirq, steal), or None where the file does not exist."""
    path = Path("/proc/stat")
    if not path.exists():
        return None
    fields = path.read_text().split("\n", 1)[0].split()[1:]
    user, nice, system, _idle, _iowait, irq, softirq, steal = (int(v) for v in fields[:8])
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def _own_seconds() -> float:
    """CPU seconds this process and its finished children have used."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


class LoadMonitor:
    """``with LoadMonitor() as load: ...`` then ``load.record()``: the wall time, the cores
    this process used and the cores every other process used on average during the block,
    and whether the machine counts as idle (other processes below :data:`IDLE_OTHER_CORES`)."""

    def __enter__(self) -> LoadMonitor:
        self.started = datetime.now(UTC)
        self._wall = time.perf_counter()
        self._busy = _busy_seconds()
        self._own = _own_seconds()
        self._load_start = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
        self._result: dict[str, Any] | None = None
        return self

    def __exit__(self, *exc: object) -> None:
        wall = time.perf_counter() - self._wall
        busy = _busy_seconds()
        own = _own_seconds() - self._own
        other = None
        if busy is not None and self._busy is not None and wall > 0:
            other = max(0.0, (busy - self._busy - own) / wall)
        self._result = {
            "started": self.started.isoformat(timespec="seconds"),
            "wall_seconds": wall,
            "own_cores": own / wall if wall > 0 else None,
            "other_cores": other,
            "loadavg_1min_start": self._load_start,
            "loadavg_1min_end": os.getloadavg()[0] if hasattr(os, "getloadavg") else None,
            "idle": None if other is None else other < IDLE_OTHER_CORES,
        }

    def record(self) -> dict[str, Any]:
        if self._result is None:
            raise RuntimeError("LoadMonitor.record() before the block ended")
        return self._result


def load_warning(load: dict[str, Any]) -> str | None:
    """One line for a run that was not idle (None when it was, or could not be told)."""
    if load.get("idle") is not False:
        return None
    return (
        f"other processes used {load['other_cores']:.1f} cores on average during this run: "
        "its times are marked shared; rerun with nothing else running for numbers to publish"
    )


def alternation_args(argv: list[str] | None, description: str, rounds: int) -> argparse.Namespace:
    """The options of a timing that alternates two code versions: ``--before`` (the commit,
    required), ``--rounds`` (≥ 1; default ``rounds``) and ``--json`` (a file in an existing
    folder), checked before any work; :class:`DceeInputError` naming the option otherwise."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--before", required=True, help="the commit to compare with")
    ap.add_argument("--rounds", type=int, default=rounds)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    if args.json is not None and not args.json.parent.is_dir():
        raise DceeInputError("--json", f"no folder {args.json.parent}")
    if args.rounds < 1:
        raise DceeInputError("--rounds", f"must be ≥ 1, got {args.rounds}")
    return args


@contextmanager
def code_at(root: Path, commit: str) -> Iterator[Path]:
    """``with code_at(root, commit) as src:`` the ``src`` folder of ``commit`` of the git
    repository ``root``, checked out in a temporary worktree that is removed afterwards: the
    "before" side of a timing that alternates two code versions (``studies/*_speedup.py``,
    ``studies/demo_decision.py``). :class:`DceeInputError` (``--before``) when git cannot
    check it out."""
    work = Path(tempfile.mkdtemp())
    tree = work / "before"
    git = ["git", "-C", str(root), "worktree"]
    made = subprocess.run(
        [*git, "add", "--detach", str(tree), commit], capture_output=True, text=True
    )
    if made.returncode != 0:
        shutil.rmtree(work, ignore_errors=True)
        first = (made.stderr.strip().splitlines() or ["git worktree add failed"])[0]
        raise DceeInputError("--before", f"{commit}: {first}")
    try:
        yield tree / "src"
    finally:
        subprocess.run([*git, "remove", "--force", str(tree)], capture_output=True)
        shutil.rmtree(work, ignore_errors=True)


def package_env(src: Path, **extra: str) -> dict[str, str]:
    """The environment of a process that runs the package under ``src`` (another version's,
    for a timing in alternation): this one's, with ``src`` first on the path and without the
    compiled-kernel cache this process chose (``NUMBA_CACHE_DIR``, and the locator older
    versions cannot import): each version files its own kernels. Without the vector width
    this process chose either (:mod:`dcee.kernel_target`; one the user set stays): each
    version compiles as it would on its own, so a timing against an older version measures
    what updating gives."""
    from dcee import kernel_target

    dropped = {*KERNEL_CACHE_VARIABLES, kernel_target.SET_BY_DCEE_ENV}
    if kernel_target.set_by_dcee():
        dropped.add("NUMBA_CPU_FEATURES")
    env = {k: v for k, v in os.environ.items() if k not in dropped}
    return {**env, **extra, "PYTHONPATH": str(src)}


KERNEL_CACHE_VARIABLES = ("NUMBA_CACHE_DIR", "NUMBA_CACHE_LOCATOR_CLASSES")
"""What :mod:`dcee.kernel_cache` sets for this process's own source."""


def json_from_package(src: Path, code: str) -> Any:
    """Run ``python -c code`` in a fresh process with the package under ``src`` first on the
    path (:func:`package_env`); the JSON of the last line it prints."""
    import json
    import sys

    env = package_env(src)
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def alternate_versions(
    root: Path,
    before: str,
    timed: Callable[[Path], Any],
    rounds: int,
    report: Callable[[str, int, Any], None] | None = None,
) -> tuple[dict[str, list[Any]], dict[str, Any]]:
    """Time two code versions in alternation: ``timed(src)`` with the package of commit
    ``before`` (:func:`code_at`) and with ``root``'s own ``src``, once each uncounted (it
    compiles the kernels), then ``rounds`` times each in turn, ``report(side, round, result)``
    after each. Returns ({"before": [...], "after": [...]}, the load beside the counted runs,
    :meth:`LoadMonitor.record`). :class:`DceeInputError` when ``before`` cannot be checked
    out."""
    runs: dict[str, list[Any]] = {"before": [], "after": []}
    with code_at(root, before) as old:
        sides = {"before": old, "after": root / "src"}
        for src in sides.values():
            timed(src)
        with LoadMonitor() as load:
            for r in range(rounds):
                for side, src in sides.items():
                    runs[side].append(timed(src))
                    if report is not None:
                        report(side, r, runs[side][-1])
    return runs, load.record()


def alternate_code(
    root: Path,
    argv: list[str] | None,
    description: str,
    code: str,
    rounds: int,
    report: Callable[[str, int, Any], None] | None = None,
) -> tuple[argparse.Namespace, dict[str, list[Any]], dict[str, Any]]:
    """A timing study's whole alternation: its options (:func:`alternation_args`), then
    :func:`alternate_versions` with ``python -c code`` run by each version
    (:func:`json_from_package`, the JSON of its last line). Returns (the options, the runs,
    the load); :class:`DceeInputError` naming a bad option or commit."""
    args = alternation_args(argv, description, rounds)
    runs, load = alternate_versions(
        root, args.before, lambda src: json_from_package(src, code), args.rounds, report
    )
    return args, runs, load


def store_timing(path: Path | None, load: dict[str, Any], **fields: Any) -> None:
    """Print :func:`load_warning`'s line for a run that was not idle, and write ``path`` (JSON;
    None: nothing): the machine (:func:`machine_record`), the ``load`` beside the run
    (:meth:`LoadMonitor.record`) and ``fields``."""
    if warning := load_warning(load):
        print(warning)
    if path is not None:
        write_json(path, {"machine": machine_record(), "load": load, **fields})


__all__ = [
    "IDLE_OTHER_CORES",
    "LoadMonitor",
    "alternate_versions",
    "alternation_args",
    "code_at",
    "cpu_identity",
    "json_from_package",
    "load_warning",
    "machine_identity",
    "machine_record",
    "package_env",
    "store_timing",
]
