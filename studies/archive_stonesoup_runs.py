"""Keep every stored Stone Soup comparison (issue 82): copy
``docs/results/perf/stonesoup-ste.json`` (``dcee perf --compare-stonesoup``) and
``stonesoup-mcts.json`` (``studies/stonesoup_mcts_study.py``) into
``docs/results/perf/stonesoup-runs/`` as ``KIND-DATE-COMMIT.json`` (a run already kept is left
as it is), so that the speed table is generated from every run on every machine and day, not
from the latest or the best one.

    python studies/archive_stonesoup_runs.py [FILE ...]
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

PERF = Path(__file__).resolve().parents[1] / "docs" / "results" / "perf"
RUNS = PERF / "stonesoup-runs"
LATEST = {"ste": PERF / "stonesoup-ste.json", "mcts": PERF / "stonesoup-mcts.json"}


def kind_of(record: dict) -> str:
    """``ste`` for a `dcee perf --compare-stonesoup` record, ``mcts`` for an MCTS study's."""
    return "ste" if "stonesoup" in record else "mcts"


def archive(path: Path) -> Path:
    """Copy one stored comparison into :data:`RUNS` under its kind, date and commit."""
    record = json.loads(path.read_text(encoding="utf-8"))
    date = (record["load"].get("started") or "undated")[:10]
    commit = (record["machine"].get("code", {}).get("commit") or "unknown")[:7]
    target = RUNS / f"{kind_of(record)}-{date}-{commit}.json"
    if not target.exists():
        RUNS.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, target)
    return target


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    paths = [Path(a) for a in args] or [p for p in LATEST.values() if p.exists()]
    for path in paths:
        print(f"{path} -> {archive(path)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
