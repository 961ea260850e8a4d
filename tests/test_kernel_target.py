"""The kernels' vector width (dcee.kernel_target): 512-bit vectors where the CPU has AVX-512,
LLVM's choice on request, the user's numba settings always first."""

import os
import subprocess
import sys

import llvmlite.binding as llvm
import numpy as np
import pytest

from dcee.kernel_target import SET_BY_DCEE_ENV, full_width_features

HOST = llvm.get_host_cpu_features().flatten()


def test_full_width_features_prefer_512_bit_only_on_avx512():
    assert full_width_features("+avx2,+fma,-avx512f") is None
    wide = full_width_features("+avx2,+avx512f,+prefer-256-bit,+fma")
    assert wide is not None
    parts = wide.split(",")
    assert parts[-1] == "-prefer-256-bit" and "+prefer-256-bit" not in parts
    assert {"+avx2", "+avx512f", "+fma"} <= set(parts)


def _without_width_settings() -> dict[str, str]:
    """This process's environment without any setting of the kernels' vector width (numba's,
    dcee's, and the note of dcee's own choice): a child starts from the user's defaults."""
    dropped = ("NUMBA_CPU_FEATURES", "NUMBA_CPU_NAME", "DCEE_VECTOR_WIDTH", SET_BY_DCEE_ENV)
    return {k: v for k, v in os.environ.items() if k not in dropped}


def _features_after_import(**env: str) -> str:
    """NUMBA_CPU_FEATURES as numba's configuration holds it after ``import dcee, numba`` in a
    fresh process with ``env`` added."""
    base = _without_width_settings()
    code = "import dcee, numba; print(repr(numba.config.CPU_FEATURES))"
    out = subprocess.run(
        [sys.executable, "-c", code], env={**base, **env}, capture_output=True, text=True,
        check=True,
    )  # fmt: skip
    return out.stdout.strip()


def test_importing_dcee_widens_numbas_vectors_on_this_cpu_unless_told_not_to():
    expected = full_width_features(HOST)
    assert _features_after_import() == repr(expected)  # None where the CPU has no AVX-512
    assert _features_after_import(DCEE_VECTOR_WIDTH="llvm") == "None"
    # the user's own numba setting wins
    assert _features_after_import(NUMBA_CPU_FEATURES="+sse2") == repr("+sse2")


@pytest.mark.skipif("+avx512f" not in HOST.split(","), reason="the CPU has no AVX-512")
def test_a_child_of_a_dcee_process_chooses_its_own_width_but_keeps_the_users():
    """The width a dcee parent chose reaches its children as that parent's choice, not as the
    user's: a child asked for LLVM's width gets it; a value the user set stays in every child."""
    child = (
        "import os, subprocess, sys, dcee, numba\n"
        "env = {**os.environ, 'DCEE_VECTOR_WIDTH': 'llvm'}\n"
        "code = 'import dcee, numba; print(repr(numba.config.CPU_FEATURES))'\n"
        "print(subprocess.run([sys.executable, '-c', code], env=env, capture_output=True,\n"
        "                     text=True, check=True).stdout.strip())\n"
    )
    base = _without_width_settings()
    for env, expected in (({}, "None"), ({"NUMBA_CPU_FEATURES": "+sse2"}, repr("+sse2"))):
        out = subprocess.run(
            [sys.executable, "-c", child], env={**base, **env}, capture_output=True, text=True,
            check=True,
        )  # fmt: skip
        assert out.stdout.strip() == expected, env


@pytest.mark.skipif("+avx512f" not in HOST.split(","), reason="the CPU has no AVX-512")
def test_the_vectorised_exp_uses_512_bit_registers_on_avx512():
    code = (
        "import dcee, numpy as np\n"
        "from numba import njit\n"
        "from dcee.numeric import exp_scalar\n"
        "@njit(fastmath={'contract'}, error_model='numpy')\n"
        "def f(a, out):\n"
        "    for i in range(a.shape[0]):\n"
        "        out[np.uint64(i)] = exp_scalar(a[np.uint64(i)])\n"
        "a = -np.arange(64.0); out = np.empty(64); f(a, out)\n"
        "print(sum(asm.count('zmm') for asm in f.inspect_asm().values()))\n"
    )
    env = _without_width_settings()
    for width, wide in (("full", True), ("llvm", False)):
        out = subprocess.run(
            [sys.executable, "-c", code], env={**env, "DCEE_VECTOR_WIDTH": width},
            capture_output=True, text=True, check=True,
        )  # fmt: skip
        assert (int(out.stdout.strip()) > 0) is wide, width


def test_particle_terms_share_the_concentration_rows_only_where_loc_is_c():
    """With the paper's sensor the transformed location is C itself and its rows are C's
    memory; with the log-normal family they are rows of their own, and differ from C."""
    from dcee.models import IsotropicPlume, Sensor
    from dcee.planning.particle_terms import ParticleTerms

    rng = np.random.default_rng(0)
    n = 300
    theta = np.column_stack(
        [rng.uniform(0, 50, n), rng.uniform(0, 50, n), rng.uniform(0, 3, n), rng.gamma(2, 5, n),
         rng.uniform(1, 6, n), rng.uniform(0, np.pi, n), rng.uniform(0.5, 2, n),
         rng.uniform(6, 10, n)]
    )  # fmt: skip
    pos = np.array([[10.0, 20.0, 2.0], [30.0, 5.0, 1.0]])
    for sensor, shared in ((Sensor.paper_exact(), True), (Sensor(family="lognormal"), False)):
        terms = ParticleTerms()
        terms.sync(theta, sensor, IsotropicPlume())
        terms.begin()
        rows = terms.rows(pos)
        t = terms.terms
        assert np.shares_memory(t.loc, t.conc) is shared
        if shared:
            np.testing.assert_array_equal(t.loc[rows], t.conc[rows])
        else:
            assert not np.array_equal(t.loc[rows], t.conc[rows])
    # a sensor of the other family on the same cache: the layout follows it
    terms.sync(theta, Sensor.paper_exact(), IsotropicPlume())
    terms.begin()
    terms.rows(pos)
    assert np.shares_memory(terms.terms.loc, terms.terms.conc)
