"""A search's result and its folder: per-reading records, summary, final posterior sample and
snapshots; written atomically (``summary.json`` last marks it complete) and read back. The same
layout serves ``dcee run`` and every search of a campaign."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from dcee.io import write_atomic, write_json
from dcee.provenance import code_version

SNAPSHOT_FRACTIONS = (0.1, 0.3, 0.5, 1.0)
"""When a saved search keeps particle snapshots, as fractions of its budget (the paper's figure 4
shows 90, 270, 450 and 900 s of a 900 s search). Derived from the budget, so a 60 s search has
snapshots too."""
FINAL_SAMPLE = 2000
"""Particles kept from a saved search's final posterior (drawn by weight, every parameter)."""
SNAPSHOT_SAMPLE = 1000
"""Particles kept per saved snapshot (source locations only)."""
RESULT_FILES = ("summary.json", "config.json", "steps.parquet", "posterior.npz")
"""The files of a saved search. ``summary.json`` is written last and marks it complete."""


def snapshot_times(budget: float) -> tuple[float, ...]:
    """The snapshot times (s) of a search with this budget: :data:`SNAPSHOT_FRACTIONS` of it."""
    return tuple(round(f * budget, 6) for f in SNAPSHOT_FRACTIONS)


@dataclass
class EpisodeResult:
    """Per-step records (list of dicts, one per reading), the summary, the final particles
    (N, 8) with every parameter (known ones included) and their weights (N,), and optional
    snapshots of the particles' source locations for figures: list of (time, (n, 3) array)."""

    records: list[dict[str, Any]]
    summary: dict[str, Any]
    final_theta: np.ndarray
    final_weights: np.ndarray
    snapshots: list[tuple[float, np.ndarray]] = field(default_factory=list)
    config: dict[str, Any] | None = None
    """What made it: ``{"scenario": resolved scenario, "strategy", "seed", "planner_options",
    "code"}`` (set by :func:`run_episode` and by :meth:`load`)."""

    def save(self, folder: str | Path, keep_snapshots: bool = True) -> Path:
        """Write the search to ``folder`` (created): ``steps.parquet`` (one row per reading),
        ``posterior.npz`` (``final_particles`` (n, 8) float32, :data:`FINAL_SAMPLE` draws by
        weight from the final posterior with every parameter; with ``keep_snapshots``,
        ``snapshot_times`` (k,) s and ``snapshot_particles`` (k, m, 3) source locations),
        ``config.json`` and ``summary.json`` (last: its presence marks a complete result).
        Every file is written atomically. The same layout serves ``dcee run`` and every search
        of a campaign; :meth:`load` reads it back."""
        import pandas as pd

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "summary.json").unlink(missing_ok=True)  # incomplete until rewritten
        for name in RESULT_FILES:  # temporaries of a writer killed mid-file (dcee.io)
            for leftover in folder.glob(f".{name}.*"):
                leftover.unlink(missing_ok=True)
        config = self.config or {}
        seed = int(self.summary.get("seed", 0))
        records = pd.DataFrame.from_records(self.records)
        w = self.final_weights / self.final_weights.sum()
        idx = np.random.default_rng(seed).choice(len(w), size=min(FINAL_SAMPLE, len(w)), p=w)
        arrays: dict[str, np.ndarray] = {
            "final_particles": self.final_theta[idx].astype(np.float32)
        }
        snapshots = self._standard_snapshots() if keep_snapshots else []
        if snapshots:
            arrays["snapshot_times"] = np.array([t for t, _ in snapshots])
            arrays["snapshot_particles"] = np.stack(
                [p[:SNAPSHOT_SAMPLE].astype(np.float32) for _, p in snapshots]
            )
        write_atomic(folder / "steps.parquet", lambda p: records.to_parquet(p, index=False))
        write_atomic(folder / "posterior.npz", lambda p: _savez(p, arrays))
        write_json(folder / "config.json", config)
        summary = {"code": code_version(), **self.summary}  # run_episode already set it
        summary.update(record_rows=len(records), final_sample=len(idx))
        frame = ((config.get("scenario") or {}).get("world") or {}).get("frame")
        if frame is not None:  # a site in geographic coordinates: the answer on a map too
            from dcee.runs.map_answer import write_map_answer

            summary["final_mean_geo"] = write_map_answer(folder, self, frame)
            self.summary["final_mean_geo"] = summary["final_mean_geo"]
        write_json(folder / "summary.json", summary)
        return folder

    def _standard_snapshots(self) -> list[tuple[float, np.ndarray]]:
        """The snapshots at :func:`snapshot_times` of the budget (the first taken at or after
        each) and the last one: what a saved search keeps, whatever else was taken (an
        animation takes 41), so every saved search has the same comparison-grid columns."""
        if not self.snapshots:
            return []
        budget = float(self.summary.get("budget", self.snapshots[-1][0]))
        keep = {len(self.snapshots) - 1}
        for target in snapshot_times(budget):
            k = next((i for i, (t, _) in enumerate(self.snapshots) if t >= target - 1e-9), None)
            if k is not None:
                keep.add(k)
        return [self.snapshots[i] for i in sorted(keep)]

    @staticmethod
    def is_complete(folder: str | Path) -> bool:
        """True when ``folder`` holds a complete saved search: the summary parses, and the record
        and posterior files exist with the row and particle counts it names."""
        folder = Path(folder)
        try:
            summary = json.loads((folder / "summary.json").read_text())
            import pyarrow.parquet as pq

            rows = pq.ParquetFile(folder / "steps.parquet").metadata.num_rows
            with np.load(folder / "posterior.npz") as z:
                n_final = z["final_particles"].shape[0]
            json.loads((folder / "config.json").read_text())
        except Exception:  # missing, truncated or corrupt
            return False
        return rows == summary.get("record_rows") and n_final == summary.get("final_sample")

    @classmethod
    def load(cls, folder: str | Path) -> EpisodeResult:
        """Read a search written by :meth:`save`. ``final_theta`` is the saved sample of the
        final posterior (equal weights); ``records`` one dict per reading."""
        import pandas as pd

        from dcee.errors import DceeInputError

        folder = Path(folder)
        if not cls.is_complete(folder):
            raise DceeInputError("results", f"{folder} holds no complete dcee search result")
        summary = json.loads((folder / "summary.json").read_text())
        config = json.loads((folder / "config.json").read_text())
        records = pd.read_parquet(folder / "steps.parquet").to_dict("records")
        with np.load(folder / "posterior.npz") as z:
            final = z["final_particles"].astype(np.float64)
            snaps = []
            if "snapshot_times" in z:
                snaps = [
                    (float(t), p.astype(np.float64))
                    for t, p in zip(z["snapshot_times"], z["snapshot_particles"], strict=True)
                ]
        weights = np.full(len(final), 1.0 / len(final))
        return cls(records, summary, final, weights, snaps, config)


def _savez(path: Path, arrays: dict[str, np.ndarray]) -> None:
    with open(path, "wb") as f:  # a file object: np.savez would append .npz to a path
        np.savez_compressed(f, **arrays)
