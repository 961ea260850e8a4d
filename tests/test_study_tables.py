"""The paired study tables (studies/ablation_table.py, studies/pair_campaigns.py) against hand
counts, read from a stored study's per-search rows (the searches.csv that
studies/collect_metrics.py writes), and a stored generation kept by collect_metrics."""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

ROOT = Path(__file__).resolve().parent.parent


def _script(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "studies" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(module)
    return module


def _stored(tmp_path: Path) -> Path:
    """Two planners on six configurations, two truths; hand-made so the counts are known."""
    rows = []
    for truth in ("a", "b"):
        for k in range(6):
            # reference: acquires 0-3; its time to 1 m 100 s + 10 k where acquired
            rows.append(
                ("ref", truth, k, k < 4, 0.5 + 0.1 * k, True, 100.0 + 10 * k if k < 4 else None)
            )
            # variant: acquires 0-4 (one more), 20 s sooner wherever both got there
            rows.append(
                ("var", truth, k, k < 5, 0.4 + 0.1 * k, k != 0, 80.0 + 10 * k if k < 5 else None)
            )
    frame = pd.DataFrame(
        [
            {
                "scenario": f"random:{1000 + k}",
                "seed": 0,
                "strategy": s,
                "truth_model": t,
                "source_acquired": acq,
                "final_rmse": rmse,
                "truth_in_95": cover,
                "time_to_rmse_1m": when,
                "longest_stall": 30.0 + k,
            }
            for s, t, k, acq, rmse, cover, when in rows
        ]
    )
    path = tmp_path / "study" / "searches.csv"
    path.parent.mkdir()
    frame.to_csv(path, index=False)
    return path


def test_paired_table_from_a_stored_study_matches_hand_counts(tmp_path: Path) -> None:
    table_module = _script("ablation_table")
    path = _stored(tmp_path)
    table = table_module.compare(f"{path}=ref:truth_model:a", [f"{path}=var:truth_model:a"])
    ref, var = table.iloc[0], table.iloc[1]
    assert (ref["pairs"], ref["acquired"], var["acquired"]) == (6, 4, 5)
    assert (var["acquired_reference_only"], var["acquired_variant_only"]) == (0, 1)
    assert var["mcnemar_p"] == pytest.approx(1.0)  # one discordant pair: p = 1 exactly
    assert var["truth_in_95"] == 5
    # both got there on k = 0..3, 20 s sooner each time: the median difference is -20 s
    assert var["time_to_1m_difference"] == pytest.approx(-20.0)
    assert var["time_wilcoxon_p"] == pytest.approx(0.125)  # exact, n = 4, every sign negative
    # median over all six, a search that never got there later than all: (100+110)/2 for k 2, 3
    assert var["time_to_1m"] == pytest.approx(105.0)
    assert ref["time_to_1m"] == pytest.approx(125.0)
    assert var["final_rmse_difference"] == pytest.approx(-0.1)
    assert var["longest_stall"] == 35.0 and var["stalled"] == 0
    assert math.isnan(ref["time_to_1m_difference"])


def test_paired_table_refuses_rows_of_several_studies(tmp_path: Path, capsys) -> None:
    table_module = _script("ablation_table")
    path = _stored(tmp_path)
    for arg, says in (
        (f"{path}=ref", "several studies"),
        (f"{tmp_path / 'none' / 'searches.csv'}=ref", "no such stored study"),
        (f"{path}=ref:truth_model:c", "no search matches"),
    ):
        with pytest.raises(SystemExit) as stop:
            table_module.compare(arg, [])
        assert stop.value.code == 2
        err = capsys.readouterr().err
        assert says in err and err.count("\n") == 1


def test_pair_campaigns_pairs_two_generations_of_a_stored_study(tmp_path: Path, capsys) -> None:
    pair = _script("pair_campaigns")
    path = _stored(tmp_path)
    frame = pd.read_csv(path)
    # a second generation: the reference planner ("ref") 0.2 m closer everywhere, covering k = 5
    later = frame[frame["truth_model"] == "a"].assign(truth_model="later")
    later.loc[later["strategy"] == "ref", "final_rmse"] -= 0.2
    later.loc[later["strategy"] == "ref", "source_acquired"] = True
    pd.concat([frame, later]).to_csv(path, index=False)
    out = tmp_path / "pairs.csv"
    assert pair.main([f"{path}=truth_model:a", f"{path}=truth_model:later", "--csv", str(out)]) == 0
    rows = pd.read_csv(out).set_index("strategy")
    ref, var = rows.loc["ref"], rows.loc["var"]
    assert (ref["pairs"], ref["acquired_a_only"], ref["acquired_b_only"]) == (6, 0, 2)
    assert ref["median_rmse_b_minus_a"] == pytest.approx(-0.2)
    assert ref["rmse_wilcoxon_p"] == pytest.approx(2 / 2**6)  # exact, n = 6, every sign negative
    assert (var["acquired_b_only"], var["median_rmse_b_minus_a"], var["rmse_wilcoxon_p"]) == (
        0, 0.0, 1.0,
    )  # fmt: skip
    for spec, says in ((f"{path}=truth_model", "KEY:VALUE pairs"), (f"{path}", "pick one")):
        with pytest.raises(SystemExit) as stop:
            pair.main([spec, f"{path}=truth_model:a"])
        assert stop.value.code == 2 and says in capsys.readouterr().err


def test_pair_campaigns_pairs_a_planner_option_with_the_planner(tmp_path: Path, capsys) -> None:
    """``--as SPEC=NAME``: side b's planner option ``var:opt=2`` (the variant rows renamed)
    paired with side a's ``ref``: the variant's hand counts against the reference's."""
    pair = _script("pair_campaigns")
    path = _stored(tmp_path)
    frame = pd.read_csv(path)
    ref, var = frame[frame["strategy"] == "ref"], frame[frame["strategy"] == "var"]
    ref.to_csv(tmp_path / "ref.csv", index=False)
    var.assign(strategy="var:opt=2").to_csv(tmp_path / "var.csv", index=False)
    out = tmp_path / "pairs.csv"
    a, b = f"{tmp_path / 'ref.csv'}=truth_model:a", f"{tmp_path / 'var.csv'}=truth_model:a"
    assert pair.main([a, b, "--as", "var:opt=2=ref", "--csv", str(out)]) == 0
    row = pd.read_csv(out).set_index("strategy").loc["ref"]
    # the variant (b) acquires k = 4 that the reference (a) does not; 0.1 m closer everywhere;
    # the region: the variant misses k = 0, which the reference holds
    assert (row["pairs"], row["acquired_a_only"], row["acquired_b_only"]) == (6, 0, 1)
    assert row["median_rmse_b_minus_a"] == pytest.approx(-0.1)
    assert (row["in95_a_only"], row["in95_b_only"]) == (1, 0)
    with pytest.raises(SystemExit) as stop:
        pair.main([a, b, "--as", "=ref"])
    assert stop.value.code == 2 and "SPEC=NAME" in capsys.readouterr().err


def test_collect_metrics_keeps_a_stored_generation(tmp_path: Path, capsys) -> None:
    collect = _script("collect_metrics")
    out = _stored(tmp_path).parent
    pd.DataFrame(
        [{"strategy": s, "truth_model": t, "searches": 6} for s in ("ref", "var") for t in "ab"]
    ).to_csv(out / "metrics.csv", index=False)
    # no campaign to add: the kept generation alone is written back, the rest dropped
    assert collect.main(["--out", str(out), "--keep", "truth_model:a"]) == 0
    assert set(pd.read_csv(out / "metrics.csv")["truth_model"]) == {"a"}
    kept = pd.read_csv(out / "searches.csv")
    assert set(kept["truth_model"]) == {"a"} and len(kept) == 12
    assert not (out / "pairwise.csv").exists()
    assert collect.main(["--out", str(out), "--keep", "truth_model:c"]) == 2
    assert collect.main(["--out", str(out), "--keep", "planner:a"]) == 2
    assert capsys.readouterr().err.count("\n") == 2


def test_count_prior_sweep_by_hand(tmp_path: Path, capsys) -> None:
    """Two stored searches, true counts 2 and 3, each answering two under the equal prior:
    P(K) ∝ r^K with r = 1 gets one right, r = 30 turns both to three (one right), r = 2 only
    the search whose P(K = 3) was 0.4 (two right); a folder without searches is refused."""
    import json

    sweep = _script("count_prior_sweep")
    folder = tmp_path / "camp"
    for name, probs, true in (("a", [0.0, 0.0, 0.6, 0.4], 3), ("b", [0.0, 0.05, 0.9, 0.05], 2)):
        run = folder / "runs" / f"config={name}" / "strategy=dcee-cl" / "seed=0"
        run.mkdir(parents=True)
        summary = {"count_probabilities": probs, "true_sources": true}
        (run / "summary.json").write_text(json.dumps(summary))
    assert sweep.right_counts(folder, 1.0) == (1, 2)
    assert sweep.right_counts(folder, 2.0) == (2, 2)
    assert sweep.right_counts(folder, 30.0) == (1, 2)
    assert sweep.main([str(folder)]) == 0
    assert "| r = 2 | 2/2 |" in capsys.readouterr().out
    assert sweep.main([str(tmp_path / "empty")]) == 2
    assert "no finished searches" in capsys.readouterr().err


def _count_rows(campaign: str, correct: list[bool], ospa: list[float]) -> list[dict]:
    return [
        {
            "campaign": campaign,
            "scenario": f"random:{k}",
            "strategy": "dcee-cl",
            "seed": 0,
            "true_count": 1,
            "estimated_count": 1 if ok else 2,
            "count_correct": ok,
            "p_estimated": float("nan"),
            "p_true": float("nan"),
            "final_ospa": d,
            "worst_release_error": d,
            "mean_release_error": d,
            "explore_guard_fired": 0,
            "least_reached_readings": 5,
            "decision_ms": 1.0,
            "code": "",
        }
        for k, (ok, d) in enumerate(zip(correct, ospa, strict=True))
    ]


def test_the_source_count_tables_pair_named_campaigns_and_list_todays_only() -> None:
    script = _script("source_count_table")
    unknown, known = script.PAIRS[0]
    rows = _count_rows(unknown, [True, True, False, True], [0.3, 0.2, 3.0, 0.5])
    rows += _count_rows(known, [True, True, True, True], [0.1, 0.1, 0.2, 0.1])
    rows += _count_rows("two-source-held-out-100-before", [True] * 4, [0.1] * 4)
    frame = pd.DataFrame(rows)
    latest = script.table_latest(frame)
    assert unknown in latest and known in latest and "-before" not in latest
    assert "| — |" in latest  # no count probabilities: no median P(K̂)
    paired = script.paired(frame).splitlines()
    (row,) = [line for line in paired if line.startswith(f"| {unknown} − {known} ")]
    # one search right only with the count known; OSPA differences 0.2, 0.1, 2.8, 0.4
    assert "| 4 | 0 / 1 (p = 1) |" in row
    assert "+0.30" in row


def test_the_source_count_csv_keeps_the_campaigns_a_study_did_not_fly() -> None:
    script = _script("source_count_table")
    stored = pd.DataFrame(_count_rows("a", [True], [0.1]) + _count_rows("b", [True], [0.2]))
    new = pd.DataFrame(_count_rows("b", [False, True], [1.0, 0.3]))
    merged = script.merged_rows(stored, new)
    assert sorted(merged["campaign"]) == ["a", "b", "b"]
    assert list(merged.loc[merged["campaign"] == "b", "final_ospa"]) == [1.0, 0.3]
    assert script.merged_rows(None, new) is new
    # a replaced campaign keeps its place in the tables, a new one comes after the stored ones
    first = pd.DataFrame(_count_rows("a", [False], [2.0]) + _count_rows("c", [True], [0.5]))
    assert list(dict.fromkeys(script.merged_rows(stored, first)["campaign"])) == ["a", "b", "c"]


def test_the_source_count_tables_pair_two_planners_on_the_same_configurations() -> None:
    script = _script("source_count_table")
    rows = _count_rows("two-source-held-out-100", [True, False, True], [0.3, 2.0, 0.4])
    other = _count_rows("two-source-held-out-100-infotaxis", [True, True, True], [0.2, 0.5, 0.4])
    for row in other:
        row["strategy"] = "infotaxis"
    frame = pd.DataFrame(rows + other)
    assert "two-source-held-out-100-infotaxis | infotaxis" in script.table_latest(frame)
    paired = script.paired(frame).splitlines()
    (row,) = [line for line in paired if "-infotaxis − two-source-held-out-100 " in line]
    # paired by scenario and seed across planners: one search right only with infotaxis
    assert "| 3 | 1 / 0 (p = 1) |" in row and "-0.10" in row


def test_the_climbing_campaign_replaces_the_fixed_altitude_one_among_todays() -> None:
    """X-climb (today's defaults, the UAV free to climb) stands for X in the latest table and is
    paired with it on the same configurations; X without X-climb stays today's."""
    script = _script("source_count_table")
    fixed = _count_rows("three-source-held-out-100", [True, False, False], [0.5, 2.0, 1.5])
    climb = _count_rows("three-source-held-out-100-climb", [True, True, False], [0.3, 0.4, 1.4])
    two = _count_rows("two-source-held-out-100", [True], [0.2])
    frame = pd.DataFrame(fixed + climb + two)
    latest = script.table_latest(frame)
    assert "| three-source-held-out-100-climb |" in latest
    assert "| three-source-held-out-100 |" not in latest
    assert "| two-source-held-out-100 |" in latest
    (row,) = [line for line in script.paired(frame).splitlines() if "-climb − " in line]
    # one search right only when climbing; OSPA differences −0.2, −1.6, −0.1
    assert "| 3 | 1 / 0 (p = 1) |" in row and "-0.20" in row


def test_a_releases_footprint_is_where_one_reading_detects_its_gas() -> None:
    """The footprint counts the 0.5 m cells of the flight plane where one reading detects the
    release's mean gas with probability ≥ 0.1: by hand from the sensor's Pd and noise on
    paper:1; a release made ten times weaker covers less ground; one at the ground at the
    downwind edge whose gas leaves the area (random2:1073's first) covers none."""
    script = _script("source_count_table")
    from dcee.models import IsotropicPlume
    from dcee.scenarios import load_scenario

    paper = load_scenario("paper:1")
    sensor = paper.make_sensor()
    cells = np.arange(0.25, 50.0, 0.5)
    gx, gy = np.meshgrid(cells, cells, indexing="ij")
    points = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, 4.0)])
    conc = IsotropicPlume().concentration(paper.truth_thetas(), points)[0]
    # P(detection | C) = Pd Φ((C − threshold) / σ(C)), σ = σ_frac C + σ_min (no false alarms)
    sigma = sensor.sigma_frac * conc + sensor.sigma_min
    p_detect = sensor.pd * stats.norm.cdf((conc - sensor.threshold) / sigma)
    assert sensor.false_alarm == 0.0 and sensor.outlier == 0.0
    by_hand = (p_detect >= 0.1).sum() * 0.25
    (footprint,) = script.release_footprints(paper)
    assert footprint == pytest.approx(by_hand) and footprint > 100.0
    weak = paper.model_copy(
        update={"truth": paper.truth.model_copy(update={"q": paper.truth.q / 10})}
    )
    assert 0 < script.release_footprints(weak)[0] < footprint
    assert script.release_footprints(load_scenario("random2:1073"))[0] == 0.0


