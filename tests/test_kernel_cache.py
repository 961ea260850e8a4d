"""The compiled kernels' cache is keyed by the package's source (dcee.kernel_cache): numba checks
only the file that defines a kernel, not the helpers inlined into it."""

import os
import subprocess
import sys
import time

from dcee import kernel_cache


def _package(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "kernel.py").write_text("from numba import njit\nfrom pkg.sub.helper import h\n")
    (pkg / "sub" / "helper.py").write_text(
        "from numba import njit\n\n@njit\ndef h(x):\n  return x\n"
    )
    (pkg / "cli.py").write_text("print('no kernels here')\n")
    return pkg


def test_the_key_changes_with_a_kernel_or_helper_module_and_only_then(tmp_path):
    pkg = _package(tmp_path)
    first = kernel_cache.source_stamp(pkg)
    assert kernel_cache.source_stamp(pkg) == first  # stable
    helper = pkg / "sub" / "helper.py"
    helper.write_text(helper.read_text().replace("return x", "return 2*x"))  # inlined helper
    second = kernel_cache.source_stamp(pkg)
    assert second != first
    (pkg / "cli.py").write_text("print('still no kernels')\n")  # no compiled code changes
    (pkg / "notes.txt").write_text("not python")
    assert kernel_cache.source_stamp(pkg) == second
    later = time.time() + 5  # a checkout that only touches times
    os.utime(helper, (later, later))
    assert kernel_cache.source_stamp(pkg) == second


def test_numba_cache_dir_follows_the_source_and_old_states_are_pruned(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.delitem(sys.modules, "numba", raising=False)  # as before numba is imported
    root = tmp_path / "cache" / "dcee" / "numba"
    for k in range(6):  # earlier source states, oldest first
        old = root / f"old{k}"
        old.mkdir(parents=True)
        os.utime(old, (1000 + k, 1000 + k))
    folder = kernel_cache.key_numba_cache()
    assert folder == root / kernel_cache.source_stamp()
    assert os.environ["NUMBA_CACHE_DIR"] == str(folder)
    kept = sorted(p.name for p in root.iterdir())
    assert len(kept) == kernel_cache.KEEP and folder.name in kept
    assert {"old5", "old4", "old3"} <= set(kept)  # the most recently used survive
    # a folder the user chose wins
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    assert kernel_cache.key_numba_cache() == tmp_path / "mine"


def test_an_unusable_cache_root_leaves_numbas_default(tmp_path, monkeypatch):
    """A cache root that cannot be created (below a plain file: refused even to root) leaves
    NUMBA_CACHE_DIR unset, so numba keeps its own default."""
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker / "cache"))
    monkeypatch.delitem(sys.modules, "numba", raising=False)
    assert kernel_cache.key_numba_cache() is None
    assert "NUMBA_CACHE_DIR" not in os.environ


def test_importing_dcee_sets_the_keyed_folder_before_numba_loads(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    code = (
        "import os, sys, dcee; from dcee.kernel_cache import source_stamp; "
        "import numba; from numba.core import config; "
        "print(os.environ['NUMBA_CACHE_DIR'] == config.CACHE_DIR, source_stamp())"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    ).stdout.split()
    assert out[0] == "True"
    assert (tmp_path / "dcee" / "numba" / out[1]).is_dir()


def test_kernels_are_filed_by_package_folder_so_another_checkout_reuses_them(tmp_path):
    """Where dcee chose the cache folder, a kernel's cache lies in ``<source state>/dcee/<its
    subpackage>`` (dcee.kernel_locator), not under a hash of the checkout's absolute folder, so
    a fresh clone of the same source finds what another compiled; a user's NUMBA_CACHE_DIR
    keeps numba's own locator."""
    code = (
        "import numpy as np, dcee\n"
        "from dcee.planning.reading_terms import task_layout\n"
        "task_layout(np.zeros((2, 1), dtype=np.int64), 3)\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    subprocess.run([sys.executable, "-c", code], env=env, check=True, timeout=300)
    root = tmp_path / "cache" / "dcee" / "numba" / kernel_cache.source_stamp()
    index = sorted(p.relative_to(root) for p in root.rglob("*.nbi"))
    assert index and all(p.parts[:2] == ("dcee", "planning") for p in index), index
    from dcee.kernel_locator import PackageRelativeLocator

    def outside(x):
        return x

    assert PackageRelativeLocator.from_function(outside, __file__) is None  # not dcee's


def test_a_kernel_that_calls_another_modules_summation_runs_from_the_cache(tmp_path):
    """The stratified hypotheses' kernel calls particle_terms.pairwise_sum; loaded from the
    on-disk cache in a later process it must run. (A recursive pairwise_sum was compiled into
    the cache unlinked: "unresolved symbol", or a segfault, in every process after the first.)"""
    code = (
        "import numpy as np\n"
        "from dcee.planning.stratified_kernels import _systematic_picks\n"
        "p = np.full((1, 300), 1e-3); prob = np.zeros((1, 4)); live = np.zeros(1, bool)\n"
        "sel = np.zeros((3, 1, 3, 1)); terms = np.ones((1, 300))\n"
        "_systematic_picks(p, 0.5, 3, terms, terms, terms, np.zeros((1, 1), np.int64),\n"
        "                  prob, live, sel[0], sel[1], sel[2])\n"
        "assert live[0] and abs(prob[0, 0] - 0.7) < 1e-12, prob\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    for _ in range(2):  # the first compiles and stores, the second loads
        subprocess.run([sys.executable, "-c", code], env=env, check=True, timeout=300)


def test_a_search_compiles_each_particle_kernel_once_whether_its_particles_are_frozen_or_not():
    """The filter freezes its particles for the planners (``planning_particles``) and edits a
    copy afterwards, so kernels saw them both writeable and read-only; numba types an array's
    mutability, and compiled the history likelihood twice (14 s of a fresh machine's first
    search). Kernels that only read their inputs take read-only views
    (``dcee.numeric.read_only_view``): one specialisation each. In a fresh process, with the
    suite's cache, so that no other test's calls count."""
    code = (
        "from dcee.runs import run_episode\n"
        "from dcee.scenarios import load_scenario\n"
        "from dcee.estimation import filter_kernels as f\n"
        "from dcee.models import plume_kernels as p\n"
        "from dcee.planning import particle_terms as t, position_kernels as k\n"
        "s = load_scenario('random:1000').with_overrides(**{'search.particles': 300,\n"
        "    'search.hypotheses': 4, 'search.budget': 12.0})\n"
        "for planner in ('dcee-cl', 'infotaxis'):\n"
        "    run_episode(s, planner, 0)\n"
        "kernels = (f._history_kernel, p.concentration_distance_grid, t.merge_runs,\n"
        "           k.content_hash)\n"
        "print([len(kernel.signatures) for kernel in kernels])\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, check=True, timeout=300, capture_output=True,
        text=True,
    )  # fmt: skip
    counts = out.stdout.strip().splitlines()[-1]
    assert counts == "[1, 1, 1, 1]", counts
