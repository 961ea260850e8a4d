"""A saved search's answer on a map, for a scenario in geographic coordinates (``world.frame``):
``estimate.geojson`` and ``estimate.kml`` beside the other result files (:mod:`dcee.geo.export`),
and the estimate's longitude and latitude in the summary."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from dcee.estimation.summaries import credible_ellipse_boundary
from dcee.io import write_atomic, write_json

MAP_FILES = ("estimate.geojson", "estimate.kml")


def write_map_answer(folder: Path, result: Any, frame_spec: dict[str, Any]) -> dict[str, Any]:
    """Write the map files of ``result`` (an :class:`~dcee.runs.result.EpisodeResult`) into
    ``folder``; returns the estimate as ``{longitude, latitude, height_m, frame}`` for the
    summary."""
    from dcee.geo.export import MapAnswer, estimate_geojson, estimate_kml
    from dcee.geo.frame import LocalFrame

    frame = LocalFrame(**{k: float(frame_spec[k]) for k in ("latitude", "longitude", "x0", "y0")})
    summary = result.summary
    records = result.records
    weights = result.final_weights / result.final_weights.sum()
    region = credible_ellipse_boundary(
        result.final_theta[:, :2], weights, 0.95, float(summary.get("region_floor") or 0.0)
    )
    mean = np.asarray(summary["final_mean"], dtype=np.float64)
    if mean.size == 2:  # a planar search: its height is the plane's
        mean = np.append(mean, float(result.final_theta[0, 2]))
    scenario = (result.config or {}).get("scenario", {})
    model = scenario.get("truth", {}).get("model")
    unit = "ppm" if isinstance(model, dict) and model.get("kind") == "gaden" else "g/m3"
    answer = MapAnswer(
        estimate=mean[:3],
        region=region,
        path=np.array([[r["x"], r["y"], r["z"]] for r in records], dtype=np.float64).reshape(-1, 3),
        times=np.array([r["time"] for r in records], dtype=np.float64),
        readings=np.array([r["reading"] for r in records], dtype=np.float64),
        detections=np.array([bool(r["detection"]) for r in records]),
        unit=unit,
        name=f"dcee: {summary.get('scenario', '')} {summary.get('strategy', '')}".strip(),
    )
    # the frame's largest scale error over the area: at the east or west edge of the volume
    high_x = float((scenario.get("volume") or {}).get("high", [0.0])[0])
    half_width = max(abs(frame.x0), abs(high_x - frame.x0))
    extra = {
        "scenario": summary.get("scenario"),
        "strategy": summary.get("strategy"),
        "code": summary.get("code"),
        "frame": frame.proj,
        "frame_description": frame.describe(half_width),
    }
    write_json(folder / "estimate.geojson", estimate_geojson(frame, answer, extra))
    write_atomic(
        folder / "estimate.kml",
        lambda p: Path(p).write_text(estimate_kml(frame, answer), encoding="utf-8"),
    )
    lon, lat = frame.to_geo(mean[:1], mean[1:2])
    return {
        "longitude": round(float(lon[0]), 8),
        "latitude": round(float(lat[0]), 8),
        "height_m": round(float(mean[2]), 3),
        "frame": frame.proj,
        "frame_description": extra["frame_description"],
    }


__all__ = ["MAP_FILES", "write_map_answer"]
