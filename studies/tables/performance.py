"""Speed (recipes perf, search-speed, precision-*, agreement, stonesoup-mcts)."""

from __future__ import annotations

import json
import math
from collections.abc import Callable

import pandas as pd

from dcee.perf.machine import machine_identity
from dcee.provenance import same_code
from studies.tables.common import (
    RESULTS,
    acquired,
    paired,
    pick,
    rmse,
    share,
    study,
    table,
    time_to_1m,
)


def _perf(name: str) -> dict:
    return json.loads((RESULTS / "perf" / f"{name}.json").read_text(encoding="utf-8"))


def _timed(record: dict) -> str:
    """When and how a stored timing was taken: date, cores, and the load beside it."""
    load, machine = record["load"], record["machine"]
    when = (load.get("started") or "")[:10]
    other = load.get("other_cores")
    if load.get("idle") is True:
        state = "idle"
    elif other is None:
        state = "load unknown"
    else:
        state = f"**shared** (other processes {other:.1f} cores)"
    commit = (machine.get("code", {}).get("commit") or "")[:7]
    cpu = machine_identity(machine) if machine.get("cpu_model") else f"{machine['cpus']} CPUs"
    return f"{when}, {cpu}, {state}, `{commit}`"


def _repeats_text(result: dict) -> str:
    """How many runs of the alternation a comparison's figures are the median of."""
    n = result.get("repeats", 1)
    return f"; the median of {n} such runs in one process" if n > 1 else ""


def _stonesoup_runs() -> dict[str, list[dict]]:
    """Every stored Stone Soup comparison by kind (``ste``, ``mcts``;
    docs/results/perf/stonesoup-runs, studies/archive_stonesoup_runs.py), the lowest ratio
    first (the published figure: the lowest of its code's runs, :func:`_of_newest_code`)."""
    out: dict[str, list[dict]] = {"ste": [], "mcts": []}
    for path in sorted((RESULTS / "perf" / "stonesoup-runs").glob("*.json")):
        record = json.loads(path.read_text(encoding="utf-8"))
        out[path.name.split("-", 1)[0]].append(record)
    out["ste"].sort(key=lambda r: r["stonesoup"]["speedup"])
    out["mcts"].sort(key=lambda r: r["speedup"])
    return out


def _of_newest_code(records: list[dict]) -> tuple[list[dict], int]:
    """The runs (lowest ratio first, as given) of the code the newest run measured (the same
    package source, :func:`dcee.provenance.same_code`), and how many runs measured other code:
    a speed-up is a property of one code version, so the published figure is the lowest of
    that version's runs, every machine and day; earlier code's runs stay in the runs table."""
    newest = max(records, key=lambda r: r["load"].get("started") or "")
    code = newest["machine"].get("code")
    same = [r for r in records if same_code(r["machine"].get("code"), code)]
    return same, len(records) - len(same)


def _lowest_text(records: list[dict], ratio: Callable[[dict], float], earlier: int = 0) -> str:
    """Where a row's figure is the lowest of several stored runs of its code, say so and list
    the others; say how many runs of earlier code the runs table also holds."""
    text = ""
    if len(records) > 1:
        others = ", ".join(
            f"{ratio(r):.1f}× on {(r['load'].get('started') or '')[:10]}" for r in records[1:]
        )
        text = f"; the lowest of {len(records)} stored runs of this code (the others: {others})"
    elif earlier:
        text = "; one stored run of this code"
    if earlier:
        text += f"; {earlier} of earlier code in the runs table below"
    return text


def stonesoup_runs_table() -> str:
    """Every stored Stone Soup comparison, one row a run, with the machine that ran it."""
    runs = _stonesoup_runs()
    rows = []
    for r in runs["ste"]:
        ss = r["stonesoup"]
        spread = (
            " ({:.1f}-{:.1f}×)".format(*ss["speedup_range"]) if ss.get("repeats", 1) > 1 else ""
        )
        rows.append(
            [
                "`infotaxis` vs Stone Soup's KL planner (STE workload)",
                f"{ss['speedup']:.1f}×{spread}",
                f"{ss['dcee_infotaxis_median_ms']:.2f} ms vs {ss['stonesoup_median_ms']:.1f} ms",
                _timed(r),
            ]
        )
    for r in runs["mcts"]:
        rows.append(
            [
                "`dcee-mcts` vs Stone Soup's MCTS (its published example)",
                f"{r['speedup']:.1f}×",
                f"{r['dcee_median_ms']:.1f} ms vs {r['stonesoup_median_ms']:.0f} ms",
                _timed(r),
            ]
        )
    return table(
        ["comparison", "ratio (runs)", "absolute", "timed (date, machine, load, code)"], rows
    )


