import subprocess
from pathlib import Path

import pytest

from dcee.provenance import (
    FALLBACK_VERSION,
    code_version,
    describe,
    platform_record,
    version_from_describe,
    version_without_tag,
)


@pytest.mark.parametrize(
    ("described", "dirty", "expected"),
    [
        ("v0.1.0-0-gabc1234", False, "0.1.0"),  # a clean tagged commit is the tag
        ("v0.1.0-0-gabc1234", True, "0.1.1.dev0+gabc1234.dirty"),
        ("v0.1.0-26-g80ab722", False, "0.1.1.dev26+g80ab722"),
        ("v1.2-3-gdeadbee", False, "1.3.dev3+gdeadbee"),
        ("release-1-gabc", False, None),  # not a version tag: the installed version is used
        (None, False, None),
    ],
)
def test_version_follows_setuptools_scm_default_scheme(described, dirty, expected):
    assert version_from_describe(described, dirty) == expected


def test_code_version_names_the_commit_that_runs():
    code = code_version()
    head = subprocess.run(
        ["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=False
    ).stdout.strip()
    if code["commit"] is None or not head:
        pytest.skip("not running from a git work tree")
    assert code["commit"] == head
    # the version is recomputed from git, not frozen at install time: it names this commit
    # unless the commit carries the tag itself
    assert code["version"].split("+")[0] and (
        f"+g{head[:7]}" in code["version"] or "+" not in code["version"]
    )
    assert head[:7] in describe(code)


def test_version_without_a_tag_follows_setuptools_scm() -> None:
    # what the editable install of commit 7e23c7d (606 commits, no version tag) was given
    assert version_without_tag(606, "7e23c7d1e", False) == "0.1.1.dev606+g7e23c7d1e"
    assert version_without_tag(3, "abc", True) == "0.1.1.dev3+gabc.dirty"


def test_the_fallback_version_is_pyprojects() -> None:
    text = (Path(__file__).parents[1] / "pyproject.toml").read_text()
    assert f'fallback_version = "{FALLBACK_VERSION}"' in text


def test_every_summary_records_the_platform_its_kernels_were_compiled_for(monkeypatch) -> None:
    import llvmlite.binding as llvm
    import numba
    import numpy

    from dcee.runs.episode import run_episode
    from dcee.scenarios import load_scenario

    platform_record.cache_clear()
    monkeypatch.delenv("NUMBA_CPU_NAME", raising=False)
    here = platform_record()
    assert here["cpu"] == llvm.get_host_cpu_name() and here["numba"] == numba.__version__
    assert here["numpy"] == numpy.__version__ and here["machine"]
    platform_record.cache_clear()
    monkeypatch.setenv("NUMBA_CPU_NAME", "generic")
    assert platform_record()["cpu"] == "generic"  # the target numba compiles for, not the host
    platform_record.cache_clear()
    monkeypatch.delenv("NUMBA_CPU_NAME")
    scenario = load_scenario("paper:1").with_overrides(
        **{"search.particles": 500, "search.hypotheses": 5, "search.budget": 30.0}
    )
    assert run_episode(scenario, "dcee", 0).summary["platform"] == here