def test_the_observable_table_keeps_searches_whose_every_release_has_a_footprint() -> None:
    script = _script("source_count_table")
    rows = _count_rows("two-source-held-out-100", [False, True, True], [2.0, 0.3, 0.4])
    frame = pd.DataFrame(rows).drop(columns=["least_footprint_m2"], errors="ignore")
    frame["scenario"] = ["random2:1073", "random2:1000", "random2:1001"]
    filled = script.with_footprints(frame)
    assert filled.loc[0, "least_footprint_m2"] == 0.0  # computed from the scenario
    assert (filled.loc[1:, "least_footprint_m2"] >= script.OBSERVABLE_M2).all()
    # what a row read from a campaign folder gets: the configuration's, not the folder's
    assert filled.loc[1, "least_footprint_m2"] == script.least_footprint("random2:1000")
    table = script.observable(filled)
    assert "| 2 | 2/2 (100 %)" in table  # the unobservable search is left out


def test_lbm_endgame_by_hand(tmp_path: Path) -> None:
    """One made-up search: the wind from 180° (φ = π, the gas goes towards +x), the release at
    (10, 10); in the last 300 s readings at along-wind −1, −2, +2, −1 m, detections at the
    first, third and fourth; the final mean at (9.5, 10.5)."""
    endgame = _script("lbm_endgame")
    run = tmp_path / "run"
    run.mkdir()
    (run / "config.json").write_text(
        '{"strategy": "dcee-cl:horizon=2", "scenario": {"truth": {"x": 10, "y": 10, "phi": 180}}}'
    )
    (run / "summary.json").write_text(
        '{"scenario": "random:13", "final_rmse": 0.8, "truth_in_95": true, "version": "v"}'
    )
    x = [0.0, 4.0, 6.0, 9.0, 8.0, 12.0, 9.0]
    pd.DataFrame(
        {
            "time": [0.0, 100.0, 200.0, 300.0, 400.0, 500.0, 600.0],
            "x": x,
            "y": [10.0] * 7,
            "detection": [False, False, True, True, False, True, True],
            "mean_x": [20.0] * 6 + [9.5],
            "mean_y": [20.0] * 6 + [10.5],
            "spread": [5.0] * 6 + [0.25],
        }
    ).to_parquet(run / "steps.parquet")
    row = endgame.endgame(run)
    assert row["strategy"] == "dcee-cl:horizon=2" and row["scenario"] == "random:13"
    assert row["late_along_median_m"] == pytest.approx(-1.0)
    assert row["late_distance_median_m"] == pytest.approx(1.5)  # 1, 2, 2, 1 m
    assert row["late_upwind_share"] == pytest.approx(0.75)
    assert row["late_within_2m_share"] == pytest.approx(0.5)  # 1 and 1 m; 2 m is not within
    assert row["late_detections_upwind_share"] == pytest.approx(2 / 3)
    assert row["final_along_m"] == pytest.approx(-0.5)
    assert row["final_cross_m"] == pytest.approx(0.5)
    assert (row["final_spread_m"], row["final_rmse_m"], row["truth_in_95"]) == (0.25, 0.8, True)


