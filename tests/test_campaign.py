"""Campaigns: resume, corruption, refusal of a changed configuration, failures, Dask, report."""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from dcee.analysis.report import load_campaign, write_report
from dcee.analysis.statistics import (
    censored_median_time,
    median_ci,
    median_order_statistic_ranks,
    rmse_over_time,
    wilson,
)
from dcee.campaign import Campaign, SearchTask, run_campaign
from dcee.campaign.runner import _local_results, is_done, run_search
from dcee.cli import main
from dcee.errors import DceeInputError
from dcee.provenance import code_version
from tests.helpers import search_that_kills_its_worker_on_seed_1

STRATEGIES = ("mpc", "dcee")


def _campaign(out, particles=300, repeats=2):
    return Campaign(out, "smoke", STRATEGIES, repeats, particles=particles)


def _run(out, config, strategy, seed):
    """The folder of one search of a campaign (hive partitions)."""
    return SearchTask(str(out), config, strategy, seed, {}).folder


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    out = tmp_path_factory.mktemp("campaign")
    counts = run_campaign(_campaign(out), workers=2)
    return out, counts


def test_campaign_runs_every_search_with_common_random_numbers(finished):
    out, counts = finished
    assert counts == {"total": 8, "skipped": 0, "done": 8, "failed": 0}
    meta = json.loads((out / "campaign.json").read_text())
    assert meta["version"] and meta["settings"]["particles"] == 300
    assert [c["source_hash"] for c in meta["code_versions"]] == [code_version()["source_hash"]]
    # Same (configuration, repeat): every strategy saw the same truth noise at its first reading
    # (same start position), and a different repeat saw different noise.
    first = {}
    for strategy in STRATEGIES:
        for seed in (0, 1):
            steps = pd.read_parquet(_run(out, "paper:1", strategy, seed) / "steps.parquet")
            first[strategy, seed] = steps["true_concentration"].iloc[0], steps["reading"].iloc[0]
    assert first["mpc", 0] == first["dcee", 0] and first["mpc", 1] == first["dcee", 1]


def test_rerun_skips_finished_and_redoes_corrupt_or_partial(finished, tmp_path):
    out, _ = finished
    again = run_campaign(_campaign(out), workers=1)
    assert again == {"total": 8, "skipped": 8, "done": 0, "failed": 0}
    # A truncated record, and a search whose summary never got written (killed mid-search).
    rec = _run(out, "paper:6", "dcee", 1) / "steps.parquet"
    rec.write_bytes(rec.read_bytes()[:100])
    (_run(out, "paper:1", "mpc", 0) / "summary.json").unlink()
    summary = _run(out, "paper:6", "mpc", 0) / "summary.json"
    summary.write_text(summary.read_text()[:20])  # corrupt JSON
    redo = run_campaign(_campaign(out), workers=1)
    assert redo == {"total": 8, "skipped": 5, "done": 3, "failed": 0}
    assert all(is_done(t) for t in _campaign(out).tasks())


def test_changed_configuration_in_the_same_folder_is_refused(finished):
    out, _ = finished
    with pytest.raises(DceeInputError, match=r"different configuration.*particles"):
        run_campaign(_campaign(out, particles=400), workers=1)


def test_a_default_changed_since_a_campaign_was_stored_is_refused(tmp_path, monkeypatch):
    """A campaign records what each unset default resolved to; resumed after that default
    changed (here the climb with the count unknown, 1 m → 2 m) it is refused, naming the
    setting; pinning the value it flew with resumes it. One stored before the record is compared
    by today's rules, as before."""
    import dcee.scenarios.schema.agent as agent_schema

    several = {"estimator.max_sources": 2}

    def prepare(out: Path, overrides: dict) -> None:
        Campaign(out, "smoke", ("mpc",), 1, particles=200, overrides=overrides).prepare()

    prepare(tmp_path, several)
    meta = json.loads((tmp_path / "campaign.json").read_text())
    assert meta["settings"]["resolved"]["paper:1"]["agent.climb"] == 1.0
    prepare(tmp_path, several)  # the same defaults: resumes
    monkeypatch.setattr(agent_schema, "AUTO_CLIMB", 2.0)
    with pytest.raises(DceeInputError, match=r"agent\.climb: stored 1\.0, now 2\.0"):
        prepare(tmp_path, several)
    prepare(tmp_path, {**several, "agent.climb": 1.0})
    older = tmp_path / "older"
    older.mkdir()
    del meta["settings"]["resolved"]
    (older / "campaign.json").write_text(json.dumps(meta))
    prepare(older, several)  # unset on both sides, resolved by today's rule


def test_a_reworded_description_does_not_orphan_a_campaign(finished, tmp_path):
    """Free text changes no result: a campaign whose stored scenario descriptions differ from
    today's still resumes (it refused before, a whole chain of studies once stopped on it)."""
    import shutil

    out, _ = finished
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    meta = json.loads((copy / "campaign.json").read_text())
    for scenario in meta["settings"]["scenarios"].values():
        scenario["description"] = "worded differently"
    (copy / "campaign.json").write_text(json.dumps(meta))
    assert run_campaign(_campaign(copy), workers=1)["skipped"] == 8


