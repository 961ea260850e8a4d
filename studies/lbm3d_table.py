"""Issue 78's tables from stored campaigns: per campaign and strategy, the searches acquired
(final 3-D RMSE < ``search.acquired_rmse``), the median final 3-D RMSE with a 95 % bootstrap
interval, the truth in the 95 % region, the median detections, and the altitudes the searches
read at (the share of readings at each altitude, the lowest and the highest); the paired
difference of two strategies on the same configurations (Wilcoxon); and each campaign's worst
searches. Written as CSV and JSON under ``--out`` (docs/results/lbm3d/ in the recipe).

    .venv/bin/python studies/lbm3d_table.py results/lbm3d-held-out-100 \\
        results/lbm3d-slice-held-out-50 --out docs/results/lbm3d
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.report import load_campaign
from dcee.io import write_json


def _bootstrap_median(values: np.ndarray, seed: int = 0) -> tuple[float, float]:
    rng = np.random.default_rng(seed)
    draws = rng.choice(values, size=(4000, len(values)), replace=True)
    lo, hi = np.percentile(np.median(draws, axis=1), [2.5, 97.5])
    return float(lo), float(hi)


def _altitudes(run_dirs: list[str]) -> tuple[dict[str, float], float, float]:
    """(share of readings at each altitude, lowest, highest) over the searches' readings."""
    z = np.concatenate(
        [
            pd.read_parquet(Path(d) / "steps.parquet", columns=["z"])["z"].to_numpy()
            for d in run_dirs
        ]
    )
    values, counts = np.unique(np.round(z, 2), return_counts=True)
    share = {f"{v:g}": float(c / len(z)) for v, c in zip(values, counts, strict=True)}
    return share, float(z.min()), float(z.max())


RARE = 60
"""Detections in a search below which gas counts as rare (issue 78, item 4)."""


def _rare(part: pd.DataFrame) -> dict[str, float]:
    """The searches with fewer than :data:`RARE` detections against the rest: how many, their
    median final RMSE, their truth in the region; and Spearman's ρ between detections and the
    final RMSE over all searches."""
    few = part[part["detections"] < RARE]
    many = part[part["detections"] >= RARE]
    rho = stats.spearmanr(part["detections"], part["final_rmse"]).statistic
    return {
        "searches": len(few),
        "median_final_rmse": float(few["final_rmse"].median()) if len(few) else float("nan"),
        "truth_in_95": int(few["truth_in_95"].astype(bool).sum()),
        "acquired": int(few["source_acquired"].astype(bool).sum()),
        "others_median_final_rmse": float(many["final_rmse"].median())
        if len(many)
        else float("nan"),
        "spearman_detections_rmse": float(rho),
    }


def mean_error(final_mean: list[float], truth: dict) -> tuple[float, float, float]:
    """The final posterior mean's error (m) along the wind (+ downwind of the release), across
    it (absolute) and in height (+ above); ``truth`` a scenario's truth (x, y, z, φ in degrees:
    the wind comes from φ, the plume runs towards −(cos φ, sin φ))."""
    err = np.asarray(final_mean, dtype=float) - [truth["x"], truth["y"], truth["z"]]
    phi = math.radians(truth["phi"])
    along = -np.array([math.cos(phi), math.sin(phi)])
    return float(err[:2] @ along), abs(float(err[0] * -along[1] + err[1] * along[0])), float(err[2])


def _errors(run_dirs: list[str]) -> dict[str, float]:
    """Median :func:`mean_error` over searches, from each one's summary and its scenario."""
    errors = []
    for d in run_dirs:
        summary = json.loads((Path(d) / "summary.json").read_text(encoding="utf-8"))
        config = json.loads((Path(d) / "config.json").read_text(encoding="utf-8"))
        errors.append(mean_error(summary["final_mean"], config["scenario"]["truth"]))
    down, cross, height = np.median(np.asarray(errors), axis=0)
    return {
        "median_downwind_error": float(down),
        "median_crosswind_error": float(cross),
        "median_height_error": float(height),
    }