def test_upwind_detections_finds_a_planner_option_by_its_quoted_folder(tmp_path: Path) -> None:
    """A campaign stores ``dcee-cl:horizon=2``'s searches under ``strategy=dcee-cl%3Ahorizon%3D2``:
    the planner spec as given finds them. One search of ``paper:1``: detections 1 m and 3 m
    upwind of the source and 2 m downwind; the final mean 0.5 m downwind."""
    import math

    from dcee.scenarios import load_scenario

    upwind = _script("upwind_detections")
    scenario = load_scenario("paper:1")
    t = scenario.truth
    down = -np.array([math.cos(math.radians(t.phi)), math.sin(math.radians(t.phi))])
    source = np.array([t.x, t.y])
    run = tmp_path / "c" / "runs" / "config=paper%3A1" / "strategy=dcee-cl%3Ahorizon%3D2" / "s0"
    run.mkdir(parents=True)
    mean = source + 0.5 * down
    (run / "summary.json").write_text(
        f'{{"config": "paper:1", "final_mean": [{mean[0]}, {mean[1]}], "final_spread": 0.3}}'
    )
    points = source + np.outer([-1.0, -3.0, 2.0, 0.0], down)
    reading = [1.0, 1.0, 1.0, 0.0]  # the last below any threshold: not a detection
    pd.DataFrame({"x": points[:, 0], "y": points[:, 1], "reading": reading}).to_parquet(
        run / "steps.parquet"
    )
    row = upwind.along_wind(tmp_path / "c", "dcee-cl:horizon=2")
    assert row["searches"] == 1 and row["detections"] == 3
    assert row["median_along_m"] == pytest.approx(0.5)
    assert row["upwind_share"] == pytest.approx(2 / 3)
    assert row["upwind_1m_share"] == pytest.approx(1 / 3)  # only the 3 m one is beyond 1 m
    assert row["upwind_2m_share"] == pytest.approx(1 / 3)