def _mcts_row(mcts: dict, what: str) -> list[str]:
    """A row of the speed table for a stored MCTS comparison (studies/stonesoup_mcts_study.py)."""
    return [
        what,
        f"{mcts['speedup']:.1f}× faster at the median decision"
        + (
            f" ({mcts['first10_speedup']:.0f}× over each search's first ten)"
            if "first10_speedup" in mcts
            else ""
        )
        + "; final x-y RMSE "
        f"{mcts['dcee_median_final_rmse']:.2f} m vs {mcts['stonesoup_median_final_rmse']:.2f}"
        f" m (lower in {mcts['dcee_lower_rmse']}/{mcts['seeds']})",
        f"{mcts['dcee_median_ms']:.1f} ms vs {mcts['stonesoup_median_ms']:.0f} ms",
        "≥ 50×, lower RMSE",
        _timed(mcts),
    ]


def speed_table() -> str:
    """Speed, from the stored `dcee perf` outputs of docs/results/perf/ (bash studies/run.sh
    perf): every ratio's two sides timed in the same run."""
    runs = _stonesoup_runs()
    ste_runs, ste_earlier = _of_newest_code(runs["ste"])
    mcts_runs, mcts_earlier = _of_newest_code(runs["mcts"])
    ste, mcts, work = ste_runs[0], mcts_runs[0], _perf("workloads")
    by_name = {w["name"]: w for w in work["workloads"]}
    rows = [
        [
            "our `infotaxis` decision vs Stone Soup's KL planner on Stone Soup's own STE "
            f"workload, {ste['stonesoup']['decisions']} decisions each, in alternation"
            + _repeats_text(ste["stonesoup"]),
            f"{ste['stonesoup']['speedup']:.1f}× faster"
            + (
                " (runs {:.1f}-{:.1f}×)".format(*ste["stonesoup"]["speedup_range"])
                if ste["stonesoup"].get("repeats", 1) > 1
                else ""
            )
            + _lowest_text(ste_runs, lambda r: r["stonesoup"]["speedup"], ste_earlier),
            f"{ste['stonesoup']['dcee_infotaxis_median_ms']:.2f} ms vs "
            f"{ste['stonesoup']['stonesoup_median_ms']:.1f} ms",
            "≥ 50×",  # TARGET_SPEEDUP of dcee.perf.stonesoup_compare (older runs stored 20)
            _timed(ste),
        ],
        _mcts_row(
            mcts,
            f"our tree search (`{mcts['strategy']}`) vs Stone Soup's "
            f"`MCTSRolloutSensorManager` on its MCTS STE example as published (Glover et al. "
            f"2024: every setting in `docs/results/perf/stonesoup-mcts.json`), seeds "
            f"0-{mcts['seeds'] - 1}"
            + _lowest_text(mcts_runs, lambda r: r["speedup"], mcts_earlier),
        ),
        _mcts_row(
            _perf("stonesoup-mcts-weight-cached"),
            "the same as stored on 2026-11-26, a labelled variant and not the published "
            "example: our per-move bookkeeping read Stone Soup's `state.weight`, which caches "
            "10,000 Probability objects on each state for every tree node's deepcopy to copy",
        ),
    ]
    work_rows = (
        ("dcee-decision-20k", "floor", "a paper-scale `dcee` decision (20,000 particles, 8 moves "
         "× 40 readings) vs the plain compiled loop computing the same statistics exactly",
         "≤ 1.5×"),
        ("infotaxis-decision-20k", "floor", "the same for `infotaxis`", "≤ 1.5×"),
        ("dcee-mcts-decision-20k", "dcee-cl-decision", "a `dcee-mcts` decision vs a `dcee-cl` "
         "decision computed exactly, 20,000 particles, in alternation", "≤ 3×"),
        ("resample-mcmc-500-readings-20k", "filter-update", "resample + MCMC move over 500 "
         "readings vs one filter update, 20,000 particles", "≤ 76×"),
    )  # fmt: skip
    for name, reference, label, target in work_rows:
        w = by_name[name]
        ratio = w["ratio_to"][reference]
        rows.append([label, f"{ratio:.2f}×", f"{w['median']:.3g} ms", target, _timed(work)])
    move_path = RESULTS / "perf" / "move-speedup.json"
    if move_path.exists():  # studies/move_speedup.py: what moved the move / update ratio
        move = _perf("move-speedup")
        rows.append(
            [
                "the same move and one filter update vs commit "
                f"`{move['before']}` (the move / update ratio "
                f"{move['before_ratio']:.0f}× there), each side in a fresh process, in "
                "alternation",
                f"move {move['move_speedup']:.2f}× faster, update "
                f"{move['update_speedup']:.2f}× faster (ratio {move['after_ratio']:.0f}× today)",
                f"{move['after_move_ms']:.3g} ms vs {move['before_move_ms']:.3g} ms",
                "the move no slower",
                _timed(move),
            ]
        )
    # issue 46: the default (interpolated sums) and precision=single against the exact decision
    for name, label in (
        ("dcee-cl-decision-20k", "the default (`precision=interpolated`)"),
        ("dcee-cl-single-decision-20k", "`precision=single`"),
    ):
        w = by_name[name]
        if "dcee-cl-double-decision" not in w["ratio_to"]:
            continue  # runs stored before the interpolated sums
        rows.append(
            [
                f"a paper-scale `dcee-cl` decision with {label} vs the same computed exactly in "
                "double precision, in alternation",
                f"{w['ratio_to']['dcee-cl-double-decision']:.2f}×",
                f"{w['median']:.3g} ms",
                "—",
                _timed(work),
            ]
        )
    demo_path = RESULTS / "perf" / "demo-decision.json"
    if demo_path.exists():  # studies/demo_decision.py (issue 46)
        demo = _perf("demo-decision")
        rows.append(
            [
                "the demo's search (`paper:1`, `dcee-cl`, seed 0, 20,000 particles): mean "
                f"decision on one pinned core, against commit `{demo['before']}` in alternation"
                + ("" if demo["same_search"] else " (**the two flew different searches**)"),
                f"{demo['speedup']:.2f}× faster",
                f"{demo['after_ms']:.1f} ms vs {demo['before_ms']:.1f} ms",
                f"≤ {demo['target_ms']:.0f} ms",
                _timed(demo),
            ]
        )
    cl = by_name["dcee-cl-decision-20k"]
    rows.append(
        [
            "a paper-scale `dcee-cl` decision (20,000 particles, 8 moves × 40 readings), "
            f"{work['machine']['numba_threads']} threads",
            "—",
            f"{cl['median']:.3g} ms",
            "—",
            _timed(work),
        ]
    )
    return table(["comparison (both sides in the same run)", "ratio", "absolute", "target",
                  "timed (date, machine, load, code)"], rows)  # fmt: skip


