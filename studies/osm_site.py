"""Write a dcee site file (GeoJSON) of a real place from an OpenStreetMap extract (issue 81).

The buildings (``building`` with OpenStreetMap's ``height`` / ``building:levels``, as mapped),
the no-go zones (ways of the extract, by id) and their tags come from the extract as they are;
the search area ("the fence"), the start and the simulated release are this script's choices,
given in metres east and north of the centroid of the way ``--around`` and written as
longitude and latitude (by the local equirectangular scale, good to about 0.5 %: it only places
the chosen shapes; dcee builds its own frame from the file). Every building
and no-go way that meets the area is kept whole, with its OpenStreetMap id.

The site that ships with dcee, ``area:fontvieille`` (src/dcee/scenarios/sites/fontvieille.geojson),
was written from Geofabrik's Monaco extract of 2023-12-26 as quackosm 0.19.0 ships it with its
tests (the package registry is the only source of map data this project's machines reach):

    pip download --no-deps --no-binary :all: quackosm==0.19.0 && tar xzf quackosm-0.19.0.tar.gz
    pip install osmium
    python studies/osm_site.py quackosm-0.19.0/tests/test_files/monaco.osm.pbf \\
        --around 836387059 --area=-90,-70,70,60 --no-go 157456963 --no-go 731585434 \\
        --start=60,-60,4 --source=22,14,4 --rate 5 --wind-from 315 --wind-speed 3 \\
        --name "Fontvieille, Monaco: the SMA waste incinerator and its block" \\
        --out src/dcee/scenarios/sites/fontvieille.geojson

Map data © OpenStreetMap contributors, available under the Open Database Licence (ODbL 1.0).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

ATTRIBUTION = "© OpenStreetMap contributors, ODbL 1.0 (https://www.openstreetmap.org/copyright)"
KEEP_TAGS = ("building", "height", "building:levels", "name", "landuse", "amenity", "operator")


def _numbers(text: str, count: int, what: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise SystemExit(f"osm_site: error: {what}: give {count} numbers separated by commas")
    return values


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pbf", type=Path, help="an OpenStreetMap extract (.osm.pbf)")
    parser.add_argument("--around", type=int, required=True, help="way id: the local origin")
    parser.add_argument("--area", required=True, help="x0,y0,x1,y1 m: the search area")
    parser.add_argument("--no-go", type=int, action="append", default=[], help="way id")
    parser.add_argument("--start", required=True, help="x,y,height m")
    parser.add_argument("--source", required=True, help="x,y,height m: the simulated release")
    parser.add_argument("--rate", type=float, default=5.0, help="g/s")
    parser.add_argument("--wind-from", type=float, default=270.0, help="compass bearing, °")
    parser.add_argument("--wind-speed", type=float, default=3.0, help="m/s")
    parser.add_argument("--name", required=True)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    x0, y0, x1, y1 = _numbers(args.area, 4, "area")
    start = _numbers(args.start, 3, "start")
    source = _numbers(args.source, 3, "source")
    if not args.pbf.is_file():
        print(f"osm_site: error: pbf: no such file {args.pbf}", file=sys.stderr)
        return 2
    try:
        import osmium
        from shapely.geometry import Polygon, box
    except ImportError:
        print("osm_site: error: needs osmium and shapely (pip install osmium)", file=sys.stderr)
        return 2

    ways: dict[int, tuple[dict[str, str], list[tuple[float, float]]]] = {}

    class Ways(osmium.SimpleHandler):
        def way(self, w: object) -> None:
            tags = dict(w.tags)
            if "building" in tags or w.id in args.no_go or w.id == args.around:
                try:
                    ways[w.id] = (tags, [(n.lon, n.lat) for n in w.nodes])
                except osmium.InvalidLocationError:
                    pass

    Ways().apply_file(str(args.pbf), locations=True)
    if args.around not in ways:
        print(f"osm_site: error: around: no way {args.around} in {args.pbf}", file=sys.stderr)
        return 2
    ring = ways[args.around][1][:-1]
    lon0 = sum(p[0] for p in ring) / len(ring)
    lat0 = sum(p[1] for p in ring) / len(ring)
    east = 111_320.0 * math.cos(math.radians(lat0))  # m per degree, locally
    north = 110_540.0

    def local(p: tuple[float, float]) -> tuple[float, float]:
        return ((p[0] - lon0) * east, (p[1] - lat0) * north)

    def degrees(x: float, y: float) -> list[float]:
        return [round(lon0 + x / east, 7), round(lat0 + y / north, 7)]

    area = box(x0, y0, x1, y1)
    features = [
        {
            "type": "Feature",
            "properties": {
                "dcee": "area",
                "name": f"search area (chosen, not mapped): {args.name}",
            },
            "geometry": {
                "type": "Polygon",
                "coordinates": [[degrees(x, y) for x, y in area.exterior.coords]],
            },
        }
    ]
    for way_id, (tags, points) in sorted(ways.items()):
        if len(points) < 4 or points[0] != points[-1]:
            continue
        shape = Polygon([local(p) for p in points])
        if not shape.intersects(area):
            continue
        props = {k: tags[k] for k in KEEP_TAGS if k in tags}
        props["osm_id"] = f"way/{way_id}"
        if way_id in args.no_go:
            props["dcee"] = "no-go"
            props.pop("building", None)
        elif "building" not in tags or tags["building"] == "no":
            continue
        coords = [[round(p[0], 7), round(p[1], 7)] for p in points]
        features.append(
            {"type": "Feature", "properties": props,
             "geometry": {"type": "Polygon", "coordinates": [coords]}}
        )  # fmt: skip
    features.append(
        {"type": "Feature", "properties": {"dcee": "start", "name": "take-off", "height": start[2]},
         "geometry": {"type": "Point", "coordinates": degrees(start[0], start[1])}}
    )  # fmt: skip
    features.append(
        {"type": "Feature",
         "properties": {"dcee": "source", "name": "simulated leak (not a recorded event)",
                        "height": source[2], "rate": args.rate, "wind_from": args.wind_from,
                        "wind_speed": args.wind_speed},
         "geometry": {"type": "Point", "coordinates": degrees(source[0], source[1])}}
    )  # fmt: skip
    collection = {
        "type": "FeatureCollection",
        "attribution": f"{args.name}. Buildings and no-go zones: {args.pbf.name}, "
        f"{ATTRIBUTION}; the area, the start and the simulated leak chosen for dcee "
        f"(studies/osm_site.py)",
        "features": features,
    }
    args.out.write_text(json.dumps(collection, indent=1, ensure_ascii=False) + "\n")
    print(f"{args.out}: {len(features) - 3} buildings and no-go zones", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
