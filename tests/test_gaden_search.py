"""A GADEN simulation as the truth of a search (dcee.simulation.gaden) and the room's scenario
built from its folder (dcee.scenarios.gaden_room, ``dcee run --truth DIR``)."""

from __future__ import annotations

import itertools
import json
import math
import shutil
import zlib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from dcee.errors import DceeInputError
from dcee.scenarios import load_scenario
from dcee.simulation import make_truth
from tests.helpers import run_cli

DATA = Path(__file__).resolve().parent / "data" / "gaden"
ROOM = DATA / "empty-room"


def test_the_room_s_scenario_comes_from_its_folder():
    """The area is the box of free cells, the release the files name, the start the free cell
    at the sensor's height farthest from it, the wind (0.4 m/s along +x) blowing from 180°."""
    s = load_scenario(str(ROOM))
    assert s.name == "gaden:empty-room"
    np.testing.assert_allclose(s.volume.low, [0.1, 0.1, 0.0], atol=1e-6)
    np.testing.assert_allclose(s.volume.high, [10.0, 5.9, 2.5], atol=1e-6)
    np.testing.assert_allclose(s.truth_theta()[:3], [2.0, 3.0, 0.5], atol=1e-6)
    assert s.truth.u == pytest.approx(0.4, abs=1e-6)
    assert math.degrees(s.truth_theta()[5]) == pytest.approx(180.0)
    np.testing.assert_allclose(s.agent.start, [9.95, 0.15, 0.5], atol=1e-6)
    assert s.search_dimensions == 3 and s.search.acquired_rmse == 1.0
    # rate: 10 filaments/s × 6.440745e-6 mol × 46.07 g/mol
    assert s.truth.q == pytest.approx(10 * 6.440745e-6 * 46.07, rel=1e-6)


def test_the_room_s_estimator_knows_its_wind_field_unless_told_it_knows_only_its_own(tmp_path):
    """By default the estimator's plume is the room's own (its wind file, walls and doors: the
    source and its rate unknown, K weighed at 0.002, 0.006, 0.02 m²/s); ``unknown = "full"``
    is what a robot alone could know (the open plume, the wind estimated); the room's wind is
    refused where there is no GADEN room, in one line."""
    from dcee.models.plume import IsotropicPlume
    from dcee.models.room_plume import RoomPlume

    s = load_scenario(str(DATA / "empty-room-cfd"))
    assert (s.unknown, s.plume_model, s.wall_wind) == ("source", "walls", "room")
    assert s.unknown_names == ("x", "y", "z", "q")
    assert isinstance(s.make_plume(), RoomPlume)
    members = [dict(v).get("wall_diffusivity", s.wall_diffusivity) for _, v in
               s.reading_model_variants[:3]]  # fmt: skip
    assert members == pytest.approx([0.002, 0.006, 0.02])
    robot = s.with_overrides(unknown="full")
    assert robot.plume_model == "open" and isinstance(robot.make_plume(), IsotropicPlume)
    with pytest.raises(DceeInputError, match="wall_wind"):
        load_scenario("site:wall").with_overrides(**{"estimator.wall_wind": "room"})


def test_dcee_show_says_which_wall_settings_the_reading_model_does_not_read():
    """In the room's own wind the wake wind's viscosity is not read; with the open plume none
    of the wall settings is: ``dcee show`` says so in place of a provenance that would read as
    if it applied; the settings it does read keep theirs."""
    from dcee.scenarios import to_toml

    room = to_toml(load_scenario(str(DATA / "empty-room-cfd")))
    assert '# wall_viscosity = 1.0  (unset; not read with estimator.wall_wind = "room")' in room
    assert '# wall_wind = "room"  (unset: the default for this scenario)' in room
    robot = to_toml(load_scenario(str(DATA / "empty-room-cfd")).with_overrides(unknown="full"))
    for key in ("wall_diffusivity", "wall_wind", "wall_viscosity"):
        line = next(x for x in robot.splitlines() if x.startswith(f"# {key} = "))
        assert line.endswith('(unset; not read with estimator.plume = "open")'), line
    site = to_toml(load_scenario("site:wall"))  # the wake wind: its viscosity is read
    assert "# wall_viscosity = 1.0  (unset: the default for this scenario)" in site


def test_the_truth_reads_gaden_s_ppm_in_grams_per_cubic_metre():
    """At search time t the truth reads the file saved at 60 s + t: GADEN's reference ppm ×
    10⁻⁶ × the air's 40.894633 mol/m³ × ethanol's 46.07 g/mol; past the files' end the
    playback starts again at 60 s."""
    truth = make_truth(load_scenario(str(ROOM)), 0)
    ref = pd.read_csv(ROOM / "reference.csv")
    rows = ref[ref["t_s"] == 150]
    got = truth.field(rows[["x", "y", "z"]].to_numpy(), 90.0)
    want = rows["gaden_ppm"].to_numpy() * 1e-6 * 4.0894633e-5 * 1e6 * 46.07
    np.testing.assert_allclose(got, want, rtol=1e-5)
    assert truth.simulated_time(90.0) == 150.0
    assert truth.simulated_time(240.0) == 300.0
    assert truth.simulated_time(241.0) == 60.0  # 301 s: the loop's first second again
    assert truth.time_step == 1.0


