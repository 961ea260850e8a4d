"""Load saved searches: one ``dcee run`` folder, a folder of them, or a whole campaign.

Every search is a folder written by :meth:`dcee.runs.EpisodeResult.save`
(``summary.json``, ``config.json``, ``steps.parquet``, ``posterior.npz``); a campaign keeps them
under ``runs/config=…/strategy=…/seed=…/``. These readers find every complete search below a
folder, so the same call loads either.

>>> runs = load_summaries("results/my-campaign")          # doctest: +SKIP
>>> steps = load_steps("results/my-campaign", ["time", "rmse"])  # doctest: +SKIP
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pandas as pd

from dcee.errors import DceeInputError


def find_runs(folder: str | Path) -> list[Path]:
    """Every complete saved search at or below ``folder`` (sorted). Incomplete ones (a search
    killed mid-write, a failed one) are skipped: :func:`incomplete_runs`."""
    return _runs(folder, complete=True)


def incomplete_runs(folder: str | Path) -> list[Path]:
    """The folders at or below ``folder`` with a ``summary.json`` that :func:`find_runs`
    skips (sorted): a search killed mid-write, a failed one, a file since corrupted."""
    return _runs(folder, complete=False)


def _runs(folder: str | Path, complete: bool) -> list[Path]:
    """The folders at or below ``folder`` holding a ``summary.json``, complete or not."""
    from dcee.runs import EpisodeResult

    folder = Path(folder)
    if not folder.is_dir():
        raise DceeInputError("results", f"no such folder {str(folder)!r}")
    found = sorted(p.parent for p in folder.rglob("summary.json"))
    return [p for p in found if EpisodeResult.is_complete(p) == complete]


def load_summaries(folder: str | Path) -> pd.DataFrame:
    """One row per complete search below ``folder``: its summary (``scenario``, ``strategy``,
    ``seed``, ``final_rmse``, ``time_to_rmse_1m`` …) plus ``run_dir``, the folder it came
    from. Raises :class:`DceeInputError` when there is none."""
    rows = []
    for run in find_runs(folder):
        summary = json.loads((run / "summary.json").read_text())
        summary["run_dir"] = str(run)
        rows.append(summary)
    if not rows:
        raise DceeInputError(
            "results", f"{folder} holds no finished searches (no complete summary.json below it)"
        )
    return pd.DataFrame(rows)


def load_steps(folder: str | Path, columns: list[str] | None = None) -> pd.DataFrame:
    """Every per-reading record below ``folder`` in one frame, with ``scenario``,
    ``strategy`` and ``seed`` columns naming the search each row belongs to. ``columns``
    selects record columns (``time``, ``rmse``, ``x`` …; all by default)."""
    frames = []
    for _, row in load_summaries(folder).iterrows():
        steps = pd.read_parquet(Path(row["run_dir"]) / "steps.parquet", columns=columns)
        steps.insert(0, "seed", row["seed"])
        steps.insert(0, "strategy", row["strategy"])
        steps.insert(0, "scenario", row["scenario"])
        frames.append(steps)
    return pd.concat(frames, ignore_index=True)


def load_config(run_dir: str | Path) -> dict[str, Any]:
    """The ``config.json`` of one saved search: resolved scenario, strategy, seed, planner
    options and code version."""
    return json.loads((Path(run_dir) / "config.json").read_text())


def describe_folder(folder: str | Path) -> dict[str, Any]:
    """``campaign.json`` when ``folder`` is a campaign, else a description of the loose
    searches it holds (what the report prints in its header)."""
    path = Path(folder) / "campaign.json"
    if path.is_file():
        try:
            meta = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError) as exc:
            raise DceeInputError("campaign", f"{path} is not valid JSON ({exc})") from None
        if not isinstance(meta, dict) or "settings" not in meta:
            raise DceeInputError("campaign", f"{path} is not a dcee campaign file")
        return meta
    return {"settings": {"suite": f"searches in {Path(folder).name}", "unknown": None}}


__all__ = ["describe_folder", "find_runs", "load_config", "load_steps", "load_summaries"]
