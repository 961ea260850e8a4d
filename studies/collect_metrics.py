"""Gather several campaigns' `dcee report` tables into one stored study (docs/results/<study>/):
each campaign's ``report/metrics.csv`` and ``report/pairwise.csv`` rows, tagged with the columns
that tell the campaigns apart, into ``metrics.csv`` and ``pairwise.csv``; and one row per search
(``searches.csv``: configuration, seed, strategy, acquired, final RMSE, truth in the 95 % region,
time to RMSE < 1 m, longest stall, mean decision time), so a paired comparison with a later
campaign needs no search folder
(``studies/ablation_table.py docs/results/<study>/searches.csv=STRATEGY``).

    .venv/bin/python studies/collect_metrics.py --out docs/results/turbulent-held-out-100 \\
        results/turbulent-puffs-held-out-100=truth_model:puffs,climb:0 \\
        results/turbulent-puffs-held-out-100-climb=truth_model:puffs,climb:1 …

Run ``dcee report DIR`` on every campaign first (this reads its tables, it computes nothing).
``--keep KEY:VALUE`` keeps the rows of the study already in ``--out`` that carry that tag (a
generation of campaigns whose search folders are gone; its rows were collected from them).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from dcee.analysis.report import load_campaign

# what a paired comparison reads from a search (studies/ablation_table.py)
SEARCH_COLUMNS = [
    "scenario",
    "seed",
    "strategy",
    "source_acquired",
    "final_rmse",
    "truth_in_95",
    "time_to_rmse_1m",
    "longest_stall",
    "decision_seconds_mean",  # wall time per decision, s (a comparison timed in one campaign)
]


def _tagged(arg: str) -> tuple[Path, dict[str, object]]:
    folder, _, tags = arg.partition("=")
    values: dict[str, object] = {}
    for item in filter(None, tags.split(",")):
        key, _, value = item.partition(":")
        try:
            values[key] = float(value)
        except ValueError:
            values[key] = value
    return Path(folder), values


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaigns", nargs="*", help="DIR=key:value,key:value")
    ap.add_argument("--out", required=True, help="the study folder to write")
    ap.add_argument("--keep", action="append", default=[], help="KEY:VALUE rows to keep")
    args = ap.parse_args(argv)
    metrics, pairwise, searches = [], [], []
    for keep in args.keep:
        key, _, value = keep.partition(":")
        for name, into in (("metrics.csv", metrics), ("pairwise.csv", pairwise),
                           ("searches.csv", searches)):  # fmt: skip
            path = Path(args.out) / name
            if not path.exists():
                continue  # a study of one planner has no pairs
            stored = pd.read_csv(path)
            if key not in stored.columns:
                print(f"collect_metrics: {path} has no tag {key!r}", file=sys.stderr)
                return 2
            into.append(stored[stored[key].astype(str) == value])
    if not args.campaigns and not any(len(frame) for frame in metrics):
        print("collect_metrics: nothing to collect", file=sys.stderr)
        return 2
    for arg in args.campaigns:
        folder, tags = _tagged(arg)
        for name, into in (("metrics.csv", metrics), ("pairwise.csv", pairwise)):
            path = folder / "report" / name
            if not path.exists():
                print(
                    f"collect_metrics: {path} is missing; run dcee report {folder}", file=sys.stderr
                )
                return 2
            try:
                frame = pd.read_csv(path)
            except pd.errors.EmptyDataError:  # one strategy: no pairs to list
                continue
            for i, (key, value) in enumerate(tags.items()):
                frame.insert(1 + i, key, value)
            into.append(frame)
        _, runs = load_campaign(folder)
        runs = runs.reindex(columns=SEARCH_COLUMNS)
        for i, (key, value) in enumerate(tags.items()):
            runs.insert(3 + i, key, value)
        searches.append(runs)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    pd.concat(metrics).to_csv(out / "metrics.csv", index=False)
    if pairwise:
        pd.concat(pairwise).to_csv(out / "pairwise.csv", index=False)
    table = pd.concat(searches).sort_values(["strategy", "scenario", "seed"], kind="stable")
    table.to_csv(out / "searches.csv", index=False)
    print(f"wrote {out / 'metrics.csv'}, {out / 'pairwise.csv'} and {out / 'searches.csv'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
