"""Sites and answers in geographic coordinates (issue 81): the local frame against pyproj's
geodesic, the site file's shapes, estimate.geojson against RFC 7946, the same search in both
frames, and every bad input refused in one line with nothing written."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.geo.frame import LocalFrame, frame_for_bounds
from dcee.scenarios import load_scenario
from dcee.scenarios.schema import validate_scenario
from tests.helpers import run_cli

SITE = Path(__file__).parents[1] / "src" / "dcee" / "scenarios" / "sites" / "example-works.geojson"
REAL_SITE = SITE.with_name("fontvieille.geojson")
"""A real site: Fontvieille, Monaco, from OpenStreetMap (studies/osm_site.py)"""


def test_frame_round_trip_and_distances_match_the_geodesic() -> None:
    from pyproj import Geod

    frame = frame_for_bounds(-3.20, 55.94, -3.18, 55.95)  # about 1.25 km x 1.1 km
    rng = np.random.default_rng(1)
    lon = rng.uniform(-3.20, -3.18, 50)
    lat = rng.uniform(55.94, 55.95, 50)
    x, y = frame.to_local(lon, lat)
    back_lon, back_lat = frame.to_geo(x, y)
    assert np.max(np.abs(back_lon - lon)) < 1e-10 and np.max(np.abs(back_lat - lat)) < 1e-10
    # the south-west corner is the origin (to the centimetre the shift is rounded to)
    x0, y0 = frame.to_local(np.array([-3.20]), np.array([55.94]))
    assert 0.0 <= x0[0] < 0.011 and 0.0 <= y0[0] < 0.011
    _, _, true = Geod(ellps="WGS84").inv(lon[:-1], lat[:-1], lon[1:], lat[1:])
    local = np.hypot(np.diff(x), np.diff(y))
    assert np.max(np.abs(local / true - 1.0)) < 1e-5  # MAX_SCALE_ERROR, with room
    # grid north is true north on the central meridian: a point due north has the same x
    n = frame.to_local(np.array([frame.longitude] * 2), np.array([55.94, 55.95]))
    assert abs(n[0][1] - n[0][0]) < 1e-6


def test_the_site_file_becomes_the_scenario(tmp_path: Path) -> None:
    scenario = load_scenario(str(SITE))
    assert scenario.world.frame is not None and scenario.world.area == str(SITE.resolve())
    # a UAV at 4 m overflies the 3 m pump shed; the hall, the store (3 levels = 9 m) and the
    # 7.5 m office block it
    assert len(scenario.world.obstacles) == 3
    # the ground robot (its sensor at 0.5 m) meets all four
    low = validate_scenario(_with_start_height(tmp_path, 0.5))
    assert len(low.world.obstacles) == 4
    # outside the fence is a no-go zone: the west corner cut off at (0, 60)-(20, 80)
    site = scenario.make_site()
    assert site is not None
    assert site.is_blocked(np.array([[2.0, 75.0]]))[0]
    assert not site.is_blocked(np.array([[30.0, 30.0]]))[0]
    # the release Point's rate and wind
    assert scenario.truth.q == 5.0 and scenario.truth.u == 4.0
    assert math.isclose(scenario.truth.phi, (90.0 - 250.0) % 360.0)


def _with_start_height(tmp_path: Path, height: float) -> dict:
    from dcee.scenarios.geo_area import area_configuration

    text = json.loads(SITE.read_text())
    for f in text["features"]:
        if f["properties"].get("dcee") == "start":
            f["properties"]["height"] = height
    path = tmp_path / "low.geojson"
    path.write_text(json.dumps(text))
    out = area_configuration(path)
    # the release at 4 m is off a ground robot's plane: the paper's plume, not the site's
    # default (the fluid solver's planar plume, its source in the plane the robot reads)
    out["truth"]["model"] = "isotropic"
    return out


def _search(args: list[str], tmp_path: Path, name: str, capsys) -> Path:
    out = tmp_path / name
    code, _, err = run_cli(
        [
            "run", *args, "--strategy", "infotaxis", "--particles", "1000", "--hypotheses",
            "8", "--budget", "40", "--out", str(out), "-q", "--no-figure",
            # the geography, not the gas: the paper's plume as the truth and the estimator's (the
            # site's defaults, the solver's plume and the wall-aware one, cost minutes)
            "--truth", "isotropic", "--set", "estimator.plume=open",
        ],
        capsys,
    )  # fmt: skip
    assert code == 0, err
    return out


@pytest.mark.parametrize("site", [SITE, REAL_SITE], ids=["constructed", "openstreetmap"])
def test_estimate_geojson_is_rfc7946_and_its_point_round_trips(
    site: Path, tmp_path: Path, capsys
) -> None:
    import geojson

    out = _search(["--area", str(site)], tmp_path, "geo", capsys)
    doc = json.loads((out / "estimate.geojson").read_text())
    checked = geojson.loads(json.dumps(doc))
    assert checked.is_valid, checked.errors()
    assert "crs" not in doc  # RFC 7946 has none: WGS 84 only
    kinds = [f["properties"]["kind"] for f in doc["features"]]
    assert kinds[:3] == ["estimate", "region_95", "path"] and kinds.count("reading") >= 10
    ring = np.array(doc["features"][1]["geometry"]["coordinates"][0])
    assert np.array_equal(ring[0], ring[-1])
    signed = np.sum(ring[:-1, 0] * ring[1:, 1] - ring[1:, 0] * ring[:-1, 1])
    assert signed > 0  # exterior ring counter-clockwise (RFC 7946 3.1.6)
    for f in doc["features"]:
        pts = np.array(f["geometry"]["coordinates"], dtype=float).reshape(-1, 2)
        assert np.all(np.abs(pts[:, 0]) <= 180) and np.all(np.abs(pts[:, 1]) <= 90)
    summary = json.loads((out / "summary.json").read_text())
    assert "scale error at most" in summary["final_mean_geo"]["frame_description"]
    frame = LocalFrame(
        **json.loads((out / "config.json").read_text())["scenario"]["world"]["frame"]
    )
    lon, lat = doc["features"][0]["geometry"]["coordinates"]
    x, y = frame.to_local(np.array([lon]), np.array([lat]))
    assert math.hypot(x[0] - summary["final_mean"][0], y[0] - summary["final_mean"][1]) < 1.0
    assert math.hypot(x[0] - summary["final_mean"][0], y[0] - summary["final_mean"][1]) < 0.01
    code, _, err = run_cli(["report", str(out), "--out", str(tmp_path / "report")], capsys)
    assert code == 0, err
    table = (tmp_path / "report" / "map_estimates.md").read_text()
    assert f"{summary['final_mean_geo']['latitude']:.7f}" in table
    assert "estimates on the map" in (tmp_path / "report" / "report.html").read_text()
    kml = (out / "estimate.kml").read_text()
    assert kml.startswith("<?xml") and "<Polygon>" in kml and "<LineString>" in kml
    import xml.etree.ElementTree as ET

    ET.fromstring(kml)  # well-formed


def test_the_same_search_in_geographic_and_local_coordinates(tmp_path: Path, capsys) -> None:
    geo = load_scenario(str(SITE))
    local = copy.deepcopy(geo.model_dump())
    local["world"].pop("frame")
    local["world"].pop("area")
    local["name"] = "local"
    path = tmp_path / "local.toml"
    _write_toml(local, path)
    a = _search(["--scenario", str(SITE)], tmp_path, "a", capsys)
    b = _search(["--scenario", str(path)], tmp_path, "b", capsys)
    import pandas as pd

    ra, rb = pd.read_parquet(a / "steps.parquet"), pd.read_parquet(b / "steps.parquet")
    cols = ["time", "x", "y", "z", "reading", "mean_x", "mean_y", "mean_z"]
    pd.testing.assert_frame_equal(ra[cols], rb[cols])
    assert (a / "estimate.geojson").exists() and not (b / "estimate.geojson").exists()


def _write_toml(data: dict, path: Path) -> None:
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{k} = {value(x)}" for k, x in v.items() if x is not None) + "}"
        return repr(float(v)) if isinstance(v, float) else str(v)

    lines = [f"{k} = {value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, v in data.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            lines += [f"{kk} = {value(x)}" for kk, x in v.items() if x is not None]
    path.write_text("\n".join(lines) + "\n")


def _edited(tmp_path: Path, edit) -> Path:
    doc = json.loads(SITE.read_text())
    edit(doc)
    path = tmp_path / "bad.geojson"
    path.write_text(json.dumps(doc))
    return path


def _feature(doc: dict, name: str) -> dict:
    return next(f for f in doc["features"] if f["properties"].get("name") == name)


def _open_ring(doc: dict) -> None:
    _feature(doc, "Hall A")["geometry"]["coordinates"][0].pop()


def _crossing_ring(doc: dict) -> None:
    ring = _feature(doc, "Hall A")["geometry"]["coordinates"][0]
    ring[1], ring[2] = ring[2], ring[1]  # a bow tie


def _swapped_start(doc: dict) -> None:
    start = _feature(doc, "gate")["geometry"]
    start["coordinates"] = start["coordinates"][::-1]


def _swapped_position(doc: dict) -> None:
    # a site at 121.5° E, 31.2° N written [latitude, longitude]: its "latitude" is 121.5
    ring = _feature(doc, "site fence")["geometry"]["coordinates"][0]
    ring[0] = ring[-1] = [31.2, 121.5]


def _projected(doc: dict) -> None:
    for f in doc["features"]:
        g = f["geometry"]
        if g["type"] == "Point":
            g["coordinates"] = [545000.0, 258000.0]


def _start_in_building(doc: dict) -> None:
    hall = _feature(doc, "Hall A")["geometry"]["coordinates"][0]
    centre = np.mean(np.array(hall[:-1]), axis=0).tolist()
    _feature(doc, "gate")["geometry"]["coordinates"] = centre


def _start_outside(doc: dict) -> None:
    lon, lat = _feature(doc, "gate")["geometry"]["coordinates"]
    _feature(doc, "gate")["geometry"]["coordinates"] = [lon - 0.001, lat]


def _too_large(doc: dict) -> None:
    ring = _feature(doc, "site fence")["geometry"]["coordinates"][0]
    ring[1][0] += 1.0  # one corner 68 km east


def _levels_range(doc: dict) -> None:
    _feature(doc, "Store B")["properties"]["building:levels"] = "3;4"  # OSM's multiple values


def _height_in_feet(doc: dict) -> None:
    _feature(doc, "Hall A")["properties"]["height"] = "40 ft"


@pytest.mark.parametrize(
    ("edit", "field", "words"),
    [
        (_levels_range, "Store B", "building:levels must be a number of storeys"),
        (_height_in_feet, "Hall A", "height must be a number of metres"),
        (_open_ring, "Hall A", "ring not closed"),
        (_crossing_ring, "Hall A", "cross itself"),
        (_swapped_start, "gate", "swapped"),
        (_swapped_position, "site fence", "latitude and longitude swapped"),
        (_projected, "gate", "declare the file's CRS"),
        (_start_in_building, "gate", "inside features"),
        (_start_outside, "gate", "outside the area"),
        (_too_large, "site fence", "one local frame serves at most"),
    ],
)
def test_bad_site_files_are_refused_in_one_line(
    tmp_path: Path,
    capsys,
    edit,
    field: str,
    words: str,
) -> None:
    path = _edited(tmp_path, edit)
    out = tmp_path / "out"
    code, stdout, err = run_cli(["run", "--area", str(path), "--out", str(out), "-q"], capsys)
    assert code == 2, err
    lines = [line for line in err.strip().splitlines() if line.strip()]
    assert len(lines) == 1 and field in lines[0] and words in lines[0], err
    assert "Traceback" not in err and not out.exists() and not stdout


def test_a_declared_crs_gives_the_same_site(tmp_path: Path) -> None:
    """The example site written in UTM zone 31N (EPSG:32631, as GeoJSON 2008's ``crs``
    member names it) is the same scenario to the millimetre."""
    from pyproj import Transformer

    to_utm = Transformer.from_crs("EPSG:4326", "EPSG:32631", always_xy=True)
    doc = json.loads(SITE.read_text())

    def utm(p: list[float]) -> list[float]:
        return list(to_utm.transform(p[0], p[1]))

    for f in doc["features"]:
        g = f["geometry"]
        if g["type"] == "Polygon":
            g["coordinates"] = [[utm(p) for p in ring] for ring in g["coordinates"]]
        elif g["type"] == "Point":
            g["coordinates"] = utm(g["coordinates"])
        elif g["type"] == "LineString":
            g["coordinates"] = [utm(p) for p in g["coordinates"]]
    doc["crs"] = {"type": "name", "properties": {"name": "EPSG:32631"}}
    path = tmp_path / "utm.geojson"
    path.write_text(json.dumps(doc))
    a, b = load_scenario(str(SITE)), load_scenario(str(path))
    assert np.allclose(a.agent.start, b.agent.start, atol=2e-3)
    assert np.allclose(
        [a.truth.x, a.truth.y, a.truth.z], [b.truth.x, b.truth.y, b.truth.z], atol=2e-3
    )
    for sa, sb in zip(a.world.obstacles, b.world.obstacles, strict=True):
        assert np.allclose(sa.points, sb.points, atol=2e-3)


def test_the_site_check_finds_a_position_inside_a_building(tmp_path: Path, capsys) -> None:
    """studies/geo_site_check.py, the check behind the published 'never entered' count, flags
    a path moved into the hall (so its zero can fail)."""
    from studies.geo_site_check import check

    out = _search(["--area", str(SITE)], tmp_path / "campaign", "run", capsys)
    assert all(not r["entered"] for r in check(tmp_path / "campaign")["searches"])
    doc = json.loads((out / "estimate.geojson").read_text())
    hall = np.array(_feature(json.loads(SITE.read_text()), "Hall A")["geometry"]["coordinates"][0])
    path = next(f for f in doc["features"] if f["properties"]["kind"] == "path")
    path["geometry"]["coordinates"][3] = hall[:-1].mean(axis=0).tolist()
    (out / "estimate.geojson").write_text(json.dumps(doc))
    entered = check(tmp_path / "campaign")["searches"][0]["entered"]
    assert "position 3 in features[1] (building 'Hall A')" in entered
    assert any("crosses features[1]" in e for e in entered)


def test_gnss_fixes_become_poses_with_course_and_speed() -> None:
    """dcee.robot.gps: a fix 3 m east then 4 m north of the last, 1 s apart, gives heading 0
    then 90°, speed 3 then 4 m/s; NO_FIX and NaN become poses the cycle drops (not finite), a
    stamp not after the last one it drops as going back; STATUS_UNKNOWN (-2) is a fix."""
    from dcee.robot.gps import NO_FIX, pose_from_fix

    frame = load_scenario(str(SITE)).world.frame.local_frame()

    def fix(t: float, x: float, y: float, last, status: int = 0):
        lon, lat = frame.to_geo(np.array([x]), np.array([y]))
        return pose_from_fix(frame, t, float(lat[0]), float(lon[0]), status, last)

    p0 = fix(1.0, 10.0, 10.0, None)
    p1 = fix(2.0, 13.0, 10.0, p0)
    p2 = fix(3.0, 13.0, 14.0, p1, status=-2)
    assert abs(p0.x - 10.0) < 1e-6 and abs(p2.y - 14.0) < 1e-6 and p0.v == 0.0
    assert abs(p1.heading) < 1e-6 and abs(p1.v - 3.0) < 1e-6
    assert abs(p2.heading - math.pi / 2) < 1e-6 and abs(p2.v - 4.0) < 1e-6
    assert abs(p2.omega - math.pi / 2) < 1e-6
    assert math.isnan(fix(4.0, 50.0, 50.0, p2, status=NO_FIX).x)
    assert not math.isfinite(pose_from_fix(frame, 4.0, math.nan, 0.1, 0, p2).x)
    stale = fix(2.5, 13.0, 20.0, p2)  # not after the last: the cycle drops it as going back
    assert stale.t < p2.t and stale.v == 0.0


def test_a_scenario_file_names_the_area_and_places_start_and_release_in_degrees(
    tmp_path: Path,
) -> None:
    """[world] area (relative to the scenario file) with agent.start_geo and truth.source_geo:
    the same site, the start and release where the degrees put them (the frame's inverse)."""
    (tmp_path / "site.geojson").write_text(SITE.read_text())
    (tmp_path / "s.toml").write_text(
        'name = "my-site"\n[world]\narea = "site.geojson"\n'
        "[agent]\nstart_geo = {latitude = 52.20505, longitude = 0.11815, height = 4.0}\n"
        "step = 2.0\nspeed = 2.0\n"
        "[truth]\nsource_geo = {latitude = 52.2053, longitude = 0.11905, height = 4.0}\n"
        "q = 3.0\nu = 4.0\nwind_from = 250.0\nzeta1 = 1.0\nzeta2 = 8.0\n"
    )
    s = load_scenario(str(tmp_path / "s.toml"))
    frame = s.world.frame.local_frame()
    lon, lat = frame.to_geo(
        np.array([s.agent.start[0], s.truth.x]), np.array([s.agent.start[1], s.truth.y])
    )
    assert np.allclose(lat, [52.20505, 52.2053], atol=1e-7)
    assert np.allclose(lon, [0.11815, 0.11905], atol=1e-7)
    assert s.truth.q == 3.0 and len(s.world.obstacles) == 3
    with pytest.raises(DceeInputError, match=r"agent\.start_geo"):
        load_scenario("paper:1").with_overrides(**{"agent.start_geo": {"latitude": 1.0}})


def test_the_real_site_is_openstreetmap_s_as_mapped() -> None:
    """area:fontvieille: the buildings and no-go zones of the OpenStreetMap extract with their
    ids and tags as mapped (heights from building:levels, 3 m a storey; the incinerator has
    none and so blocks every agent), the attribution the ODbL asks for, and a start and a
    release outside every building."""
    from shapely import Point, Polygon

    from dcee.geo.site_file import read_site

    doc = json.loads(REAL_SITE.read_text())
    assert "OpenStreetMap contributors" in doc["attribution"] and "ODbL" in doc["attribution"]
    mapped = [f for f in doc["features"] if "osm_id" in f["properties"]]
    assert len(mapped) >= 10 and all(f["properties"]["osm_id"].startswith("way/") for f in mapped)
    site = read_site(REAL_SITE)
    heights = {b.footprint.label: b.height for b in site.buildings}
    triton = next(v for k, v in heights.items() if "Le Triton" in k)
    incinerator = next(v for k, v in heights.items() if "Incinérateur SMA" in k)
    assert triton == 30.0 and incinerator is None
    assert sum(h is not None for h in heights.values()) >= 4  # 7-10 storeys
    assert {"cemetery", "construction"} <= {
        f["properties"].get("landuse") for f in doc["features"]
        if f["properties"].get("dcee") == "no-go"
    }  # fmt: skip
    for point in (site.start, site.source):
        p = Point(point.lon, point.lat)
        assert not any(Polygon(b.footprint.ring).contains(p) for b in site.buildings)