def kernel_speedup_table(name: str = "kernel-speedup") -> str:
    """The predicted-posterior kernel before and after issue 46's changes, in alternation in one
    run (studies/kernel_speedup.py, docs/results/perf/kernel-speedup.json; the second round,
    the sums as matrix products: kernel-speedup-blas.json)."""
    record = _perf(name)
    rows = [
        [
            w["workload"],
            f"{w['tasks']} × {w['particles']:,}",
            f"{w['before_ms']:.1f} ms",
            f"{w['after_ms']:.1f} ms",
            f"**{w['speedup']:.2f}×**",
            f"{w['max_abs_difference']:.0e}",
        ]
        for w in record["workloads"]
    ]
    rows.append(["timed", _timed(record), f"before: `{record['before']}`", "", "", ""])
    return table(
        ["workload", "tasks × particles", "before", "after", "speed-up", "largest difference"],
        rows,
    )


def precision_single_table(
    name: str = "precision-single",
    double: str = "dcee-cl",
    single: str = "dcee-cl:precision=single",
    label: str = "single",
) -> str:
    """`dcee-cl` in single and double precision on the public study's 120 searches, paired
    (bash studies/run.sh precision-single; docs/results/precision-single); with the other
    arguments the interpolated sums against exact double precision
    (docs/results/precision-interpolated)."""
    metrics, pairs = study(name), paired(name)
    searches = pd.read_csv(RESULTS / name / "searches.csv")
    ms = {k: 1e3 * g["decision_seconds_mean"] for k, g in searches.groupby("strategy")}
    rows = []
    for strategy in (double, single):
        r = pick(metrics, strategy)
        rows.append(
            [
                f"`{strategy}`",
                acquired(r),
                share(r, "truth_in_95"),
                rmse(r),
                time_to_1m(r),
                f"{ms[strategy].mean():.1f}",
            ]
        )
    p = pick(pairs, single)
    both = searches.pivot_table(index=["scenario", "seed"], columns="strategy",
                                values="decision_seconds_mean")  # fmt: skip
    ratio = float((both[single] / both[double]).median())
    final = searches.pivot_table(index=["scenario", "seed"], columns="strategy",
                                 values="final_rmse")  # fmt: skip
    same = int((abs(final[single] - final[double]) < 1e-9).sum())
    time_diff, time_p = p["time_to_1m_difference"], p["time_wilcoxon_p"]
    reach = searches.pivot_table(index=["scenario", "seed"], columns="strategy",
                                 values="time_to_rmse_1m")  # fmt: skip
    if not math.isnan(time_diff):
        time_cell = f"{time_diff:+.0f} s (p = {time_p:.2g})"
    elif (reach[single] == reach[double]).all():  # no nonzero difference for a test to use
        time_cell = "0 s in every pair"
    else:
        time_cell = "—"
    rows.append(
        [
            f"paired, {label} − double ({same}/{len(final)} searches end at the same final RMSE "
            "to 1e-9 m)",
            f"{int(p['acquired_variant_only'])} / {int(p['acquired_reference_only'])} acquired "
            f"only by one (McNemar p = {p['mcnemar_p']:.2g})",
            "",
            f"{p['final_rmse_difference']:+.3f} m "
            + (
                "(equal in every pair)"
                if math.isnan(p["rmse_wilcoxon_p"])  # no nonzero difference for a test to use
                else f"(Wilcoxon p = {p['rmse_wilcoxon_p']:.2g})"
            ),
            time_cell,
            f"{ratio:.2f}× per search (median of {len(both)} pairs)",
        ]
    )
    return table(
        ["planner", "source acquired (RMSE < 3 m)", "truth in 95 % region",
         "median final RMSE (m)", "median time to RMSE < 1 m (s)", "mean decision (ms)"],
        rows,
    )  # fmt: skip


