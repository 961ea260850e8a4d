"""What every table family shares: the stored results, row selection, cell formats and the
words for the defaults a row was flown at."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "docs" / "results"


def study(name: str) -> pd.DataFrame:
    return pd.read_csv(RESULTS / name / "metrics.csv")


def paired(name: str) -> pd.DataFrame:
    return pd.read_csv(RESULTS / name / "paired.csv")


def matching(frame: pd.DataFrame, strategy: str, **where: object) -> pd.DataFrame:
    """The rows of ``strategy`` where every column equals its value (a dict value: the value
    for this strategy, e.g. :data:`TODAY_DEFAULTS`)."""
    rows = frame[frame["strategy"] == strategy]
    for key, value in where.items():
        if isinstance(value, dict):
            value = value[strategy]
        rows = rows[rows[key] == value]
    return rows


def pick(frame: pd.DataFrame, strategy: str, **where: object) -> pd.Series:
    """The one row of ``strategy`` where every column equals its value (a dict value: the value
    for this strategy, e.g. :data:`TODAY_DEFAULTS`)."""
    rows = matching(frame, strategy, **where)
    if len(rows) != 1:
        raise KeyError(f"{strategy} {where}: {len(rows)} rows")
    return rows.iloc[0]


# --- cell formats --------------------------------------------------------------------------


def count(r: pd.Series) -> str:
    """acquired k/n"""
    n = int(r["searches"])
    return f"{round(r['source_acquired_rate'] * n)}/{n}"


def share(r: pd.Series, key: str) -> str:
    """ "82 % [75, 88]" from a rate and its interval"""
    v, lo, hi = (r[f"{key}_rate"], r[f"{key}_lo"], r[f"{key}_hi"])
    if math.isnan(v):
        return "—"
    return f"{100 * v:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]"


def acquired(r: pd.Series) -> str:
    return f"{count(r)}, {share(r, 'source_acquired')}"


def interval(r: pd.Series, key: str, fmt: str) -> str:
    v, lo, hi = r[key], r.get(f"{key}_lo", math.nan), r.get(f"{key}_hi", math.nan)

    def one(x: float) -> str:
        return "> budget" if math.isinf(x) else format(x, fmt)

    if math.isnan(lo) or math.isnan(hi):
        return one(v)
    return f"{one(v)} [{one(lo)}, {one(hi)}]"


def rmse(r: pd.Series) -> str:
    return interval(r, "median_final_rmse", ".2f")


def time_to_1m(r: pd.Series) -> str:
    if math.isnan(r["reached_1m"]):
        return "—"  # not in the published table the results were transcribed from
    if r["reached_1m"] == 0:
        return "never"
    if math.isinf(r["time_to_1m"]):  # fewer than half got there: no median within the budget
        return f"> budget ({100 * r['reached_1m']:.0f} % got there)"
    v = interval(r, "time_to_1m", ".0f")
    if r["reached_1m"] < 1:
        v += f" ({100 * r['reached_1m']:.0f} % got there)"
    return v


def stall(r: pd.Series) -> str:
    longest, stalled = r.get("longest_stall", math.nan), r.get("stalled", math.nan)
    if math.isnan(stalled):
        return "—"
    if math.isnan(longest):
        return f"{int(stalled)} > 60 s"
    return f"{longest:.0f} ({int(stalled)} > 60 s)"


def table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


PLANNERS = ("dcee-cl", "infotaxis", "dcee-mcts")


TODAY_DEFAULTS = {"dcee-cl": "2026-12-02", "infotaxis": "2026-12-02", "dcee-mcts": "2026-12-02"}
"""Per planner, the ``defaults`` tag of rows flown at today's defaults (a 0.5 m near-source
fall, repeat power 1/2, the backflow member and the disc member at prior odds 9 : 1 learned, the
95 % region the members' mixture's; ``dcee-cl`` looks three moves ahead in a turbulent plume
since 2026-11-29 (b) (two on 2026-11-29), ``search.lookahead``, which changed no other planner;
the region widened by the model-discrepancy floor, ``estimator.region_floor`` = 0.25 m, since
2026-12-02, for every planner: rows flown before it report the particles' own region)."""
EARLIER_DEFAULTS = {
    "2026-11-29b": "defaults of 2026-11-29 (b) (`dcee-cl` three moves ahead), the particles' "
    "own 95 % region",
    "2026-11-29": "defaults of 2026-11-29 (`dcee-cl` two moves ahead), the particles' own 95 % "
    "region",
    "2026-11-27c": "defaults of 2026-11-27 (c) (`dcee-cl` one move ahead), the particles' own "
    "95 % region",
    "2026-11-27b": "defaults of 2026-11-27 (b): the backflow member alone, the selected "
    "member's region",
    "2026-11-27": "defaults of 2026-11-27 before the backflow member",
    "2026-11-23": "defaults of 2026-11-23 (2.5 m fall, repeat power 1/4, no backflow member)",
}
"""How a row flown before today's defaults says so, by its ``defaults`` tag."""
OLD_DEFAULTS = EARLIER_DEFAULTS["2026-11-23"]


def earlier_defaults(tag: str, strategy: str) -> str:
    """How a row of ``strategy`` flown at the earlier defaults ``tag`` says so: the words of
    :data:`EARLIER_DEFAULTS`, without the parenthesis on how far ``dcee-cl`` looked ahead on a
    row of another planner (``search.lookahead`` changed no other planner)."""
    words = EARLIER_DEFAULTS[tag]
    if strategy != "dcee-cl":
        words = re.sub(r" \(`dcee-cl` \w+ moves? ahead\)", "", words)
    return words


def small_sample(r: pd.Series) -> str:
    """ ", N configurations (small sample)" for a row of fewer than the 100 held-out ones."""
    n = int(r["searches"])
    return f", {n} configurations (small sample)" if n < 100 else ""


def latest_defaults(frame: pd.DataFrame, strategies: tuple[str, ...], **where: object) -> dict:
    """Per planner, the newest ``defaults`` tag among its rows where every column equals its
    value (the tags sort by date)."""
    return {s: max(matching(frame, s, **where)["defaults"].astype(str)) for s in strategies}


def defaults_words(tags: dict) -> str:
    """ "today's defaults" when every planner's newest rows are today's, else which of them."""
    if all(tag == TODAY_DEFAULTS.get(s) for s, tag in tags.items()):
        return "today's defaults (`dcee-cl` three moves ahead, the region's floor 0.25 m)"
    parts = [
        f"`{s}` at "
        + ("today's" if tag == TODAY_DEFAULTS.get(s) else f"the {earlier_defaults(tag, s)}")
        for s, tag in tags.items()
    ]
    return ", ".join(parts)
