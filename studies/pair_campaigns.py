"""Pair two campaigns search by search (same configuration, seed and strategy; common random
numbers make the pairing exact) and test the difference per strategy: exact McNemar on
acquisition and on the truth lying in the 95 % region, Wilcoxon on the final RMSE.

    .venv/bin/python studies/pair_campaigns.py results/turbulent-puffs-held-out-100 \\
        results/turbulent-puffs-held-out-100-climb [--csv out.csv --tag truth_model=puffs]

``--as SPEC=NAME`` pairs side b's planner ``SPEC`` with side a's ``NAME`` (a planner option
against the planner: ``--as dcee-cl:horizon=2=dcee-cl``).

Either side may be a stored study's rows instead of a campaign folder whose searches are gone
(``searches.csv`` of studies/collect_metrics.py), its rows picked by their tags as
studies/ablation_table.py picks them (``FILE.csv=KEY:VALUE[:KEY:VALUE…]``):
``docs/results/turbulent-held-out-100-today/searches.csv=truth_model:puffs:defaults:2026-11-27``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pandas as pd
from scipy.stats import binomtest, wilcoxon

COLUMNS = ["scenario", "seed", "strategy", "source_acquired", "final_rmse", "truth_in_95"]


def _stored(spec: str) -> pd.DataFrame:
    """A stored study's rows: ``FILE.csv[=KEY:VALUE[:KEY:VALUE…]]``."""
    path, _, picks = spec.partition("=")
    if not Path(path).is_file():
        print(f"pair_campaigns: {path}: no such stored study", file=sys.stderr)
        raise SystemExit(2)
    rows = pd.read_csv(path)
    tags = picks.split(":") if picks else []
    if len(tags) % 2:
        print(f"pair_campaigns: {spec}: tags come as KEY:VALUE pairs", file=sys.stderr)
        raise SystemExit(2)
    for key, value in zip(tags[::2], tags[1::2], strict=True):
        if key not in rows.columns:
            print(f"pair_campaigns: {path} has no column {key!r}", file=sys.stderr)
            raise SystemExit(2)
        rows = rows[rows[key].astype(str) == value]
    if rows.empty or rows.duplicated(["scenario", "seed", "strategy"]).any():
        print(f"pair_campaigns: {spec}: pick one search per configuration", file=sys.stderr)
        raise SystemExit(2)
    return rows[COLUMNS]


def _load(folder: str) -> pd.DataFrame:
    if folder.partition("=")[0].endswith(".csv"):
        return _stored(folder)
    paths = sorted(Path(folder).glob("runs/**/summary.json"))
    if not paths:
        print(f"pair_campaigns: no searches under {folder}", file=sys.stderr)
        raise SystemExit(2)
    return pd.DataFrame([json.loads(p.read_text()) for p in paths])[COLUMNS]


def _mcnemar(a_only: int, b_only: int) -> float:
    return binomtest(a_only, a_only + b_only).pvalue if a_only + b_only else 1.0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--csv", default=None, help="append the rows to this file")
    ap.add_argument("--tag", action="append", default=[], help="KEY=VALUE column for the rows")
    ap.add_argument(
        "--as",
        dest="rename",
        action="append",
        default=[],
        help="SPEC=NAME: pair b's planner SPEC with a's NAME (e.g. dcee-cl:horizon=2=dcee-cl)",
    )
    args = ap.parse_args(argv)
    b = _load(args.b)
    for item in args.rename:
        spec, _, name = item.rpartition("=")
        if not spec or not name:
            print(f"pair_campaigns: --as {item!r}: give SPEC=NAME", file=sys.stderr)
            raise SystemExit(2)
        b["strategy"] = b["strategy"].replace(spec, name)
    pairs = _load(args.a).merge(b, on=["scenario", "seed", "strategy"], suffixes=("_a", "_b"))
    rows = []
    for strategy, x in pairs.groupby("strategy"):
        acq_a, acq_b = x.source_acquired_a.astype(bool), x.source_acquired_b.astype(bool)
        in_a, in_b = x.truth_in_95_a.astype(bool), x.truth_in_95_b.astype(bool)
        diff = x.final_rmse_b - x.final_rmse_a
        rows.append(
            {
                **dict(t.split("=", 1) for t in args.tag),
                "strategy": strategy,
                "pairs": len(x),
                "acquired_a_only": int((acq_a & ~acq_b).sum()),
                "acquired_b_only": int((~acq_a & acq_b).sum()),
                "acquired_mcnemar_p": _mcnemar(
                    int((acq_a & ~acq_b).sum()), int((~acq_a & acq_b).sum())
                ),
                "median_rmse_b_minus_a": float(diff.median()),
                "rmse_wilcoxon_p": float(wilcoxon(diff).pvalue) if diff.any() else 1.0,
                "in95_a_only": int((in_a & ~in_b).sum()),
                "in95_b_only": int((~in_a & in_b).sum()),
                "in95_mcnemar_p": _mcnemar(int((in_a & ~in_b).sum()), int((~in_a & in_b).sum())),
            }
        )
    table = pd.DataFrame(rows)
    print(table.to_string(index=False))
    if args.csv:
        path = Path(args.csv)
        table.to_csv(path, mode="a", header=not path.exists(), index=False)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
