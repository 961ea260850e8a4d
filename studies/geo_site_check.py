"""Check every position of the searches on a map site (issue 81): no position and no segment
between two positions enters a building that the UAV cannot overfly, a no-go zone, or leaves the
fence. The check reads the site file itself (shapely, in degrees) and each search's
``estimate.geojson`` path, so it depends on neither the local frame's shapes nor the site grid
the planners use. Writes CHECK (JSON) with one row per search.

    python studies/geo_site_check.py results/geo-example --out docs/results/geo-site
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from shapely import LineString, Point, Polygon

from dcee.geo.site_file import read_site


def check(campaign: Path) -> dict:
    searches = sorted(p.parent for p in campaign.rglob("estimate.geojson"))
    if not searches:
        raise SystemExit(f"no search with estimate.geojson under {campaign}")
    rows = []
    for folder in searches:
        config = json.loads((folder / "config.json").read_text())
        scenario = config["scenario"]
        site = read_site(scenario["world"]["area"])
        height = float(scenario["agent"]["start"][2])
        fence = Polygon(site.area.ring, list(site.area.holes))
        blocked = [
            (b.footprint.label, Polygon(b.footprint.ring))
            for b in site.buildings
            if b.height is None or b.height >= height
        ]
        zones = [(z.label, Polygon(z.ring)) for z in site.no_go]
        doc = json.loads((folder / "estimate.geojson").read_text())
        path = next(f for f in doc["features"] if f["properties"]["kind"] == "path")
        pts = np.array(path["geometry"]["coordinates"], dtype=np.float64)
        summary = json.loads((folder / "summary.json").read_text())
        entered = []
        for k, p in enumerate(pts):
            if not fence.covers(Point(p)):
                entered.append(f"position {k} outside the fence")
            for label, shape in (*blocked, *zones):
                if shape.intersects(Point(p)):
                    entered.append(f"position {k} in {label}")
                if k and shape.intersects(LineString([pts[k - 1], p])):
                    entered.append(f"segment {k - 1}-{k} crosses {label}")
        rows.append(
            {
                "search": folder.relative_to(campaign).as_posix(),
                "strategy": summary["strategy"],
                "seed": summary["seed"],
                "positions": len(pts),
                "entered": entered,
                "final_rmse": summary["final_rmse"],
                "source_acquired": summary["source_acquired"],
                "estimate": doc["features"][0]["geometry"]["coordinates"],
            }
        )
    return {
        "site": str(Path(scenario["world"]["area"]).name),
        "flight_height_m": height,
        "blocking": [label for label, _ in blocked],
        "no_go": [label for label, _ in zones],
        "code": json.loads((searches[0] / "summary.json").read_text())["code"],
        "searches": rows,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("campaign", type=Path)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    result = check(args.campaign)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "check.json").write_text(json.dumps(result, indent=1) + "\n")
    bad = [r for r in result["searches"] if r["entered"]]
    print(
        f"{len(result['searches'])} searches, {sum(r['positions'] for r in result['searches'])} "
        f"positions; entered: {len(bad)}"
    )


if __name__ == "__main__":
    main()