def test_pinned_variants_set_the_pins_first_and_a_variant_overrides_them():
    """precision_variants --pin: a setting of the day the rows were flown, in every variant."""
    import argparse

    pv = _script("precision_variants")
    ap = argparse.ArgumentParser()
    pv.add_variant_arguments(ap)
    args = ap.parse_args(
        ["--pin", "search.lookahead=1", "--variant", "a:", "--variant", "b:search.lookahead=2"]
    )
    assert pv.pinned_variants(args) == [
        ("a", {"search.lookahead": 1}),
        ("b", {"search.lookahead": 2}),
    ]
    assert pv.pinned_variants(ap.parse_args([])) == [("base", {})]
    scenario = pv.variant_scenario("random:13", "puffs", pv.pinned_variants(args)[0][1])
    assert scenario.lookahead == 1  # a turbulent scenario, three moves ahead unless pinned
    assert pv.variant_scenario("random:13", "puffs", {}).lookahead == 3


def test_region_floor_table_and_rule_by_hand(tmp_path: Path, capsys) -> None:
    """Four searches per truth: on ``a`` the truth is inside from floor 0 in 3 of 4 and in all 4
    from 0.2 m; on ``b`` in all 4 from 0.1 m. The rule at 95 % takes 0.2 m (the smallest floor
    at which both truths reach it), at 75 % 0.1 m; the radius is √(spread² + 3 σ²)."""
    region_floor = _script("region_floor")
    floors = ("0.00", "0.10", "0.20")
    path = tmp_path / "variants.csv"
    inside = {"a": [(1, 1, 1), (1, 1, 1), (1, 1, 1), (0, 0, 1)], "b": [(0, 1, 1)] * 4}
    rows = [
        {
            "truth": t,
            "final_spread": 0.3,
            **{f"truth_in_95_floor_{f}": bool(v) for f, v in zip(floors, hit, strict=True)},
        }
        for t, hits in inside.items()
        for hit in hits
    ]
    pd.DataFrame(rows).to_csv(path, index=False)
    assert region_floor.main([str(path), "--csv", str(tmp_path / "c.csv"), "--choose", "0.95"]) == 0
    assert "chosen floor: 0.20" in capsys.readouterr().out
    table = pd.read_csv(tmp_path / "c.csv")
    a0 = table[(table["truth"] == "a") & (table["floor"] == 0.0)].iloc[0]
    assert (a0["inside"], a0["n"]) == (3, 4)
    both = table[(table["truth"] == "all") & (table["floor"] == 0.2)].iloc[0]
    assert both["inside"] == 8 and both["median_radius"] == pytest.approx(math.sqrt(0.09 + 0.12))
    assert region_floor.main([str(path), "--choose", "0.75"]) == 0
    assert "chosen floor: 0.10" in capsys.readouterr().out