def agreement_single_table(name: str = "agreement-single", whole: str | None = None) -> str:
    """Decisions with ``precision=single`` against today's double-precision full computation,
    per planner (studies/decision_agreement.py, docs/results/perf/agreement-single.json); with
    ``name="agreement-interpolated"`` the interpolated sums, and the whole searches of
    ``whole`` (the same check over every decision of longer searches) in a last row."""
    record = _perf(name)
    settings = record["settings"]
    rows = []
    for strategy in settings["strategies"]:
        mine = [r for r in record["searches"] if r["strategy"] == strategy]
        decisions = sum(r["decisions"] for r in mine)
        same = sum(r["same_choice"] for r in mine)
        worst = max(r["max_cost_diff_over_spread"] for r in mine)
        rows.append([f"`{strategy}`", f"{same}/{decisions}", f"{worst:.0e}"])
    rows.append(
        [
            "**all**",
            f"**{record['same_choice']}/{record['decisions']}** "
            f"({100 * record['same_choice'] / record['decisions']:.1f} %)",
            f"{record['max_cost_diff_over_spread']:.0e}",
        ]
    )
    commit = (record["machine"].get("code", {}).get("commit") or "")[:7]
    rows.append(
        [
            "settings",
            f"{', '.join(settings['configs'])}; seeds 0-{settings['seeds'] - 1}; "
            f"{settings['steps']} decisions per search; {settings['particles']:,} particles",
            f"`{commit}`",
        ]
    )
    if whole is not None and (RESULTS / "perf" / f"{whole}.json").exists():
        full = _perf(whole)
        fs = full["settings"]
        rows.append(
            [
                f"whole searches: `{'`, `'.join(fs['strategies'])}`, {', '.join(fs['configs'])}, "
                f"seed 0, up to {fs['steps']} decisions each",
                f"**{full['same_choice']}/{full['decisions']}** "
                f"({100 * full['same_choice'] / full['decisions']:.1f} %)",
                f"{full['max_cost_diff_over_spread']:.0e}",
            ]
        )
    return table(
        ["planner", "same choice as exact double precision", "largest cost difference / spread"],
        rows,
    )


