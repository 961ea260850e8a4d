"""The unknown-count study's table (issue 45): per campaign (two or three releases, held out),
how often the search ended with the right number of releases (Wilson 95 % interval), the
confusion of the estimated against the true count, the OSPA distance (3 m cut-off, order 1;
median with its 95 % interval), each true release's distance to the nearest estimated one,
P(K̂) and the worst searches.

    python studies/source_count_table.py results/two-source-held-out-100 \\
        results/three-source-held-out-100 [results/two-source-held-out-100-before …] \\
        [--csv docs/results/source-count/searches.csv]

A folder named X-before holds the same searches run with the code before a change; the paired
table compares X with it.
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.results import find_runs
from dcee.analysis.statistics import median_ci, wilson
from dcee.errors import DceeInputError
from dcee.models import IsotropicPlume
from dcee.scenarios import Scenario, load_scenario
from dcee.scenarios.schema.scenario import validate_scenario


def release_readings(scenario: Scenario, run: Path) -> np.ndarray:
    """(K,) how many of the search's readings each true release's mean gas reached (its
    isotropic concentration above the sensor's threshold at the reading's position): which
    releases the robot ever sampled. A release that never reached a reading cannot be counted
    however good the estimator: an exploration failure, not an estimation one."""
    steps = pd.read_parquet(run / "steps.parquet", columns=["x", "y", "z"])
    positions = steps[["x", "y", "z"]].to_numpy()
    conc = IsotropicPlume().concentration(scenario.truth_thetas(), positions)  # (K, steps)
    return (conc > scenario.sensor.threshold).sum(axis=1)


FOOTPRINT_CELL = 0.5
"""m: the side of the cells a release's footprint is counted in."""

FOOTPRINT_DETECTION = 0.1
"""The least probability that one reading detects a release's gas for its cell to count in the
release's footprint: one reading in ten."""


def release_footprints(scenario: Scenario) -> np.ndarray:
    """(K,) m²: each true release's footprint, the part of the area at the robot's flight
    height where one reading of the scenario's sensor detects its mean (isotropic) gas with
    probability at least :data:`FOOTPRINT_DETECTION` (1 − P(miss | C) / P(miss | 0), as the
    exploration guard measures a detection), counted on a 0.5 m grid. A property of the
    configuration, not of a search: a release of footprint 0 (its gas leaves the area below or
    beside the flight plane) is detected at best by chance anywhere a robot may go."""
    lo, hi = np.asarray(scenario.volume.low), np.asarray(scenario.volume.high)
    xs = np.arange(lo[0] + FOOTPRINT_CELL / 2, hi[0], FOOTPRINT_CELL)
    ys = np.arange(lo[1] + FOOTPRINT_CELL / 2, hi[1], FOOTPRINT_CELL)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    height = np.full(gx.size, float(scenario.agent.start[2]))
    points = np.column_stack([gx.ravel(), gy.ravel(), height])
    conc = IsotropicPlume().concentration(scenario.truth_thetas(), points)  # (K, cells)
    sensor = scenario.make_sensor()  # the truth's sensor
    missed = np.exp(sensor.log_likelihood(0.0, conc) - sensor.log_likelihood(0.0, 0.0))
    return (1.0 - missed >= FOOTPRINT_DETECTION).sum(axis=1) * FOOTPRINT_CELL**2


@functools.cache
def least_footprint(name: str) -> float:
    """m²: the least :func:`release_footprints` of the configuration ``name``'s built-in
    scenario (its sensor), for a row read from a campaign folder and one filled in the stored
    CSV alike: the same number whichever folders a machine holds (a filament or puff campaign's
    own scenario has another sensor)."""
    return float(release_footprints(load_scenario(name)).min())


def rows_of(folder: Path) -> list[dict]:
    out = []
    for run in find_runs(folder):
        summary = json.loads((run / "summary.json").read_text())
        config = json.loads((run / "config.json").read_text())
        scenario = validate_scenario(config["scenario"])
        truth = scenario.truth.source_locations()
        reached = release_readings(scenario, run)
        # the one-release filter (estimator.max_sources = 1) reports its posterior mean only
        estimates = summary.get("estimated_sources") or [summary["final_mean"][:3]]
        est = np.array(estimates, dtype=float).reshape(-1, 3)
        near = (
            np.linalg.norm(truth[:, None, :] - est[None, :, :], axis=2).min(axis=1)
            if len(est)
            else np.full(len(truth), np.inf)
        )
        probs = summary.get("count_probabilities", [])
        k_hat = int(summary.get("estimated_count", 1))
        # a `dcee run --set` search names its edited scenario NAME+hash: the configuration is NAME
        name = str(summary["scenario"]).split("+", 1)[0]
        out.append(
            {
                "campaign": folder.name,
                "scenario": name,
                "strategy": summary["strategy"],
                "seed": summary["seed"],
                "true_count": int(summary["true_sources"]),
                "estimated_count": k_hat,
                "count_correct": k_hat == int(summary["true_sources"]),
                "p_estimated": float(probs[k_hat]) if probs else np.nan,
                "p_true": float(probs[summary["true_sources"]]) if probs else np.nan,
                "final_ospa": float(summary["final_ospa"]),
                "worst_release_error": float(near.max()),
                "mean_release_error": float(near.mean()),
                "explore_guard_fired": int(summary.get("explore_guard_fired", 0)),
                "least_reached_readings": int(reached.min()),
                "least_footprint_m2": least_footprint(name),
                "decision_ms": 1e3 * float(summary["decision_seconds_mean"]),
                "code": summary.get("code", {}).get("commit", "")
                if isinstance(summary.get("code"), dict)
                else "",
            }
        )
    return out


