"""Convert a campaign folder written before 2026-11-22 (``runs/<config>/<strategy>/seed-<k>.json``
+ ``.parquet`` + ``.npz``) into the saved-search layout that ``dcee report`` and
``dcee.analysis.results`` read (``runs/config=…/strategy=…/seed=…/summary.json`` …), in place.

The old summaries recorded no code version; the migrated ones say ``{"version": <old>,
"commit": null, "source_hash": "pre-2026-11-22"}`` so that they are never mistaken for results
of newer code, and ``campaign.json`` gets the same entry (resuming such a campaign needs
``--allow-code-change``, and is better not done: start a new folder).

    .venv/bin/python scripts/migrate_results.py results/paper-full-cl [more folders]
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

from dcee.campaign.runner import SearchTask
from dcee.io import write_json

OLD = re.compile(r"seed-(\d+)\.json$")


def migrate(folder: Path) -> int:
    meta_path = folder / "campaign.json"
    meta = json.loads(meta_path.read_text())
    scenarios = meta["settings"]["scenarios"]
    code = {"version": meta.get("version"), "commit": None, "dirty": None}
    code["source_hash"] = "pre-2026-11-22"
    moved = 0
    for summary_path in sorted((folder / "runs").glob("*/*/seed-*.json")):
        match = OLD.search(summary_path.name)
        if match is None:  # error files
            continue
        summary = json.loads(summary_path.read_text())
        config, strategy, seed = summary["config"], summary["strategy"], int(match.group(1))
        target = SearchTask(str(folder), config, strategy, seed, {}).folder
        target.mkdir(parents=True, exist_ok=True)
        stem = summary_path.with_suffix("")
        stem.with_suffix(".parquet").rename(target / "steps.parquet")
        stem.with_suffix(".npz").rename(target / "posterior.npz")
        write_json(
            target / "config.json",
            {
                "scenario": scenarios[config],
                "strategy": strategy,
                "seed": seed,
                "planner_options": summary.get("planner_options"),
                "code": code,
            },
        )
        summary["code"] = code
        write_json(target / "summary.json", summary)
        summary_path.unlink()
        moved += 1
    for error in (folder / "runs").glob("*/*/seed-*.error.json"):
        error.unlink()  # a failed search of the old layout is simply redone in a new folder
    for empty in sorted((folder / "runs").glob("*/*"), reverse=True):
        if empty.is_dir() and not any(empty.iterdir()):
            empty.rmdir()
    for empty in (folder / "runs").glob("*"):
        if empty.is_dir() and not any(empty.iterdir()):
            empty.rmdir()
    meta.setdefault("code_versions", [code])
    write_json(meta_path, meta)
    return moved


if __name__ == "__main__":
    for arg in sys.argv[1:]:
        print(f"{arg}: {migrate(Path(arg))} searches migrated")
