"""The stop-when-localised rule replayed on recorded full-budget searches (issue 31, item 8).

For every rule (threshold share of ``search.acquired_rmse``, hold in s) and every saved search,
:meth:`dcee.stopping.StopRule.stop_index` finds the reading at which the search would have
stopped; the search up to there is the recorded one (the rule changes nothing before it stops),
so the replay is exact. Per rule and campaign folder:

* stopped: share of searches the rule ends before the budget;
* median stop time (s; the budget for searches it never stops) and the time it saves;
* at the stop: median RMSE, the share with RMSE < 1 m and < the acquired bar ("correct stops"),
  the share of stopped searches ending with RMSE ≥ 1 m ("early stops");
* the paired change in RMSE against flying the whole budget (median difference, Wilcoxon p).

Usage::

    python studies/stop_rule_table.py results/stop-tune-* --grid            # choose (tuning)
    python studies/stop_rule_table.py results/stop-held-out-* --csv out.csv # report the default
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.results import find_runs
from dcee.analysis.statistics import median_ci, wilson
from dcee.stopping import DEFAULT_STOP_HOLD, DEFAULT_STOP_SHARE, StopRule

SHARES = (0.05, 0.1, 0.15, 0.2, 0.3)
HOLDS = (0.0, 15.0, 30.0, 60.0)


def load(folder: Path) -> list[dict]:
    """Per search: times, spreads, RMSEs, budget and acquired bar."""
    out = []
    for run in find_runs(folder):
        cfg = json.loads((run / "config.json").read_text())
        search = cfg["scenario"]["search"]
        steps = pd.read_parquet(run / "steps.parquet", columns=["time", "spread", "rmse"])
        out.append(
            {
                "run": run,
                "time": steps["time"].to_numpy(),
                "spread": steps["spread"].to_numpy(),
                "rmse": steps["rmse"].to_numpy(),
                "budget": float(search["budget"]),
                "acquired": float(search["acquired_rmse"]),
            }
        )
    return out


def evaluate(searches: list[dict], share: float, hold: float) -> dict:
    stop_t, stop_rmse, final_rmse, stopped = [], [], [], []
    for s in searches:
        rule = StopRule(share * s["acquired"], hold)
        i = rule.stop_index(s["time"], s["spread"])
        final = float(s["rmse"][-1])
        final_rmse.append(final)
        if i is None:
            stopped.append(False)
            stop_t.append(s["budget"])
            stop_rmse.append(final)
        else:
            stopped.append(True)
            stop_t.append(float(s["time"][i]))
            stop_rmse.append(float(s["rmse"][i]))
    n = len(searches)
    stopped_a = np.array(stopped)
    stop_rmse_a, final_a = np.array(stop_rmse), np.array(final_rmse)
    acquired = np.array([s["acquired"] for s in searches])
    budget = np.array([s["budget"] for s in searches])
    saved = budget - np.array(stop_t)
    diff = stop_rmse_a - final_a
    p = float(stats.wilcoxon(diff).pvalue) if np.any(diff != 0) else 1.0
    early = int(np.sum(stopped_a & (stop_rmse_a >= 1.0)))
    return {
        "share": share,
        "hold": hold,
        "searches": n,
        "stopped": wilson(int(stopped_a.sum()), n),
        "stop_time": median_ci(np.array(stop_t)),
        "saved_mean": float(saved.mean()),
        "rmse_at_stop": median_ci(stop_rmse_a),
        "below_1m": wilson(int(np.sum(stop_rmse_a < 1.0)), n),
        "acquired": wilson(int(np.sum(stop_rmse_a < acquired)), n),
        "acquired_full": int(np.sum(final_a < acquired)),
        "early": early,
        "early_of": int(stopped_a.sum()),
        "rmse_full": float(np.median(final_a)),
        "diff": float(np.median(diff)),
        "p": p,
    }


def pct(t: tuple[float, float, float]) -> str:
    return f"{100 * t[0]:.0f} % [{100 * t[1]:.0f}, {100 * t[2]:.0f}]"


def row(r: dict) -> str:
    med = r["stop_time"]
    rm = r["rmse_at_stop"]
    return (
        f"| {r['share']:g} × acquired, {r['hold']:g} s | {r['searches']} | {pct(r['stopped'])} "
        f"| {med[0]:.0f} [{med[1]:.0f}, {med[2]:.0f}] | {r['saved_mean']:.0f} "
        f"| {rm[0]:.2f} [{rm[1]:.2f}, {rm[2]:.2f}] (budget: {r['rmse_full']:.2f}) "
        f"| {pct(r['acquired'])} (budget: {r['acquired_full']}/{r['searches']}) "
        f"| {pct(r['below_1m'])} | {r['early']}/{r['early_of']} "
        f"| {r['diff']:+.3f} m, p = {r['p']:.2g} |"
    )


HEADER = (
    "| rule (spread below, held) | searches | stopped before the budget | median stop time (s) "
    "| mean time saved (s) | median RMSE at the stop (m) | acquired at the stop "
    "| RMSE < 1 m at the stop | stopped with RMSE ≥ 1 m | RMSE change vs whole budget (median, "
    "Wilcoxon p) |\n|---|---|---|---|---|---|---|---|---|---|"
)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folders", nargs="+", type=Path)
    ap.add_argument("--grid", action="store_true", help="every rule of the grid, not the default")
    ap.add_argument("--csv", type=Path, help="write the rows here too")
    args = ap.parse_args(argv)
    rules = (
        [(s, h) for s in SHARES for h in HOLDS]
        if args.grid
        else [(DEFAULT_STOP_SHARE, DEFAULT_STOP_HOLD)]
    )
    rows = []
    for folder in args.folders:
        searches = load(folder)
        print(f"\n{folder} ({len(searches)} searches)\n\n{HEADER}")
        for share, hold in rules:
            r = evaluate(searches, share, hold)
            print(row(r))
            flat = {"folder": folder.name}
            for k, v in r.items():
                if isinstance(v, tuple):
                    flat[k], flat[f"{k}_lo"], flat[f"{k}_hi"] = v
                else:
                    flat[k] = v
            rows.append(flat)
    if args.csv:
        pd.DataFrame(rows).to_csv(args.csv, index=False, float_format="%.6g")
    return 0 if rows and not any(math.isnan(r["diff"]) for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