def test_region_floor_reads_a_campaigns_nested_summaries(tmp_path: Path, capsys) -> None:
    """A campaign keeps each search at runs/config=…/strategy=…/seed=…/summary.json; a planar
    search (x, y unknown) counts two location coordinates in the region's radius."""
    region_floor = _script("region_floor")
    for k, inside in enumerate((True, False)):
        folder = tmp_path / "runs" / f"config=random%3A{k}" / "strategy=dcee-cl" / "seed=0"
        folder.mkdir(parents=True)
        summary = {
            "truth_model": "lbm",
            "parameter_names": ["x", "y", "q", "u", "phi", "zeta1", "zeta2"],
            "final_spread": 0.2,
            "truth_in_95_floor": {"0.00": False, "0.25": inside},
        }
        (folder / "summary.json").write_text(json.dumps(summary))
    assert region_floor.main([str(tmp_path), "--csv", str(tmp_path / "c.csv")]) == 0
    table = pd.read_csv(tmp_path / "c.csv")
    row = table[table["floor"] == 0.25].iloc[0]
    assert (row["inside"], row["n"]) == (1, 2)
    assert row["median_radius"] == pytest.approx(math.sqrt(0.04 + 2 * 0.0625))


def test_lbm3d_errors_along_and_across_the_wind_by_hand(tmp_path: Path) -> None:
    """studies/lbm3d_table.py: the final mean's error along the wind is + downwind of the
    release (the wind comes from φ, the plume runs towards −(cos φ, sin φ)), across it absolute,
    in height + above: two searches laid out by hand."""
    table = _script("lbm3d_table")
    dirs = []
    # wind from φ = 0 (from +x): downwind is −x. Mean 1 m upwind (+x), 0.5 m across, 0.2 m up
    # wind from φ = 90° (from +y): downwind is −y. Mean 3 m downwind (−y), 0.25 m across
    for k, (phi, mean) in enumerate(((0.0, (11.0, 20.5, 1.2)), (90.0, (10.25, 17.0, 0.8)))):
        d = tmp_path / f"run{k}"
        d.mkdir()
        truth = {"x": 10.0, "y": 20.0, "z": 1.0, "phi": phi}
        (d / "config.json").write_text(json.dumps({"scenario": {"truth": truth}}))
        (d / "summary.json").write_text(json.dumps({"final_mean": list(mean)}))
        dirs.append(str(d))
    errors = table._errors(dirs)
    assert errors["median_downwind_error"] == pytest.approx((-1.0 + 3.0) / 2)
    assert errors["median_crosswind_error"] == pytest.approx((0.5 + 0.25) / 2)
    assert errors["median_height_error"] == pytest.approx((0.2 - 0.2) / 2)


def test_the_speed_table_publishes_the_lowest_run_of_the_newest_code() -> None:
    """A speed-up belongs to one code version: of the stored Stone Soup runs the table takes
    the lowest of those with the newest run's package source, and counts the others."""
    from studies.tables.performance import _lowest_text, _of_newest_code

    def run(day: str, source: str, ratio: float) -> dict:
        code = {"commit": source * 7, "source_hash": source}
        return {"load": {"started": f"2026-12-0{day}T08:00:00"}, "machine": {"code": code},
                "speedup": ratio}  # fmt: skip

    records = sorted(
        [run("1", "a", 30.0), run("2", "b", 52.0), run("3", "b", 55.0), run("2", "c", 40.0)],
        key=lambda r: r["speedup"],
    )  # the table's order: lowest first; the newest run (day 3) measured source "b"
    same, earlier = _of_newest_code(records)
    assert [r["speedup"] for r in same] == [52.0, 55.0] and earlier == 2
    text = _lowest_text(same, lambda r: r["speedup"], earlier)
    assert "the lowest of 2 stored runs of this code (the others: 55.0× on 2026-12-03)" in text
    assert text.endswith("2 of earlier code in the runs table below")
