"""The embedded simulator made ready for one mission: start pose, pre-flight, world.

``navseq run`` (the CLI) and :func:`navseq.simulate` (the Python API) both call
:func:`prepare_sim_world`, so the rules live once: the simulator's default start pose
when none is given, one costmap for pre-flight and the simulated navigation server
alike, and pre-flight before the world is built (it lists every problem at once,
where building the world would stop at the first, a start inside an obstacle).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from navseq.errors import MissionErrors

if TYPE_CHECKING:
    from collections.abc import Sequence

    from navseq.geometry import Pose2D
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.sim.occupancy import OccupancyGrid
    from navseq.sim.world import SimWorld


@dataclass(frozen=True)
class SimReady:
    """A simulated world for a mission, and where its robot starts."""

    world: SimWorld
    start: Pose2D
    start_defaulted: bool  # True: no start was given, the simulator chose ``start``


def prepare_sim_world(
    mission: Mission,
    grid: OccupancyGrid,
    start: Pose2D | None,
    robot: RobotProfile,
    *,
    preflight: bool = True,
    numbers: Sequence[int] | None = None,
) -> SimReady:
    """The simulated world for ``mission`` on ``grid`` with ``robot``.

    ``start`` None puts the robot at the roomy point nearest the map origin. With
    ``preflight``, every waypoint is checked against the costmap first and all problems
    are raised together as :class:`~navseq.errors.MissionErrors`, naming waypoints by
    ``numbers`` (their numbers in the file, when ``mission`` is a part of it).
    """
    from navseq.preflight import check_mission
    from navseq.sim.costmap import Costmap
    from navseq.sim.profile import SimSettings
    from navseq.sim.world import SimWorld, default_start

    settings = SimSettings.of(robot)
    defaulted = start is None
    if start is None:
        start = default_start(grid, settings.footprint)
    costmap = Costmap.from_grid(grid, settings.costmap_params)
    if preflight:
        problems = check_mission(mission, costmap, start, numbers=numbers, robot=robot)
        if problems:
            raise MissionErrors(problems)
    world = SimWorld(
        grid,
        start,
        costmap=costmap,
        nav_params=settings.nav_params,
        footprint=settings.footprint,
    )
    return SimReady(world, start, defaulted)
