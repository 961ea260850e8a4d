"""The gas round a robot's map (issue 44): an occupancy grid from the robot (the ROS node's
``map`` topic) makes the estimator's gas flow round its walls.

A robot's map is its site: the drive already keeps clear of the occupied and unknown cells
(:func:`dcee.ros.messages.site_from_map`). With :func:`scenario_with_map_gas` the estimator's
dispersion model follows the same walls: the grid is written as a ROS map file (occupied and
unknown cells as walls) and becomes the scenario's ``world.map`` under the wall-aware plume
(``estimator.plume = "walls"``, :mod:`dcee.models.site_plume`). Where the scenario cannot take
the wall-aware plume (a wind or ζ to estimate, several releases, cells too coarse for a
street, ...) the scenario is kept as it was and the one-line reason returned, so that the robot
searches on with the open-terrain gas and says why.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from dcee.errors import DceeInputError
from dcee.models.ros_map import write_ros_map
from dcee.models.site import SiteMap
from dcee.scenarios import Scenario


def scenario_with_map_gas(scenario: Scenario, grid: SiteMap, path: Path) -> tuple[Scenario, str]:
    """``scenario`` with ``grid`` (the robot's map; occupied and unknown cells blocked) written to
    ``path`` (a ``.yaml`` beside its ``.pgm``) as its ``world.map`` and the wall-aware plume, and
    a line for the log; or, where that cannot be, ``scenario`` unchanged and the reason."""
    write_ros_map(grid, path)
    try:
        walled = scenario.with_overrides(
            **{"world.map": str(Path(path).resolve()), "estimator.plume": "walls"}
        )
    except DceeInputError as exc:
        return scenario, f"the estimator's gas stays in open terrain: {exc}"
    return walled, f"the estimator's gas flows round the map's walls ({grid.name})"


class MapGas:
    """The robot's latest map for the gas (:attr:`grid`, None until one arrives) and the files
    it is written to (a temporary folder, one file per map)."""

    def __init__(self) -> None:
        self.grid: SiteMap | None = None
        self.maps = 0
        self._folder: Path | None = None

    def update(self, grid: SiteMap) -> None:
        self.grid, self.maps = grid, self.maps + 1

    def scenario(self, scenario: Scenario, enabled: bool) -> tuple[Scenario, str | None]:
        """The scenario of a new search: with a map and ``enabled``, the gas round its walls
        (:func:`scenario_with_map_gas`); and the line to log (None: nothing to say)."""
        if self.grid is None or not enabled:
            return scenario, None
        if self._folder is None:
            self._folder = Path(tempfile.mkdtemp(prefix="dcee-map-"))
        return scenario_with_map_gas(scenario, self.grid, self._folder / f"map-{self.maps}.yaml")


__all__ = ["MapGas", "scenario_with_map_gas"]