def test_planner_specs_are_campaign_strategies(tmp_path):
    spec = "dcee-cl:reach=4:hypotheses=8"
    campaign = Campaign(tmp_path, "smoke", (spec,), 1, particles=200)
    assert run_campaign(campaign, workers=1)["done"] == 2
    folder = tmp_path / "runs/config=paper%3A1/strategy=dcee-cl%3Areach%3D4%3Ahypotheses%3D8/seed=0"
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["strategy"] == spec and summary["planner_options"]["reach"] == 4.0
    with pytest.raises(DceeInputError, match="reach"):
        Campaign(tmp_path / "bad", "smoke", ("dcee-cl:reach=x",), 1)


def test_failing_search_is_recorded_and_does_not_raise(tmp_path):
    task = SearchTask(str(tmp_path), "paper:1", "dcee", 0, {"name": "broken"})
    res = run_search(task)
    assert res["status"] == "failed"
    err = json.loads((task.folder / "error.json").read_text())
    assert err["strategy"] == "dcee" and "Error" in err["error"]
    assert not is_done(task)


BENCH = ["bench", "--suite", "smoke", "--strategies", "mpc,dcee", "--repeats", "3"]
BENCH += ["--particles", "300", "--workers", "2"]


def _ctrl_c_as_in_a_terminal() -> None:
    """Before exec in a child: Ctrl-C handled by default, as a terminal's foreground job has it
    (a job started in the background from a script starts with SIGINT ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _group_alive(pgid: int) -> bool:
    """Whether any process of the process group ``pgid`` still runs (zombies do not count)."""
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":
            return True
    return False


@pytest.mark.parametrize(
    "sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL], ids=["ctrl-c", "kill", "kill-9"]
)
def test_interrupted_bench_keeps_finished_searches_and_resumes(tmp_path, capsys, sig):
    """A real interruption as soon as the first search has finished: Ctrl-C (to the driver and
    its workers, as a terminal sends it), ``kill PID`` (SIGTERM to the driver alone: it stops
    its workers, none is left running) or ``kill -9`` (to all); the rerun redoes only the rest."""
    out = tmp_path / "c"
    proc = subprocess.Popen(
        [sys.executable, "-m", "dcee.cli", *BENCH, "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=_ctrl_c_as_in_a_terminal,
    )
    deadline = time.monotonic() + 180
    while not list(out.glob("runs/*/*/*/summary.json")):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "no search finished in time"
        time.sleep(0.02)
    if sig == signal.SIGTERM:
        os.kill(proc.pid, sig)
    else:
        os.killpg(proc.pid, sig)
    _, err = proc.communicate(timeout=120)
    if sig == signal.SIGINT:
        assert proc.returncode == 130 and err.strip().endswith("dcee: interrupted")
        assert "Traceback" not in err
    elif sig == signal.SIGTERM:
        assert proc.returncode == 143 and err.strip().endswith("dcee: terminated")
        assert "Traceback" not in err
        deadline = time.monotonic() + 30  # no worker outlives the driver
        while _group_alive(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _group_alive(proc.pid), "a worker process outlived the driver"
    else:
        assert proc.returncode == -signal.SIGKILL
    tasks = Campaign(out, "smoke", ("mpc", "dcee"), 3, particles=300).tasks()
    finished = {
        t.folder: (t.folder / "summary.json").stat().st_mtime_ns for t in tasks if is_done(t)
    }
    assert 1 <= len(finished) < len(tasks)
    # What a kill in the middle of a write leaves: a temporary file beside the result.
    todo = next(t for t in tasks if t.folder not in finished)
    stale = todo.folder / ".steps.parquet.x1y2z3.parquet"
    stale.parent.mkdir(parents=True, exist_ok=True)
    stale.write_bytes(b"PAR1 half")

    with pytest.raises(SystemExit) as exc:
        main([*BENCH, "--out", str(out)])
    assert exc.value.code == 0
    assert f"{len(tasks)} searches: {len(finished)} already done" in capsys.readouterr().out
    assert all(is_done(t) for t in tasks) and not stale.exists()
    # Finished searches were skipped, not redone.
    assert all((f / "summary.json").stat().st_mtime_ns == m for f, m in finished.items())


def test_a_worker_killed_from_outside_loses_nothing(tmp_path):
    """SIGKILL one worker process after the first result: the pool breaks, and the searches
    that were in flight or queued are rerun in the same invocation, none recorded as failed."""
    import multiprocessing

    killed = []

    def kill_a_worker(res, finished, todo):
        if not killed:
            victim = multiprocessing.active_children()[0]
            os.kill(victim.pid, signal.SIGKILL)
            killed.append(victim.pid)

    campaign = Campaign(tmp_path, "smoke", ("mpc", "dcee"), 3, particles=300)
    counts = run_campaign(campaign, workers=2, on_result=kill_a_worker)
    assert killed and counts == {"total": 12, "skipped": 0, "done": 12, "failed": 0}
    assert all(is_done(t) for t in campaign.tasks())
    assert not list(tmp_path.glob("runs/*/*/*/error.json"))


def test_a_search_that_kills_its_worker_fails_alone(tmp_path):
    """Repeat 1 kills its worker every time: it is retried alone, then recorded as failed with
    an error file; the searches that shared the pool with it still finish."""
    campaign = Campaign(tmp_path, "smoke", ("mpc",), 2, particles=300)
    campaign.prepare()
    tasks = campaign.tasks()  # paper:1 and paper:6, repeats 0 and 1
    results = list(_local_results(tasks, 2, search=search_that_kills_its_worker_on_seed_1))
    status = {(r["task"].config, r["task"].seed): r["status"] for r in results}
    assert len(results) == 4
    assert status == {
        ("paper:1", 0): "done",
        ("paper:6", 0): "done",
        ("paper:1", 1): "failed",
        ("paper:6", 1): "failed",
    }
    for t in tasks:
        assert is_done(t) == (t.seed == 0)
        if t.seed == 1:
            err = json.loads((t.folder / "error.json").read_text())
            assert "worker process died" in err["error"]


def test_dask_cluster_by_address_through_the_cli(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        out = tmp_path / "c"
        args = ["bench", "--suite", "smoke", "--strategies", "mpc", "--repeats", "1"]
        args += ["--particles", "300", "--out", str(out), "--scheduler", cluster.scheduler_address]
        with pytest.raises(SystemExit) as exc:
            main(args)
    assert exc.value.code == 0
    assert "2 searches: 0 already done, 2 run, 0 failed" in capsys.readouterr().out
    assert all(is_done(t) for t in Campaign(out, "smoke", ("mpc",), 1, particles=300).tasks())


@pytest.mark.parametrize(
    ("args", "words"),
    [
        # found 2026-12-05: a traceback, and campaign.json written before it
        (["--scheduler", "nonsense"], "scheduler: cannot connect to 'nonsense'"),
        # found 2026-12-05: two workers wrote one folder, and searches failed
        (["--strategies", "mpc,mpc"], "strategies: mpc given more than once"),
    ],
)
def test_a_bad_scheduler_or_a_strategy_twice_is_one_line_before_any_work(
    tmp_path, capsys, args, words
):
    out = tmp_path / "c"
    with pytest.raises(SystemExit) as exc:
        main(["bench", "--suite", "smoke", "--repeats", "1", "--out", str(out), *args])
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and words in err[-1] and "Traceback" not in "".join(err)
    assert not out.exists() or not any(out.iterdir())


def test_dask_local_cluster_runs_the_campaign(tmp_path):
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        counts = run_campaign(
            Campaign(tmp_path, "smoke", ("mpc",), 1, particles=300), scheduler=client
        )
    assert counts == {"total": 2, "skipped": 0, "done": 2, "failed": 0}
    assert all(is_done(t) for t in Campaign(tmp_path, "smoke", ("mpc",), 1, particles=300).tasks())


def test_report_tables_and_figures(finished, tmp_path):
    out, _ = finished
    paths = write_report(out, tmp_path / "report")
    assert all(p.stat().st_size > 0 for p in paths)
    table = pd.read_csv(tmp_path / "report/metrics.csv")
    assert sorted(table["strategy"]) == sorted(STRATEGIES)
    assert (table["searches"] == 4).all()
    for key in ("source_acquired", "plume_acquired"):
        assert (table[f"{key}_lo"] <= table[f"{key}_rate"]).all()
        assert (table[f"{key}_rate"] <= table[f"{key}_hi"]).all()
    assert "mean final RMSE" in (tmp_path / "report/metrics.md").read_text()
    # the longest stall of any search per strategy, recounted from the summaries
    stalls = {}
    for run in (out / "runs").rglob("summary.json"):
        s = json.loads(run.read_text())
        stalls[s["strategy"]] = max(stalls.get(s["strategy"], 0.0), s["longest_stall"])
    assert dict(zip(table["strategy"], table["longest_stall"], strict=True)) == stalls
    assert "longest stall (s)" in (tmp_path / "report/metrics.md").read_text()
    # Per configuration: k/n recounted by hand from the summaries.
    per_config = pd.read_csv(tmp_path / "report/per_configuration.csv", index_col=0)
    assert list(per_config.index) == ["paper:1", "paper:6"]
    for config in per_config.index:
        for strategy in STRATEGIES:
            hits = [
                json.loads((_run(out, config, strategy, seed) / "summary.json").read_text())[
                    "source_acquired"
                ]
                for seed in (0, 1)
            ]
            assert per_config.loc[config, strategy] == f"{sum(hits)}/{len(hits)}"
    # RMSE curves: the final mean and median recomputed by hand from the per-step records.
    _, runs = load_campaign(out)
    curves = rmse_over_time(runs)
    for strategy in STRATEGIES:
        finals = [
            pd.read_parquet(_run(out, config, strategy, seed) / "steps.parquet")["rmse"].iloc[-1]
            for config in ("paper:1", "paper:6")
            for seed in (0, 1)
        ]
        last = curves[strategy].iloc[-1]
        assert last["mean"] == pytest.approx(np.mean(finals))
        assert last["median"] == pytest.approx(np.median(finals))
        assert last["median_lo"] <= last["median"] <= last["median_hi"]
        assert last["median_lo"] == pytest.approx(min(finals))  # n = 4: the sample range
    html = (tmp_path / "report/report.html").read_text()
    assert html.count("data:image/png;base64,") == 4
    # the campaign's edit of every configuration is named, so it is not read as the built-ins
    assert "settings changed from the configurations' own: search.particles = 300" in html
    # the paper's likelihood keeps the particles' own 95 % region (floor 0), and says so
    assert "The 95% region is the particles' own." in html
    # Paired comparison recounted by hand: searches acquired by one strategy and not the other.
    pairs = pd.read_csv(tmp_path / "report/pairwise.csv")
    assert len(pairs) == 1 and pairs.loc[0, "pairs"] == 4
    acquired = runs.set_index(["scenario", "seed", "strategy"])["source_acquired"].unstack()
    a, b = pairs.loc[0, "a"], pairs.loc[0, "b"]
    assert pairs.loc[0, "acquired_a_only"] == int((acquired[a] & ~acquired[b]).sum())
    assert pairs.loc[0, "acquired_b_only"] == int((~acquired[a] & acquired[b]).sum())


def test_whole_study_loads_in_one_call(finished):
    """The hive layout: one call (ours, or pyarrow's dataset reader) loads every record with
    the configuration, strategy and seed of each search."""
    import pyarrow.dataset as ds

    from dcee.analysis.results import load_steps, load_summaries

    out, _ = finished
    runs = load_summaries(out)
    assert len(runs) == 8 and set(runs["strategy"]) == set(STRATEGIES)
    steps = load_steps(out, ["time", "rmse"])
    assert len(steps) == runs["record_rows"].sum()
    table = ds.dataset(
        out / "runs", format="parquet", partitioning="hive", exclude_invalid_files=True
    ).to_table(columns=["config", "strategy", "seed", "rmse"])
    frame = table.to_pandas()
    assert len(frame) == len(steps)
    assert set(frame["config"]) == {"paper:1", "paper:6"} and set(frame["seed"]) == {0, 1}


def test_snapshots_follow_the_budget(finished):
    """Repeat 0 keeps snapshots at 10/30/50/100% of its budget (60 s in the smoke suite), so a
    short search still fills the comparison grid; later repeats keep none."""
    from dcee.runs import EpisodeResult

    out, _ = finished
    first = EpisodeResult.load(_run(out, "paper:1", "dcee", 0))
    times = [t for t, _ in first.snapshots]
    assert times[-1] == first.records[-1]["time"] and len(times) == 4
    for t, target in zip(times, (6.0, 18.0, 30.0), strict=False):
        assert target <= t < target + 2.0  # the first reading at or after it (2 s steps)
    assert EpisodeResult.load(_run(out, "paper:1", "dcee", 1)).snapshots == []


def test_resume_with_other_code_is_refused_unless_allowed(finished, monkeypatch, tmp_path):
    import shutil

    import dcee.campaign.folder as campaign_folder

    out, _ = finished

    def code_versions(folder):
        return json.loads((folder / "campaign.json").read_text())["code_versions"]

    before = code_versions(out)
    other = {**code_version(), "source_hash": "0123456789abcdef", "commit": "f" * 40}
    monkeypatch.setattr(campaign_folder, "code_version", lambda: other)
    # complete: resuming runs nothing, so nothing is refused and no code is recorded
    assert run_campaign(_campaign(out), workers=1)["skipped"] == 8
    assert code_versions(out) == before
    # a search left to run: other code is refused unless allowed, then recorded beside
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    (_run(copy, "paper:1", "dcee", 1) / "summary.json").unlink()
    with pytest.raises(DceeInputError, match=r"other code.*--allow-code-change"):
        run_campaign(_campaign(copy), workers=1)
    campaign = _campaign(copy)
    campaign.allow_code_change = True
    counts = run_campaign(campaign, workers=1)
    assert counts["skipped"] == 7 and counts["done"] == 1
    hashes = [c["source_hash"] for c in code_versions(copy)]
    assert hashes == [code_version()["source_hash"], "0123456789abcdef"]


def test_interval_helpers_against_hand_calculations():
    rate, lo, hi = wilson(5, 10)  # Wilson (1927): 0.5 ± 0.2634 for n = 10
    assert (
        rate == 0.5
        and lo == pytest.approx(0.2366, abs=1e-4)
        and hi == pytest.approx(0.7634, abs=1e-4)
    )
    for n in range(1, 130):  # exactly at the ends, never 1e-17 inside (the old crash)
        for k in (0, n):
            rate, lo, hi = wilson(k, n)
            assert lo <= rate <= hi
        assert wilson(n, n)[2] == 1.0 and wilson(0, n)[1] == 0.0
    m, lo, hi = median_ci(np.arange(101.0))
    assert m == 50 and lo < 50 < hi
    assert math.isnan(median_ci(np.array([np.nan]))[0])
    # Textbook order-statistic intervals for the median (1-based ranks): n = 10 -> 2nd..9th
    # (coverage 1 - 2 * 11/1024 = 97.9%), n = 100 -> 40th..61st (96.5%).
    assert median_order_statistic_ranks(10) == (1, 8)
    assert median_order_statistic_ranks(100) == (39, 60)
    assert median_order_statistic_ranks(3) == (0, 2)  # too few for 95%: the sample range
    # quantile_test's interval is the same order-statistic interval: n = 10 -> 2nd and 9th
    x = np.array([5.0, 1.0, 9.0, 3.0, 7.0, 2.0, 8.0, 4.0, 6.0, 10.0])
    assert median_ci(x) == (5.5, 2.0, 9.0)


def test_censored_time_is_kaplan_meier_not_a_mean_over_arrivals():
    """Searches that never got there are censored at the budget. Hand calculation: with all
    censoring at the budget the Kaplan-Meier CDF is the plain share arrived by t, so the median
    is the 5th of 10 sorted times when 5 or more arrived, and beyond the budget otherwise (the
    old mean over arrivals made a planner that rarely arrives look fast)."""
    budget = np.full(10, 900.0)
    t = np.array([100, 200, 300, 400, 500, np.nan, np.nan, np.nan, np.nan, np.nan], dtype=float)
    median, lo, hi = censored_median_time(t, budget)
    assert median == 500.0 and lo <= median and math.isinf(hi)
    rare = np.array([50.0] + [np.nan] * 9)
    assert censored_median_time(rare, budget)[0] == math.inf  # 1/10 arrived: "> 900"
    every = np.arange(10.0, 110.0, 10.0)
    median, lo, hi = censored_median_time(every, budget)
    assert median == 50.0 and lo <= 50.0 <= hi < 900.0
    assert censored_median_time(np.full(4, np.nan), budget[:4]) == (math.inf,) * 3


def test_posterior_histogram_range_ignores_a_lost_minority():
    """85% of errors ~ N(0, 1) and 15% from lost searches at +20 m: the histogram range keeps
    the bulk and leaves the lost ones outside; with no outliers it is the central
    98%."""
    from dcee.analysis.report_figures import _robust_range

    rng = np.random.default_rng(3)
    bulk = rng.normal(size=8500)
    lo, hi = _robust_range(np.concatenate([bulk, np.full(1500, 20.0)]))
    assert -4.0 < lo < -2.0 and 2.5 < hi < 10.0  # bulk inside (p1, ~p99.7), +20 m outside
    lo, hi = _robust_range(bulk)
    assert (lo, hi) == pytest.approx(tuple(np.percentile(bulk, [1, 99])))


def test_median_band_covers_the_median_at_95_percent():
    """Simulated coverage of the order-statistic band over 4,000 samples of n = 30 from a
    skewed distribution (the band is distribution-free)."""
    rng = np.random.default_rng(7)
    n, true_median = 30, np.log(2.0)  # exponential(1)
    lo, hi = median_order_statistic_ranks(n)
    x = np.sort(rng.exponential(size=(4000, n)), axis=1)
    coverage = np.mean((x[:, lo] <= true_median) & (true_median <= x[:, hi]))
    assert 0.94 <= coverage <= 0.975  # exact: 1 - 2 P(B <= 9) = 95.7%


@pytest.mark.parametrize(
    "args, field",
    [
        (["--workers", "0"], "workers"),
        (["--strategies", "nope"], "strategy"),
        (["--suite", "huge"], "suite"),
        (["--repeats", "0"], "repeats"),
    ],
)
@pytest.mark.parametrize("dry_run", [[], ["--dry-run"]])
def test_bench_bad_input_is_one_line_exit_2(tmp_path, capsys, args, field, dry_run):
    with pytest.raises(SystemExit) as exc:
        main(["bench", "--suite", "smoke", "--out", str(tmp_path / "c"), *args, *dry_run])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and field in err and err.count("\n") == 1
    assert not (tmp_path / "c").exists()  # refused before the folder was made


def test_bench_dry_run_writes_nothing_and_checks_the_folder(tmp_path, capsys):
    out = tmp_path / "deep" / "c"
    argv = ["bench", "--suite", "smoke", "--strategies", "mpc", "--repeats", "3"]
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--out", str(out), "--dry-run"])
    stdout = capsys.readouterr().out
    assert exc.value.code == 0 and not (tmp_path / "deep").exists()
    assert stdout.startswith("would run 6 of 6 searches (2 configurations × 1 strategies")
    (tmp_path / "file").write_text("x")
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--out", str(tmp_path / "file" / "c"), "--dry-run"])
    assert exc.value.code == 2 and "out:" in capsys.readouterr().err


def test_report_names_the_region_floor():
    from dcee.analysis.report import region_floor_text

    assert region_floor_text(pd.DataFrame({"x": [1]})) == "The 95% region is the particles' own."
    assert region_floor_text(pd.DataFrame({"region_floor": [0.0, 0.0]})).endswith("own.")
    mixed = region_floor_text(pd.DataFrame({"region_floor": [0.25, 0.0, 0.25, None]}))
    assert "estimator.region_floor = 0, 0.25 m" in mixed


def test_report_on_a_folder_without_results_is_exit_2(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["report", str(tmp_path)])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "no finished searches" in err and err.count("\n") == 1


def test_report_on_a_corrupt_campaign_file_is_exit_2(finished, tmp_path, capsys):
    import shutil

    out, _ = finished
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    (copy / "campaign.json").write_text("{not json")
    with pytest.raises(SystemExit) as exc:
        main(["report", str(copy)])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "campaign" in err and err.count("\n") == 1


def test_plain_progress_lines_for_logs(capsys):
    """Not a terminal: one line per 5% of the searches and the last, with a linear ETA."""
    from dcee.cli.bench import _log_progress

    for finished in range(1, 41):
        _log_progress("paper", finished, 40, 1, elapsed=3.0 * finished)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 20
    assert lines[0] == "paper: 2/40 searches, failed 1, elapsed 0:00:06, ETA 0:01:54"
    assert lines[-1] == "paper: 40/40 searches, failed 1, elapsed 0:02:00, ETA 0:00:00"


def test_campaigns_stored_before_a_setting_existed_still_resume():
    # agent.count came later: a stored scenario without it ran with the default (1 robot)
    from dcee.runs import scenario_identity
    from dcee.scenarios import load_scenario

    now = load_scenario("paper:1").model_dump(mode="json")
    before = {**now, "agent": {k: v for k, v in now["agent"].items() if k != "count"}}
    assert scenario_identity(before) == scenario_identity(now)
    two = {**now, "agent": {**now["agent"], "count": 2}}
    assert scenario_identity(two) != scenario_identity(before)
    # the robot's motion came later still: stored without it, the grid agent ran
    added = ("count", "model", "heading", "localisation_sd", "unicycle")
    older = {**now, "agent": {k: v for k, v in now["agent"].items() if k not in added}}
    assert scenario_identity(older) == scenario_identity(now)
    robot = {**now, "agent": {**now["agent"], "model": "unicycle"}}
    assert scenario_identity(robot) != scenario_identity(older)
    slower = {**now, "agent": {**now["agent"], "unicycle": {**now["agent"]["unicycle"]}}}
    slower["agent"]["unicycle"]["max_accel"] = 0.2
    assert scenario_identity(slower) != scenario_identity(older)


def test_a_filament_campaign_stored_before_sensor_dropout_ran_with_the_misses():
    # before sensor.dropout, the instrument missed 1 − pd of the readings on every truth: an
    # isotropic campaign is what the default still does, a filament one is not
    from dcee.runs import scenario_identity
    from dcee.scenarios import load_scenario

    def stored_before(scenario):
        d = scenario.model_dump(mode="json")
        d["sensor"] = {k: v for k, v in d["sensor"].items() if k != "dropout"}
        return d

    iso = load_scenario("paper:1")
    assert scenario_identity(stored_before(iso)) == scenario_identity(iso.model_dump(mode="json"))
    fil = iso.with_overrides(**{"truth.model": "filament"})
    old = scenario_identity(stored_before(fil))
    assert old != scenario_identity(fil.model_dump(mode="json"))
    lossy = fil.with_overrides(**{"sensor.dropout": 0.3})
    assert old == scenario_identity(lossy.model_dump(mode="json"))


def test_fluctuation_only_settings_do_not_matter_under_the_paper_likelihood():
    from dcee.runs import scenario_identity
    from dcee.scenarios import load_scenario

    lab = load_scenario("lab:upwind")
    assert lab.estimator.log_sd == 0.72  # fitted at the room's scale
    a = lab.model_dump(mode="json")
    b = lab.with_overrides(**{"estimator.log_sd": 1.3}).model_dump(mode="json")
    assert scenario_identity(a) == scenario_identity(b)  # paper likelihood: never read
    fa, fb = (
        lab.with_overrides(**{"estimator.likelihood": "fluctuation", **extra}).model_dump(
            mode="json"
        )
        for extra in ({}, {"estimator.log_sd": 1.3})
    )
    assert scenario_identity(fa) != scenario_identity(fb)


def test_campaigns_stored_before_issue_29_keep_the_estimator_they_ran_with():
    """An unset outlier weight meant 0 for the paper's likelihood and 0.01 for the fluctuation
    one; reading_weight did not exist (every reading weighed 1). A stored paper campaign then
    differs from today's default (outlier 0.01) but not from an explicit 0; an unset
    reading_weight is the likelihood's default as a number."""
    from dcee.runs import scenario_identity
    from dcee.scenarios import load_scenario

    def stored_before(scenario):
        d = scenario.model_dump(mode="json")
        d["estimator"]["outlier"] = None
        d["estimator"].pop("reading_weight")
        return d

    paper = load_scenario("paper:1")
    old = scenario_identity(stored_before(paper))
    assert old != scenario_identity(paper.model_dump(mode="json"))
    exact = paper.with_overrides(**{"estimator.outlier": 0.0})
    assert old == scenario_identity(exact.model_dump(mode="json"))
    fluct = paper.with_overrides(**{"estimator.likelihood": "fluctuation"})
    old_fluct = stored_before(fluct)
    # only the weights differ here
    old_fluct["estimator"]["near_source_length"] = fluct.estimator.near_source_length
    assert scenario_identity(old_fluct) != scenario_identity(fluct.model_dump(mode="json"))
    full = fluct.with_overrides(**{"estimator.reading_weight": 1.0})
    assert scenario_identity(old_fluct) == scenario_identity(full.model_dump(mode="json"))


def test_the_fourth_rounds_defaults_follow_the_likelihood_and_old_campaigns_keep_theirs():
    """The repeat discount is on (2 m, power 0.5) and the intermittency conserves the mean
    only with the fluctuation likelihood; the filter and the reading model receive them; a
    campaign stored before them (no conserve_mean, repeat_radius 0, no repeat_power) compares
    equal to today's scenario with those values set, and not to today's defaults."""
    from dcee.runs import scenario_identity
    from dcee.runs.assemble import make_searcher
    from dcee.scenarios import load_scenario

    paper = load_scenario("paper:1")
    fluct = paper.with_overrides(**{"estimator.likelihood": "fluctuation", "unknown": "full"})
    assert (paper.repeat_radius, paper.repeat_power) == (0.0, 1.0)
    assert (fluct.repeat_radius, fluct.repeat_power) == (2.0, 0.5)
    explicit = fluct.with_overrides(**{"estimator.repeat_radius": 0.5})
    assert (explicit.repeat_radius, explicit.repeat_power) == (0.5, 0.5)
    rng = np.random.default_rng
    pf = make_searcher(fluct, None, rng(0), rng(1), on_robot=False).filter.current
    assert (pf.repeat_radius, pf.repeat_power, pf.sensor.conserve_mean) == (2.0, 0.5, True)
    calm = make_searcher(paper, None, rng(0), rng(1), on_robot=False).filter
    assert (calm.repeat_radius, calm.sensor.params.conserve_mean) == (0.0, 0.0)

    stored = fluct.model_dump(mode="json")
    del stored["estimator"]["conserve_mean"], stored["estimator"]["repeat_power"]
    stored["estimator"]["repeat_radius"] = 0.0
    pinned = fluct.with_overrides(
        **{"estimator.conserve_mean": False, "estimator.repeat_radius": 0.0}
    )
    assert scenario_identity(stored) == scenario_identity(pinned.model_dump(mode="json"))
    assert scenario_identity(stored) != scenario_identity(fluct.model_dump(mode="json"))


def test_a_pinned_later_setting_resumes_a_campaign_stored_before_it_existed():
    """`dcee bench --set estimator.conserve_mean=false` on a folder stored before the setting
    existed (no such override recorded) resumes it: the pin is the value that campaign ran
    with. Any other override still refuses (found by `studies/run.sh turbulent-public`)."""
    from dcee.runs.identity import settings_identity

    stored = {"suite": "paper", "overrides": {"estimator.likelihood": "fluctuation"}}
    pinned = {
        "suite": "paper",
        "overrides": {
            "estimator.conserve_mean": False,
            "estimator.likelihood": "fluctuation",
            "estimator.repeat_radius": 0.0,
        },
    }
    assert settings_identity(stored) == settings_identity(pinned)
    today = {**pinned, "overrides": {**pinned["overrides"], "estimator.conserve_mean": True}}
    assert settings_identity(stored) != settings_identity(today)
    alone = {"suite": "paper", "overrides": {"estimator.repeat_radius": 0.0}}
    assert settings_identity({"suite": "paper"}) == settings_identity(alone)
    assert settings_identity({"suite": "paper"}) != settings_identity(
        {"suite": "paper", "overrides": {"estimator.repeat_radius": 2.0}}
    )


_DRIVER = """
import signal, sys, time
from dcee.campaign.runner import SearchTask, _local_results
from tests.helpers import search_that_sleeps

def stop(signum, frame):
    raise KeyboardInterrupt
signal.signal(signal.SIGTERM, stop)
tasks = [SearchTask(sys.argv[1], "paper:1", "mpc", seed, {}) for seed in range(2)]
try:
    for _ in _local_results(tasks, 2, search=search_that_sleeps):
        pass
except KeyboardInterrupt:
    print("stopped", flush=True)
    sys.exit(143)
"""


def test_driver_answers_a_signal_while_every_search_is_still_running(tmp_path):
    """SIGTERM to the driver while both workers are inside minute-long searches: it must stop
    within seconds, not when a search ends (the signal may land on a pool thread; the driver's
    wait is bounded so that its handler runs)."""
    root = Path(__file__).resolve().parent.parent
    proc = subprocess.Popen(
        [sys.executable, "-c", _DRIVER, str(tmp_path / "c")],
        cwd=root,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    deadline = time.monotonic() + 60
    while len(list((tmp_path / "c").rglob("started"))) < 2:  # both searches are running
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the searches did not start in time"
        time.sleep(0.05)
    sent = time.monotonic()
    os.kill(proc.pid, signal.SIGTERM)
    out, err = proc.communicate(timeout=50)
    assert time.monotonic() - sent < 10, "the driver waited for a search to end"
    assert proc.returncode == 143 and "stopped" in out, err


def test_campaigns_flown_before_the_0_5_m_fall_keep_their_repeat_power():
    """Until 2026-11-27 the fluctuation likelihood's defaults were a 2.5 m near-source fall and
    a repeat power of 1/4; a campaign stored then (fall as a number, power unset) compares equal
    to today's scenario pinned to both, and not to today's defaults (0.5 m, power 1/2)."""
    from dcee.runs import scenario_identity
    from dcee.scenarios import load_scenario

    today = load_scenario("random:13").with_overrides(
        **{"estimator.likelihood": "fluctuation", "truth.model": "puffs"}
    )
    assert (today.estimator.near_source_length, today.repeat_power) == (0.5, 0.5)
    stored = today.model_dump(mode="json")
    stored["estimator"]["near_source_length"] = 2.5
    assert stored["estimator"]["repeat_power"] is None
    pinned = today.with_overrides(
        **{"estimator.near_source_length": 2.5, "estimator.repeat_power": 0.25}
    )
    assert scenario_identity(stored) == scenario_identity(pinned.model_dump(mode="json"))
    assert scenario_identity(stored) != scenario_identity(today.model_dump(mode="json"))
    at_half = today.with_overrides(
        **{"estimator.near_source_length": 2.5, "estimator.repeat_power": 0.5}
    )
    assert scenario_identity(stored) != scenario_identity(at_half.model_dump(mode="json"))


def test_an_override_that_changes_no_stored_scenario_keeps_the_campaign():
    """Overrides are applied to every stored scenario, which records their effect: pinning a
    default to the value it had (``--set estimator.near_source_length=2.5`` today, for a
    campaign flown when 2.5 m was the default) resumes it; an override that changes the
    scenarios does not."""
    from dcee.runs.identity import settings_identity
    from dcee.scenarios import load_scenario

    today = load_scenario("random:13").with_overrides(**{"estimator.likelihood": "fluctuation"})
    old = today.model_dump(mode="json")
    old["estimator"]["near_source_length"] = 2.5
    stored = {"suite": "s", "scenarios": {"random:13": old}, "overrides": {"truth.z": 4.0}}
    pinned = today.with_overrides(
        **{"estimator.near_source_length": 2.5, "estimator.repeat_power": 0.25}
    )
    now = {
        "suite": "s",
        "scenarios": {"random:13": pinned.model_dump(mode="json")},
        "overrides": {
            "truth.z": 4.0,
            "estimator.near_source_length": 2.5,
            "estimator.repeat_power": 0.25,
        },
    }
    assert settings_identity(stored) == settings_identity(now)
    moved = {**now, "scenarios": {"random:13": today.model_dump(mode="json")}}
    assert settings_identity(stored) != settings_identity(moved)


def test_a_fluctuation_campaign_stored_before_the_backflow_member_is_not_todays_default():
    """The fluctuation likelihood's unset ``estimator.learn`` weighs a backflow member and a
    disc member (at prior odds 9 : 1 against, ``learn_prior``) since issue 42: a campaign stored
    with no learned setting ({} or no key) or with the backflow member alone is not today's
    default, but resumes with the grid pinned; an explicit grid and prior equal to the default
    are the default; under the paper's likelihood nothing changed."""
    from dcee.runs import scenario_identity
    from dcee.scenarios import load_scenario

    fluct = load_scenario("paper:1").with_overrides(**{"estimator.likelihood": "fluctuation"})
    now = scenario_identity(fluct.model_dump(mode="json"))
    stored = fluct.model_dump(mode="json")
    stored["estimator"]["learn"] = {}
    missing = fluct.model_dump(mode="json")
    missing["estimator"].pop("learn")
    missing["estimator"].pop("backflow")
    assert scenario_identity(stored) != now
    assert scenario_identity(missing) == scenario_identity(stored)
    pinned = fluct.with_overrides(**{"estimator.learn": {}})
    assert scenario_identity(pinned.model_dump(mode="json")) == scenario_identity(stored)
    grid = {"backflow": [0.0, 0.05], "source_radius": [0.0, 1.0]}
    explicit = fluct.with_overrides(
        **{"estimator.learn": grid, "estimator.learn_prior": {"source_radius": [0.9, 0.1]}}
    )
    assert scenario_identity(explicit.model_dump(mode="json")) == now
    # the default grid given without its prior weighs every value equally: not the default
    equal = fluct.with_overrides(**{"estimator.learn": grid})
    assert scenario_identity(equal.model_dump(mode="json")) != now
    # stored at the defaults before the disc member (backflow only, no learn_prior key)
    backflow_only = fluct.with_overrides(**{"estimator.learn": {"backflow": [0.0, 0.05]}})
    before_disc = backflow_only.model_dump(mode="json")
    before_disc["estimator"].pop("learn_prior")
    assert scenario_identity(before_disc) != now
    assert scenario_identity(before_disc) == scenario_identity(
        backflow_only.model_dump(mode="json")
    )
    paper = load_scenario("paper:1").model_dump(mode="json")
    old_paper = load_scenario("paper:1").model_dump(mode="json")
    old_paper["estimator"].pop("learn")
    assert scenario_identity(paper) == scenario_identity(old_paper)
