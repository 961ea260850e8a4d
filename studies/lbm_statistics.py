"""The solver plume's statistics on the full grid against published plume measurements
(docs/scenarios.md): crosswind spread against Briggs' open-country curves, the scalar flux,
centreline fluctuation intensity and intermittency, and a figure of the plume.

    .venv/bin/python studies/lbm_statistics.py [--set truth.model.KEY=VALUE ...] \\
        [--out docs/results/lbm-plume] [--figure docs/figures/lbm-plume.png]

Computes the plume once (cached, as ``dcee plume`` does), writes ``statistics.csv`` (one row per
distance downwind, the recording's attributes beside) and the figure.
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from dcee.provenance import package_version
from dcee.recordings.statistics import briggs_sigma_y, section_statistics
from dcee.scenarios import parse_setting
from dcee.scenarios.schema.truth import LbmSpec
from dcee.simulation.lbm import cached_recording, load_canonical

DISTANCES = [2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0]


def lbm_spec(settings: list[str]) -> LbmSpec:
    """The plume's parameters from ``--set truth.model.KEY=VALUE`` texts (defaults otherwise)."""
    values = {}
    for text in settings:
        key, value = parse_setting(text)
        values[key.removeprefix("truth.model.")] = value
    return LbmSpec(**values)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", dest="settings", action="append", default=[])
    ap.add_argument("--out", type=Path, default=Path("docs/results/lbm-plume"))
    ap.add_argument("--figure", type=Path, default=Path("docs/figures/lbm-plume.png"))
    args = ap.parse_args()
    spec = lbm_spec(args.settings)
    path = cached_recording(spec, announce=print)
    truth = load_canonical(path)
    c, x, y = truth.values, truth.x, truth.y
    rows = section_statistics(c, x, y, DISTANCES)
    import xarray as xr

    with xr.open_dataset(path) as ds:
        attrs = {k: v for k, v in ds.attrs.items() if k not in ("parameters", "source_location")}
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "statistics.csv", "w", newline="") as fh:
        fields = [*rows[0].__dict__, "briggs_D", "briggs_B", "briggs_A"]
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow(
                {
                    **{k: round(v, 4) for k, v in r.__dict__.items()},
                    **{f"briggs_{s}": round(float(briggs_sigma_y(r.x, s)), 3) for s in "DBA"},
                }
            )
    meta = {
        "parameters": json.loads(spec.model_dump_json()),
        "recording": path.name,
        "attributes": {k: (v.item() if hasattr(v, "item") else v) for k, v in attrs.items()},
        "dcee": package_version(),
    }
    (args.out / "recording.json").write_text(json.dumps(meta, indent=2, default=str) + "\n")

    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    extent = [x[0], x[-1], y[0], y[-1]]
    for ax, field, title in (
        (axes[0, 0], c[-1], "instantaneous (last frame)"),
        (axes[0, 1], c.mean(axis=0), f"time mean over {truth.duration:.0f} s"),
    ):
        im = ax.imshow(
            np.log10(np.maximum(field, 1e-4)),
            origin="lower",
            extent=extent,
            vmin=-3.5,
            vmax=0,
            cmap="magma",
        )
        ax.set_title(f"lbm plume, {title}")
        ax.set_xlabel("downwind (m, 1 m/s)")
        ax.set_ylabel("crosswind (m)")
        fig.colorbar(im, ax=ax, label="log10 g/m³ per (g/s per m)")
    xs = np.array([r.x for r in rows])
    ax = axes[1, 0]
    ax.plot(xs, [r.sigma_y for r in rows], "ko-", label="lbm plume σ_y")
    grid = np.linspace(1, xs.max(), 100)
    for s, style in (("A", "r--"), ("B", "m--"), ("C", "b--"), ("D", "g--")):
        ax.plot(grid, briggs_sigma_y(grid, s), style, label=f"Briggs open country {s}")
    ax.set_xlabel("distance downwind (m)")
    ax.set_ylabel("σ_y of the time mean (m)")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    ax.plot(xs, [r.intensity for r in rows], "ko-", label="centreline intensity σc/C̄")
    ax.plot(xs, [r.intermittency for r in rows], "bs-", label="intermittency (c > C̄/10)")
    ax.plot(xs, [r.flux for r in rows], "g^-", label="flux ∫C̄ dy · U")
    ax.set_xlabel("distance downwind (m)")
    ax.set_ylim(0, 1.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    args.figure.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.figure, dpi=90)
    print(f"wrote {args.out / 'statistics.csv'} and {args.figure}")


if __name__ == "__main__":
    main()