def campaign_table(folder: Path) -> tuple[list[dict], list[dict], list[dict]]:
    """(rows per strategy, paired differences, worst searches) of one campaign."""
    _, runs = load_campaign(folder)
    rows, worst = [], []
    for strategy, part in runs.groupby("strategy", sort=True):
        rmse = part["final_rmse"].to_numpy(dtype=np.float64)
        lo, hi = _bootstrap_median(rmse)
        share, z_min, z_max = _altitudes(list(part["run_dir"]))
        rows.append(
            {
                "campaign": folder.name,
                "strategy": strategy,
                "searches": len(part),
                "acquired": int(part["source_acquired"].astype(bool).sum()),
                "median_final_rmse": float(np.median(rmse)),
                "median_final_rmse_ci95": [lo, hi],
                "truth_in_95": int(part["truth_in_95"].astype(bool).sum()),
                "median_detections": float(part["detections"].median()),
                # m, the final particles' RMS distance from their mean (the posterior's spread)
                "median_final_spread": float(part["final_spread"].median()),
                # precision where detections are rare: the searches with fewer than 60
                "rare": _rare(part),
                "altitude_share": share,
                **_errors(list(part["run_dir"])),
                "lowest_altitude": z_min,
                "highest_altitude": z_max,
            }
        )
        bad = part.assign(miss=~part["source_acquired"].astype(bool))
        bad = bad.sort_values(["miss", "final_rmse"], ascending=False).head(3)
        for _, r in bad.iterrows():
            worst.append(
                {
                    "campaign": folder.name,
                    "strategy": strategy,
                    "scenario": r["scenario"],
                    "final_rmse": float(r["final_rmse"]),
                    "acquired": bool(r["source_acquired"]),
                    "truth_in_95": bool(r["truth_in_95"]),
                    "detections": int(r["detections"]),
                }
            )
    pairs = []
    strategies = sorted(runs["strategy"].unique())
    for i, a in enumerate(strategies):
        for b in strategies[i + 1 :]:
            wide = runs.pivot_table(
                index=["scenario", "seed"], columns="strategy", values="final_rmse"
            )[[a, b]].dropna()
            if len(wide) < 5:
                continue
            diff = (wide[a] - wide[b]).to_numpy()
            p = float(stats.wilcoxon(diff).pvalue) if np.any(diff != 0) else 1.0
            pairs.append(
                {
                    "campaign": folder.name,
                    "a": a,
                    "b": b,
                    "pairs": len(wide),
                    "median_difference": float(np.median(diff)),
                    "wilcoxon_p": p,
                }
            )
    return rows, pairs, worst


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("campaigns", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for folder in args.campaigns:
        rows, pairs, worst = campaign_table(folder)
        write_json(args.out / f"{folder.name}.json", {"rows": rows, "pairs": pairs, "worst": worst})
        for r in rows:
            lo, hi = r["median_final_rmse_ci95"]
            print(
                f"{folder.name} {r['strategy']}: acquired {r['acquired']}/{r['searches']}, "
                f"median RMSE {r['median_final_rmse']:.2f} m [{lo:.2f}, {hi:.2f}], region "
                f"{r['truth_in_95']}/{r['searches']}, detections {r['median_detections']:.0f}, "
                f"altitudes {r['lowest_altitude']:g}-{r['highest_altitude']:g} m, error downwind "
                f"{r['median_downwind_error']:+.2f} m, across {r['median_crosswind_error']:.2f} m, "
                f"in height {r['median_height_error']:+.2f} m; under "
                f"{RARE} detections: {r['rare']['searches']} searches, median RMSE "
                f"{r['rare']['median_final_rmse']:.2f} m (others "
                f"{r['rare']['others_median_final_rmse']:.2f} m), Spearman ρ(detections, RMSE) "
                f"{r['rare']['spearman_detections_rmse']:.2f}"
            )
        for p in pairs:
            print(
                f"  {p['a']} - {p['b']}: median paired {p['median_difference']:+.2f} m over "
                f"{p['pairs']} (Wilcoxon p = {p['wilcoxon_p']:.3g})"
            )
        print(json.dumps(worst, indent=1))


if __name__ == "__main__":
    main()
