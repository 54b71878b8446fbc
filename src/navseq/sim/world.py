"""One simulated robot with its navigation server on a map, and the clock that drives them.

Each :meth:`SimWorld.step` advances simulated time by ``dt``: the navigation server turns
the robot's pose and velocity into a command, and the robot body (the same
:class:`navseq.sim.base.SimulatedBase` the ROS sim robot node wraps) carries it out
unless its footprint would then overlap an obstacle. In that case the body refuses the
move and halts, like a bumper stop, and ``collisions`` counts it — with a correct server the
count stays zero, because the server aborts before a collision becomes unavoidable.

The world holds one robot. Other robots, moved by the caller, are made known to the
body and the server alike with :meth:`SimWorld.set_other_robots`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.sim.base import SimulatedBase
from navseq.sim.costmap import Costmap, CostmapParams
from navseq.sim.footprint import (
    TURTLEBOT3_BURGER,
    Footprint,
    clearance_map,
)
from navseq.sim.navserver import NavigationServer, NavParams, NavState
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.robot import DiffDriveRobot


class SimWorld:
    """A map, a robot on it, its :class:`NavigationServer`, and simulated ``time`` (s).

    The server's costmap is built from ``grid`` with ``costmap_params``, unless the
    caller passes one already built on this very ``grid`` as ``costmap`` (inflating a
    large map takes a while; the CLI's pre-flight check has one ready). A caller with
    its own kind of server (a fleet's, :mod:`navseq.sim.fleet_world`) passes it built on
    that costmap as ``server``; ``nav_params`` and ``footprint`` are then the server's.
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        start: Pose2D,
        *,
        dt: float = 0.05,
        costmap_params: CostmapParams | None = None,
        nav_params: NavParams | None = None,
        footprint: Footprint = TURTLEBOT3_BURGER,
        costmap: Costmap | None = None,
        server: NavigationServer | None = None,
    ) -> None:
        if not dt > 0:
            raise ValueError(f"dt must be positive, got {dt}")
        if costmap is not None:
            # Grids compare by identity; a costmap of another grid would let the server
            # plan on one map while the body collides on another.
            if costmap.grid is not grid:
                raise ValueError("costmap was built on another grid than the world's")
            if costmap_params is not None and costmap_params != costmap.params:
                raise ValueError("costmap_params differ from the given costmap's params")
        self.grid = grid
        self.dt = dt
        self.footprint = footprint
        self.costmap = costmap if costmap is not None else Costmap.from_grid(grid, costmap_params)
        if server is not None and server.costmap is not self.costmap:
            raise ValueError("server was built on another costmap than the world's")
        self.server = (
            server if server is not None else NavigationServer(self.costmap, nav_params, footprint)
        )
        # A command arrives every step, so the body's command timeout (two steps, against
        # rounding) never applies.
        self.body = SimulatedBase(
            start,
            grid,
            footprint=footprint,
            limits=self.server.params.limits,
            cmd_vel_timeout=2 * dt,
        )
        if self.body.collides(start):
            raise self._collision_error(start, "start")
        self.time = 0.0
        self.steps = 0

    @property
    def robot(self) -> DiffDriveRobot:
        """The robot's kinematic state: pose (map frame) and velocities."""
        return self.body.robot

    @property
    def collisions(self) -> int:
        """Moves the body refused because the footprint would have touched something."""
        return self.body.refused_steps

    def step(self) -> None:
        """Advance one ``dt``: the server commands, the robot moves unless it would collide."""
        self.drive(*self.controller_command())

    def controller_command(self, believed: Pose2D | None = None) -> tuple[float, float]:
        """The server's command for this step, steering from ``believed`` (where a
        localiser puts the robot; None: its true pose)."""
        robot = self.robot
        pose = robot.pose if believed is None else believed
        return self.server.compute_velocity(pose, robot.v, robot.w, self.dt)

    def drive(self, cmd_v: float, cmd_w: float) -> None:
        """Advance one ``dt`` with the command ``(cmd_v, cmd_w)`` given to the body."""
        robot = self.robot
        self.steps += 1
        self.time = self.steps * self.dt  # no drift from adding dt thousands of times
        if cmd_v == 0.0 and cmd_w == 0.0 and robot.v == 0.0 and robot.w == 0.0:
            return  # at rest and told to stay: nothing can change
        self.body.command(cmd_v, cmd_w)
        self.body.step(self.dt)

    def step_commanded(self, v: float, w: float) -> None:
        """Advance one ``dt`` with the robot commanded from outside (a behaviour such as a
        recovery's spin), not by the navigation server; it still never enters a wall."""
        self.steps += 1
        self.time = self.steps * self.dt
        self.body.command(v, w)
        self.body.step(self.dt)

    def set_other_robots(
        self,
        others: Sequence[tuple[Pose2D, Footprint]],
        nearby: Sequence[tuple[Pose2D, Footprint]] | None = None,
    ) -> None:
        """Other robots (poses in the map frame, footprints) for the body and the server.

        The world does not move them: the caller sets them again whenever they move.
        ``nearby``: those of them this robot could touch within the next step or its
        braking (a fleet's broad phase); only they get the exact collision tests.
        """
        near = others if nearby is None else nearby
        self.body.set_other_robots(near)
        self.server.set_other_robots(others, near)

    def run(self, seconds: float) -> None:
        """Step for ``seconds`` of simulated time."""
        for _ in range(round(seconds / self.dt)):
            self.step()

    def replace_map(self, grid: OccupancyGrid) -> None:
        """A new map (``map_server/load_map``): the body collides with it, the server
        plans on its costmap (same parameters) and re-plans an active goal. The robot
        stays where it is, as on a real robot whose map changed."""
        self.grid = grid
        self.costmap = Costmap.from_grid(grid, self.costmap.params)
        self.body.grid = grid
        self.server.use_map(self.costmap)

    def teleport(self, pose: Pose2D) -> None:
        """Move the robot to ``pose`` at rest (the server keeps its goal and replans)."""
        if not self.body.teleport(pose):
            raise self._collision_error(pose, "pose")
        server = self.server
        if server.state is NavState.ACTIVE and server.goal is not None:
            server.set_goal(server.goal)  # replan from the new place

    def _collision_error(self, pose: Pose2D, what: str) -> NavseqError:
        return NavseqError(
            f"the robot at ({pose.x:.2f}, {pose.y:.2f}) would overlap an obstacle, "
            "unknown space, the map edge or another robot",
            source=self.grid.source,
            subject=what,
        )


def default_start(grid: OccupancyGrid, footprint: Footprint = TURTLEBOT3_BURGER) -> Pose2D:
    """A start pose when the user gave none: the roomy point nearest the map frame's origin.

    "Roomy" means at least twice the footprint's circumscribed radius from any obstacle
    or unknown cell, so the robot can turn freely; the pose faces +x. Falls back to the
    freest cell of the map when no cell is that roomy.
    """
    clearance = clearance_map(grid)
    roomy = clearance >= 2.0 * footprint.circumscribed_radius
    rows, cols = np.nonzero(roomy)
    if rows.size == 0:
        row, col = np.unravel_index(int(np.argmax(clearance)), clearance.shape)
        x, y = grid.cell_to_world(int(row), int(col))
        return Pose2D(x, y, 0.0)
    centres = grid.cells_to_world(rows, cols)
    nearest = int(np.argmin(np.hypot(centres[:, 0], centres[:, 1])))
    return Pose2D(float(centres[nearest, 0]), float(centres[nearest, 1]), 0.0)