def search_speed_table() -> str:
    """Whole searches of the public study's five planners on one pinned core, two code
    versions in alternation (studies/search_speed.py, docs/results/perf/search-speed.json)."""
    record = _perf("search-speed")
    rows = []
    total = {"before": 0.0, "after": 0.0}
    for planner, row in record["summary"].items():
        c, d, u = row["wall_s"], row["decision_s"], row["update_s"]
        for side in total:
            total[side] += c[side]
        rows.append(
            [
                f"`{planner}`",
                f"{c['before']:.2f} → **{c['after']:.2f}** ({c['before'] / c['after']:.2f}×)",
                f"{d['before']:.2f} → {d['after']:.2f}",
                f"{u['before']:.2f} → {u['after']:.2f}",
                "yes" if row["same_search"] else "no (last-digit differences diverge)",
            ]
        )
    rows.append(
        [
            "**all five** (one search each)",
            f"{total['before']:.1f} → **{total['after']:.1f}** "
            f"({total['before'] / total['after']:.2f}×)",
            "",
            "",
            "",
        ]
    )
    study = {side: 120 * total[side] / 2 / 60 for side in total}
    rows.append(
        [
            "the 600-search study on 2 workers at these costs (a projection, not a measurement: "
            "120 × the sum / 2)",
            f"{study['before']:.0f} → {study['after']:.0f} min",
            "",
            "",
            _timed(record) + f", against `{record['before']}`",
        ]
    )
    # studies/study_wall.py: the campaign itself, measured; every stored run (the machine's
    # speed differs from day to day: the same code took 25.1 and 13.5 min), the latest last
    for study_path in sorted(
        (RESULTS / "perf").glob("study-600*.json"), key=lambda p: (p.stem == "study-600", p.stem)
    ):
        run = _perf(study_path.stem)
        means = ", ".join(f"{k} {v['mean_wall_s']:.1f} s" for k, v in run["per_planner"].items())
        rows.append(
            [
                f"the study measured: `dcee bench --suite paper --repeats 10 --workers 2`, "
                f"{run['searches']} searches (mean per search: {means})",
                f"**{run['wall_seconds'] / 60:.1f} min** (bar ≤ {run['target_minutes']:.0f} min)",
                "",
                "",
                f"{run['campaign_code'].get('commit', '')[:7]}, 2 workers, nothing else run",
            ]
        )
    for extra in sorted((RESULTS / "perf").glob("search-speed-*.json")):
        # the code of an earlier study run against today's, in one run: how much of a change in
        # the study's wall time is the code's and how much the machine's day
        rec = _perf(extra.stem)
        sums = {
            side: sum(row["wall_s"][side] for row in rec["summary"].values())
            for side in ("before", "after")
        }
        same = all(v["same_search"] for v in rec["summary"].values())
        rows.append(
            [
                f"the five searches with the code of `{rec['before']}` and of today, in one run "
                "(`studies/search_speed.py`): the two study rows above differ by the machine's "
                "day, not the code",
                f"{sums['before']:.1f} → {sums['after']:.1f} s "
                f"({sums['before'] / sums['after']:.2f}×)",
                "",
                "",
                ("yes" if same else "no") + "; " + _timed(rec),
            ]
        )
    return table(["planner (`paper:1`, seed 0, 20,000 particles, 450 readings)",
                  "wall per search (s)", "decisions (s)", "filter updates (s)",
                  "same search"], rows)  # fmt: skip
