"""The wall time of a whole campaign and its mean cost per search and planner, stored as JSON
(issue 46: the 600-search study's figure of merit; the table on docs/performance.md is generated
from it).

    start=$(date +%s); .venv/bin/dcee bench --suite paper --repeats 10 --workers 2 --out DIR
    .venv/bin/python studies/study_wall.py DIR --wall $(( $(date +%s) - start )) \\
        --json docs/results/perf/study-600.json

Run the campaign with nothing else on the machine: the JSON records the load average at the end
and the machine, not a kernel-counter measurement over the run.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from dcee.analysis.results import load_summaries
from dcee.io import write_json
from dcee.perf.machine import machine_record


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign", type=Path)
    ap.add_argument("--wall", type=float, required=True, help="the campaign's wall time (s)")
    ap.add_argument("--json", type=Path, required=True)
    args = ap.parse_args(argv)
    if not (args.campaign / "campaign.json").is_file():
        print(f"study_wall: error: campaign: no campaign.json in {args.campaign}", file=sys.stderr)
        return 2
    if not args.wall > 0:
        print(f"study_wall: error: --wall must be > 0 s, got {args.wall}", file=sys.stderr)
        return 2
    runs = load_summaries(str(args.campaign))
    first = next(args.campaign.glob("runs/**/summary.json"))
    code = json.loads(first.read_text(encoding="utf-8"))["code"]  # what the searches ran
    per = runs.groupby("strategy")["wall_seconds"].agg(["count", "mean"])
    write_json(
        args.json,
        {
            "machine": machine_record(),
            "loadavg_end": os.getloadavg(),
            "campaign": str(args.campaign),
            "campaign_code": code,
            "searches": len(runs),
            "wall_seconds": args.wall,
            "per_planner": {
                s: {"searches": int(r["count"]), "mean_wall_s": float(r["mean"])}
                for s, r in per.iterrows()
            },
            "target_minutes": 15.0,
        },
    )
    print(f"{len(runs)} searches in {args.wall / 60:.1f} min")
    return 0


if __name__ == "__main__":
    sys.exit(main())
