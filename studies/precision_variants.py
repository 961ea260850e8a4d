"""Where does a turbulent search's final error come from? Setting variants on tuning
configurations (issue 29, item 3; lab notes for docs/results.md, never a reported result).

Each variant is a set of scenario overrides; every variant flies the same configurations and
seeds on each truth (all eight parameters unknown, fluctuation likelihood, 10,000 particles
unless overridden). Prints per variant and truth: acquired (final RMSE < 3 m), median final RMSE,
the share with the truth in the 95 % region, and the median signed along-wind and absolute
cross-wind error of the final mean (m; along > 0 means the estimate lies downwind); each row
also records the reading model that led at the end and its posterior probability.

    .venv/bin/python studies/precision_variants.py --configs random:1-12 --truths puffs filament \\
        --variant base: --variant hold8:agent.dwell=8 --variant n20k:search.particles=20000 \\
        [--strategy dcee-cl] [--seeds 1] [--workers 2] [--csv out.csv]
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import tomllib
from multiprocessing import Pool

import numpy as np

from dcee.scenarios import expand_names


def _top_level_items(body: str) -> list[str]:
    """``a=1,b={c=[1,2]}`` → ["a=1", "b={c=[1,2]}"]: commas inside brackets stay."""
    items, depth, start = [], 0, 0
    for i, ch in enumerate(body):
        depth += ch in "[{"
        depth -= ch in "]}"
        if ch == "," and depth == 0:
            items.append(body[start:i])
            start = i + 1
    items.append(body[start:])
    return [item for item in items if item]


def parse_variant(text: str) -> tuple[str, dict]:
    label, _, body = text.partition(":")
    over = {}
    for item in _top_level_items(body):
        key, _, value = item.partition("=")
        over[key] = tomllib.loads(f"v = {value}")["v"]
    return label, over


def add_variant_arguments(ap: argparse.ArgumentParser) -> None:
    """``--variant NAME:PATH=VALUE,...`` (repeatable) and ``--pin PATH=VALUE`` (repeatable)."""
    ap.add_argument("--variant", action="append", default=[])
    ap.add_argument(
        "--pin",
        action="append",
        default=[],
        help="PATH=VALUE set in every variant before its own overrides (e.g. a default of "
        "the day the rows were flown: search.lookahead=1)",
    )


def pinned_variants(args: argparse.Namespace) -> list[tuple[str, dict]]:
    """(label, overrides) per ``--variant`` (default one ``base`` with none), each with the
    ``--pin`` settings first (a variant's own override of the same path wins)."""
    pins = parse_variant("pins:" + ",".join(args.pin))[1]
    return [
        (label, {**pins, **over})
        for label, over in (parse_variant(v) for v in (args.variant or ["base:"]))
    ]


def variant_scenario(name: str, truth: str, over: dict):
    """Configuration ``name`` on ``truth``, all eight unknown, the fluctuation likelihood,
    10,000 particles, then the variant's overrides ``over``."""
    from dcee.scenarios import load_scenario

    base = {
        "search.particles": 10000,
        "unknown": "full",
        "truth.model": truth,
        "estimator.likelihood": "fluctuation",
    }
    return load_scenario(name).with_overrides(**base).with_overrides(**over)


def one(task: tuple) -> dict:
    label, over, name, truth, seed, strategy = task
    from dcee.runs import run_episode

    scenario = variant_scenario(name, truth, over)
    res = run_episode(scenario, strategy, seed)
    s, last = res.summary, res.records[-1]
    theta = scenario.truth_theta()
    down = -np.array([math.cos(theta[5]), math.sin(theta[5])])
    err = np.array([last["mean_x"] - theta[0], last["mean_y"] - theta[1]])
    return {
        "variant": label,
        "truth": truth,
        "scenario": name,
        "seed": seed,
        "acquired": s["source_acquired"],
        "final_rmse": s["final_rmse"],
        "truth_in_95": s["truth_in_95"],
        "along": float(err @ down),
        "cross": float(abs(err @ np.array([-down[1], down[0]]))),
        "steps": s["steps"],
        "longest_stall": s["longest_stall"],
        "model": s.get("model", ""),  # the reading model that led at the end (a bank's member)
        "model_probability": s.get("model_probability", 1.0),
        "final_spread": s["final_spread"],  # m, the particles' RMS spread about their mean
        # the truth in the 95 % region at each model-discrepancy floor (m) of the grid
        **{f"truth_in_95_floor_{k}": v for k, v in s["truth_in_95_floor"].items()},
    }


def append_row(path: str, row: dict) -> None:
    """Append one search's row to the CSV at ``path`` (header first in a new file); a file
    begun before a column existed keeps its header (the new column is dropped)."""
    new_file = not os.path.exists(path)
    if new_file:
        fields = list(row)
    else:
        with open(path, newline="") as fh:
            fields = next(csv.reader(fh))
    with open(path, "a", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        if new_file:
            w.writeheader()
        w.writerow(row)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--configs", nargs="+", default=["random:1-12"])
    ap.add_argument("--truths", nargs="+", default=["puffs", "filament"])
    ap.add_argument("--strategy", default="dcee-cl")
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--csv", default=None)
    add_variant_arguments(ap)
    args = ap.parse_args()
    variants = pinned_variants(args)
    tasks = [
        (label, over, name, truth, seed, args.strategy)
        for label, over in variants
        for truth in args.truths
        for name in expand_names(args.configs)
        for seed in range(args.seeds)
    ]
    # Rows are appended to --csv as each search finishes, and a rerun skips the searches the
    # file already holds: an interrupted study loses no finished search.
    key = ("variant", "truth", "scenario", "seed")
    rows: list[dict] = []
    if args.csv and os.path.exists(args.csv):
        with open(args.csv, newline="") as fh:
            rows = [
                {**r, "seed": int(r["seed"]), "acquired": r["acquired"] == "True",
                 "truth_in_95": r["truth_in_95"] == "True",
                 **{k: float(r[k]) for k in ("final_rmse", "along", "cross")}}
                for r in csv.DictReader(fh)
            ]  # fmt: skip
    done = {tuple(str(r[k]) for k in key) for r in rows}
    todo = [t for t in tasks if (t[0], t[3], t[2], str(t[4])) not in done]
    with Pool(args.workers) as pool:
        for row in pool.imap_unordered(one, todo, chunksize=1):
            rows.append(row)
            if args.csv:
                append_row(args.csv, row)
    print("| variant | truth | n | acquired | median final RMSE (m) | truth in 95 % | "
          "median along-wind error (m) | median cross-wind error (m) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for label, _ in variants:
        for truth in args.truths:
            rs = [r for r in rows if r["variant"] == label and r["truth"] == truth]
            print(
                f"| {label} | {truth} | {len(rs)} | {sum(r['acquired'] for r in rs)} | "
                f"{np.median([r['final_rmse'] for r in rs]):.2f} | "
                f"{np.mean([r['truth_in_95'] for r in rs]):.0%} | "
                f"{np.median([r['along'] for r in rs]):+.2f} | "
                f"{np.median([r['cross'] for r in rs]):.2f} |"
            )


if __name__ == "__main__":
    main()