def merged_rows(stored: pd.DataFrame | None, new: pd.DataFrame) -> pd.DataFrame:
    """The stored rows with those of every campaign in ``new`` replaced by ``new``'s: a study
    that flies some campaigns keeps the stored rows of the others (a fresh machine holds only
    the campaigns it flew)."""
    if stored is None:
        return new
    # each campaign where it stood (a replaced one in its stored place), new ones at the end
    order = list(dict.fromkeys([*stored["campaign"], *new["campaign"]]))
    fresh = set(new["campaign"])
    parts = [(new if c in fresh else stored)[lambda d, c=c: d["campaign"] == c] for c in order]
    return pd.concat(parts, ignore_index=True)


def table(df: pd.DataFrame) -> str:
    lines = [
        "| campaign | planner | searches | right count | confusion (K̂: searches) | median OSPA "
        "(m) [95 % CI] | OSPA ≤ 1 m | median P(K̂) | worst release within 1 m |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for (campaign, strategy), g in df.groupby(["campaign", "strategy"], sort=False):
        n = len(g)
        right = int(g["count_correct"].sum())
        _, lo, hi = wilson(right, n)
        med, mlo, mhi = median_ci(g["final_ospa"].to_numpy())
        conf = ", ".join(
            f"{k}: {c}" for k, c in sorted(g["estimated_count"].value_counts().items())
        )
        within = int((g["worst_release_error"] <= 1.0).sum())
        p_hat = g["p_estimated"].median()  # NaN: the one-release filter weighs no counts
        p_text = "—" if np.isnan(p_hat) else f"{p_hat:.2f}"
        lines.append(
            f"| {campaign} | {strategy} | {n} | {right}/{n} ({100 * right / n:.0f} %) "
            f"[{100 * lo:.0f}, {100 * hi:.0f}] | {conf} | {med:.2f} [{mlo:.2f}, {mhi:.2f}] | "
            f"{int((g['final_ospa'] <= 1.0).sum())}/{n} | {p_text} | "
            f"{within}/{n} |"
        )
    return "\n".join(lines)


CLIMB = "-climb"
"""A campaign named X-climb is X's searches at today's defaults with the UAV free to climb (an
unset ``agent.climb`` with the count unknown, since 2026-12-02); X itself flew at the paper's
fixed 4 m. Where both are stored, X-climb is today's and X an earlier default."""


def table_latest(df: pd.DataFrame) -> str:
    """:func:`table` of today's campaigns only (names without a code suffix: they end in
    ``held-out-N``, or ``held-out-N-infotaxis`` / ``-mcts`` for another planner's, or
    ``held-out-N-climb`` for today's defaults where the UAV climbs; a campaign X with its
    X-climb stored is left out for it; the README's table)."""
    latest = r"held-out-\d+(?:-infotaxis|-mcts|-climb)?$"
    names = set(df["campaign"])
    superseded = {c for c in names if c + CLIMB in names}
    keep = df["campaign"].str.contains(latest, regex=True) & ~df["campaign"].isin(superseded)
    return table(df[keep])


BEFORE = "-before"
"""A campaign named X-before is the same searches as X with the code before a change: the
paired table compares them, the worst-search table leaves them out."""

PAIRS = (
    ("one-source-unknown-count-held-out-100", "one-source-known-count-held-out-100"),
    ("two-source-wind-unknown-held-out-50", "two-source-held-out-100"),
    ("two-source-filament-held-out-100", "two-source-held-out-100"),
    ("two-source-puffs-held-out-100", "two-source-held-out-100"),
    ("two-source-held-out-100-infotaxis", "two-source-held-out-100"),
    ("two-source-held-out-100-mcts", "two-source-held-out-100"),
    ("three-source-held-out-100-mcts", "three-source-held-out-100"),
    ("two-source-held-out-100-climb", "two-source-held-out-100"),
    ("three-source-held-out-100-climb", "three-source-held-out-100"),
)
"""Campaigns compared on the same configurations besides each X against X-before: one release
with the count unknown against the one-release filter (issue 45, K = 1); two releases with the
wind unknown against the wind known (the 50 configurations both flew); two releases in a
turbulent truth (filament, puffs; the fluctuation likelihood) against the isotropic truth;
infotaxis and the tree search ``dcee-mcts`` against dcee-cl (campaigns of one planner each are
paired across planners); the UAV free to climb (today's default with the count unknown)
against the fixed 4 m."""


def paired(df: pd.DataFrame) -> str:
    """Each campaign X against X-before, and each pair of :data:`PAIRS`, on the same
    configurations: right count by one only (exact McNemar p) and the median paired OSPA
    difference (Wilcoxon signed-rank p)."""
    lines = [
        "| campaign A − campaign B (same configurations) | pairs | right count: A only / "
        "B only (McNemar p) | median OSPA difference A − B (m) (Wilcoxon p) |",
        "|---|---|---|---|",
    ]
    keyed = df.set_index(["campaign", "scenario", "strategy", "seed"])
    names = list(df["campaign"].unique())
    pairs = [(c, c + BEFORE) for c in names if not c.endswith(BEFORE) and c + BEFORE in names]
    pairs += [(a, b) for a, b in PAIRS if a in names and b in names]
    for first, second in pairs:
        rows_a, rows_b = keyed.loc[first], keyed.loc[second]
        one_planner = (
            rows_a.index.get_level_values("strategy").nunique() == 1
            and rows_b.index.get_level_values("strategy").nunique() == 1
        )
        if one_planner:  # two planners on the same configurations: pair by scenario and seed
            rows_a, rows_b = rows_a.droplevel("strategy"), rows_b.droplevel("strategy")
        common = rows_a.index.intersection(rows_b.index)
        a = rows_a.loc[common, "count_correct"].astype(bool).to_numpy()
        b = rows_b.loc[common, "count_correct"].astype(bool).to_numpy()
        only_a, only_b = int((a & ~b).sum()), int((~a & b).sum())
        p_count = stats.binomtest(only_a, only_a + only_b, 0.5).pvalue if only_a + only_b else 1.0
        diff = rows_a.loc[common, "final_ospa"].to_numpy(float) - rows_b.loc[
            common, "final_ospa"
        ].to_numpy(float)
        p_ospa = float(stats.wilcoxon(diff).pvalue) if np.any(diff != 0) else 1.0
        lines.append(
            f"| {first} − {second} | {len(common)} | {only_a} / {only_b} (p = {p_count:.2g}) | "
            f"{np.median(diff):+.2f} (p = {p_ospa:.2g}) |"
        )
    return "\n".join(lines)


OBSERVABLE_M2 = 4.0
"""m²: the least footprint (:func:`release_footprints`) of a release a search can be expected
to find: one cell of the robot's 2 m step. A smaller one a robot on its 2 m lattice of moves
may never stand in."""


def observable(df: pd.DataFrame) -> str:
    """:func:`table_latest` of the searches whose every release's footprint is at least
    :data:`OBSERVABLE_M2`: what a search could be expected to count."""
    seen = df[df["least_footprint_m2"] >= OBSERVABLE_M2]
    return table_latest(seen)


def with_footprints(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` with ``least_footprint_m2`` filled from the scenarios where missing (rows stored
    before the column existed)."""
    if "least_footprint_m2" not in df:
        df = df.assign(least_footprint_m2=np.nan)
    missing = df["least_footprint_m2"].isna()
    for i in df.index[missing]:
        df.at[i, "least_footprint_m2"] = least_footprint(df.at[i, "scenario"])
    return df


def worst(df: pd.DataFrame, k: int = 5) -> str:
    lines = [
        "| campaign | scenario | true K | K̂ | P(true K) | OSPA (m) | worst release error (m) "
        "| readings the least-sampled release's gas reached |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for campaign, g in df.groupby("campaign", sort=False):
        if campaign.endswith(BEFORE):
            continue
        for _, r in g.sort_values("final_ospa", ascending=False).head(k).iterrows():
            lines.append(
                f"| {campaign} | {r.scenario} | {r.true_count} | {r.estimated_count} | "
                f"{r.p_true:.2f} | {r.final_ospa:.2f} | {r.worst_release_error:.2f} | "
                f"{r.least_reached_readings} |"
            )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path)
    ap.add_argument("--csv", type=Path, help="write every search's row here")
    args = ap.parse_args(argv)
    try:
        rows = [r for f in args.folders for r in rows_of(f)]
    except DceeInputError as exc:
        print(f"source_count_table: {exc}", file=sys.stderr)
        return 2
    if not rows:
        print("no finished searches in " + ", ".join(map(str, args.folders)), file=sys.stderr)
        return 2
    df = pd.DataFrame(rows)
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        stored = pd.read_csv(args.csv) if args.csv.exists() else None
        with_footprints(merged_rows(stored, df)).to_csv(args.csv, index=False)
    print(table(df))
    print()
    print(observable(df))
    print()
    print(paired(df))
    print()
    print(worst(df))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