def test_dcee_run_takes_a_gaden_folder_as_its_scenario_and_truth(tmp_path, capsys):
    out = tmp_path / "run"
    code, _, err = run_cli(
        ["run", "--truth", str(ROOM), "--strategy", "dcee", "--out", str(out), "-q",
         "--particles", "500", "--budget", "20", "--set", "search.hypotheses=4", "--no-figure"],
        capsys,
    )  # fmt: skip
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert (
        summary["scenario"] == "gaden:empty-room" and summary["truth_model"] == "gaden:empty-room"
    )
    assert summary["readings"] >= 3


def _run(argv, capsys, tmp_path):
    code, _, err = run_cli([*argv, "--out", str(tmp_path / "x"), "-q"], capsys)
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert not (tmp_path / "x").exists()
    return err


def test_bad_gaden_input_is_one_line_before_any_work(tmp_path, capsys):
    not_gaden = tmp_path / "folder"
    not_gaden.mkdir()
    err = _run(["run", "--truth", str(not_gaden)], capsys, tmp_path)
    assert "is a folder but not a GADEN simulation" in err
    err = _run(["run", "--truth", "filament"], capsys, tmp_path)
    assert "scenario: required" in err
    # a folder whose files are corrupt
    room = tmp_path / "room"
    shutil.copytree(ROOM, room)
    raw = (room / "result" / "iteration_0").read_bytes()
    (room / "result" / "iteration_0").write_bytes(raw[: len(raw) // 2])
    err = _run(["run", "--truth", str(room)], capsys, tmp_path)
    assert "iteration_0: truncated" in err
    # the paper's scenario over the room's files: the release differs
    err = _run(["run", "--scenario", "lab:upwind", "--truth", str(ROOM)], capsys, tmp_path)
    assert "the GADEN files release at (2.0, 3.0, 0.5) m" in err
    # a start outside the room
    err = _run(
        ["run", "--truth", str(ROOM), "--set", "agent.start=[12.0, 1.0, 0.5]"], capsys, tmp_path
    )
    assert "agent.start" in err
    # a start in the wall beside the right-hand door (x 9.9-10.0 m is wall behind the door)
    err = _run(
        ["run", "--truth", str(ROOM), "--set", "agent.start=[9.95, 3.0, 0.5]"], capsys, tmp_path
    )
    assert "agent.start: (9.95, 3.0, 0.5) m lies in a wall or door cell" in err


def test_a_gas_without_a_known_molar_mass_must_be_given_one(tmp_path):
    from dcee.simulation.gaden import gaden_truth

    room = tmp_path / "room"
    shutil.copytree(ROOM, room)
    for path in (room / "result").glob("iteration_*"):
        data = bytearray(zlib.decompress(path.read_bytes()))
        at = 8 + 12 + 24 + 4 + 8 + 5 + 12  # version, counts, corners, cell, "point", position
        data[at : at + 4] = (3).to_bytes(4, "little")
        path.write_bytes(zlib.compress(bytes(data)))
    with pytest.raises(DceeInputError, match="gas type 3; give its molar mass"):
        gaden_truth(room, 60.0, True, None)
    assert gaden_truth(room, 60.0, True, 58.08).grams_per_ppm > 0


def _with_block(room: Path) -> None:
    """Obstacle cells x 5.0-6.0 m, y 1.0-2.0 m at every height (a cabinet) in ``room``'s grid."""
    from dcee.recordings.gaden import read_occupancy

    _, cells = read_occupancy(room / "OccupancyGrid3D.csv")
    cells[52:62, 12:22, :] = 1
    head = (room / "OccupancyGrid3D.csv").read_text().splitlines()[:4]
    body = []
    for k in range(cells.shape[2]):
        body += [" ".join(str(v) for v in cells[i, :, k]) + " " for i in range(cells.shape[0])]
        body.append(";")
    (room / "OccupancyGrid3D.csv").write_text("\n".join(head + body) + "\n")


def test_a_room_with_an_obstacle_gets_its_map_and_no_path_crosses_it(tmp_path, monkeypatch):
    """An obstacle inside the room becomes the scenario's map (the empty samples get none): a
    start in it is refused, and a search started beside it never enters or crosses it."""
    from dcee.runs import run_episode

    monkeypatch.setenv("DCEE_CACHE", str(tmp_path / "cache"))
    assert load_scenario(str(ROOM)).world.map is None
    room = tmp_path / "room"
    shutil.copytree(ROOM, room)
    _with_block(room)
    scenario = load_scenario(str(room))
    assert scenario.world.map is not None and Path(scenario.world.map).exists()
    with pytest.raises(DceeInputError, match=r"agent\.start"):
        scenario.with_overrides(**{"agent.start": [5.5, 1.5, 0.5]})
    flown = scenario.with_overrides(
        **{"agent.start": [7.0, 1.5, 0.5], "search.particles": 500, "search.hypotheses": 4,
           "search.budget": 60.0}
    )  # fmt: skip
    records = run_episode(flown, "dcee", 0).records
    path = np.array([[r["x"], r["y"]] for r in records])
    # every leg sampled every 5 cm stays outside the block
    for a, b in itertools.pairwise(path):
        for f in np.linspace(0.0, 1.0, 21):
            x, y = a + f * (b - a)
            assert not (5.0 <= x <= 6.0 and 1.0 <= y <= 2.0), (a, b)
    assert len(path) > 5
