"""Which vector width the compiled kernels use: the CPU's full width where it has AVX-512.

LLVM tunes code for Intel's AVX-512 cores to prefer 256-bit vectors (``prefer-256-bit``: on
Skylake servers a 512-bit instruction lowered the whole core's clock). The kernels here are
long loops of transcendental arithmetic (the plume's ``exp``, the sensor's ``erfc`` and ``log``
in :mod:`dcee.numeric`), where eight doubles a step instead of four pay: measured on this
project's 2-vCPU machine (an AVX-512 Xeon, LLVM names it ``rocketlake``), hot, one thread, the
vectorised ``exp`` over 8,000 values took 4.2 µs against 6.5 µs and the ``erfc`` 13.3 against
19.2 µs; the terms of 5 positions × 7,500 particles 219 against 259 µs, and an infotaxis
decision on Stone Soup's workload in alternation with Stone Soup 6-8 % less (docs/performance.md).

:func:`widen_vectors_when_numba_loads` (called by ``import dcee``, before anything imports
numba) sets ``NUMBA_CPU_FEATURES`` to the host's own features with ``-prefer-256-bit`` when
numba is first imported, on a CPU that has AVX-512 only; every other CPU compiles as before.
``DCEE_VECTOR_WIDTH=llvm`` keeps LLVM's choice; a ``NUMBA_CPU_NAME`` or ``NUMBA_CPU_FEATURES``
set by the user wins. numba files compiled kernels by the features they were compiled for, so
the two widths never share cached machine code.

Results: each particle's arithmetic is the same at either width (the same operations in the
same order); only the one-pass sums, which are reassociated into SIMD lanes
(:mod:`dcee.planning.one_stage_sums`), add in another order, a change in the last bits.

Standard library only at import (``dcee --help`` does not load llvmlite).
"""

from __future__ import annotations

import importlib.abc
import os
import sys
from collections.abc import Sequence
from types import ModuleType

WIDTH_ENV = "DCEE_VECTOR_WIDTH"
"""``full`` (the default): 512-bit vectors where the CPU has AVX-512; ``llvm``: LLVM's tuning."""
WIDTHS = ("full", "llvm")

SET_BY_DCEE_ENV = "DCEE_SET_NUMBA_CPU_FEATURES"
"""Where a dcee process notes the ``NUMBA_CPU_FEATURES`` value it set itself, beside it: a child
process inherits both, and one whose ``NUMBA_CPU_FEATURES`` equals the note knows that no user
set it (the child's own ``DCEE_VECTOR_WIDTH`` then decides, as in its parent)."""


def set_by_dcee() -> bool:
    """Whether this process's ``NUMBA_CPU_FEATURES`` is dcee's own choice (it equals the note,
    :data:`SET_BY_DCEE_ENV`), not the user's: a process that runs another version of the
    package (:func:`dcee.perf.machine.package_env`) drops it, so that each version compiles as
    it would on its own."""
    note = os.environ.get(SET_BY_DCEE_ENV)
    return note is not None and os.environ.get("NUMBA_CPU_FEATURES") == note


def forget_inherited_choice() -> bool:
    """Remove from this process's environment a ``NUMBA_CPU_FEATURES`` that a dcee parent set
    (it equals the parent's note, :data:`SET_BY_DCEE_ENV`), with the note, so that what
    remains of numba's CPU options is the user's; whether there was one."""
    inherited = set_by_dcee()
    if inherited:
        del os.environ["NUMBA_CPU_FEATURES"]
    os.environ.pop(SET_BY_DCEE_ENV, None)
    return inherited


def _choose_for_this_process() -> tuple[str | None, bool]:
    """Set ``NUMBA_CPU_FEATURES`` (and the note for child processes) to
    :func:`chosen_features`; (the value set or None, whether a parent's choice was removed)."""
    inherited = forget_inherited_choice()
    features = chosen_features()
    if features is not None:
        os.environ["NUMBA_CPU_FEATURES"] = os.environ[SET_BY_DCEE_ENV] = features
    return features, inherited


def full_width_features(host_features: str) -> str | None:
    """The feature string that compiles for ``host_features`` (LLVM's ``+a,-b,...`` form) with
    512-bit vectors preferred, or None where the host has no AVX-512 (nothing to change)."""
    features = host_features.split(",")
    if "+avx512f" not in features:
        return None
    kept = [f for f in features if f.lstrip("+-") != "prefer-256-bit"]
    return ",".join([*kept, "-prefer-256-bit"])


def chosen_features() -> str | None:
    """The ``NUMBA_CPU_FEATURES`` value to set in this process, or None to leave numba's
    default: the user set numba's CPU options or ``DCEE_VECTOR_WIDTH=llvm``, or the CPU has no
    AVX-512. Loads llvmlite (numba's own dependency) to read the host's features. Call
    :func:`forget_inherited_choice` first: a value a dcee parent set is not the user's."""
    if os.environ.get("NUMBA_CPU_FEATURES") or os.environ.get("NUMBA_CPU_NAME"):
        return None
    width = os.environ.get(WIDTH_ENV, "full").strip().lower() or "full"
    if width not in WIDTHS:
        # an environment variable has no command line to refuse it: say so once, go on
        print(
            f"dcee: {WIDTH_ENV} must be one of {', '.join(WIDTHS)}, got {width!r}; using full",
            file=sys.stderr,
        )
    if width == "llvm":
        return None
    import llvmlite.binding as llvm

    return full_width_features(llvm.get_host_cpu_features().flatten())


class _BeforeNumba(importlib.abc.MetaPathFinder):
    """Sets numba's CPU features the moment numba is first imported (its configuration reads
    the environment once, at import), then steps aside; finds nothing itself."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> None:
        if fullname == "numba":
            _remove_hook()
            _choose_for_this_process()
        return None


def _remove_hook() -> None:
    sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, _BeforeNumba)]


def widen_vectors_when_numba_loads() -> None:
    """Arrange for :func:`chosen_features` to apply when numba is imported; where numba is
    already imported (a program that used it before ``import dcee``), set its configuration
    now, which holds unless that program already compiled something (numba then keeps the
    code generator it made, at LLVM's width: slower, not wrong)."""
    if "numba" in sys.modules:
        features, inherited = _choose_for_this_process()
        if features is not None or inherited:
            sys.modules["numba"].config.CPU_FEATURES = features  # None: numba's own default
        return
    if not any(isinstance(f, _BeforeNumba) for f in sys.meta_path):
        sys.meta_path.insert(0, _BeforeNumba())
