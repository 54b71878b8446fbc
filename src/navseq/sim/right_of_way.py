"""Right of way between the robots of a :class:`~navseq.sim.fleet_world.FleetWorld`.

(First cut: the servers only wait for each other; the rule that resolves conflicts
follows.)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from navseq.sim.navserver import NavigationServer

if TYPE_CHECKING:
    from navseq.sim.fleet_world import FleetWorld


class FleetNavigationServer(NavigationServer):
    """A robot's navigation server in a fleet: it can be sent aside without losing its goal."""

    @property
    def giving_way(self) -> bool:
        """True while the robot is out of its goal's way, letting another robot pass."""
        return False


class RightOfWay:
    """Decides, before every fleet step, which robot gives way to which."""

    def __init__(self, fleet: FleetWorld) -> None:
        self.fleet = fleet

    def before_step(self) -> None:
        """Look at the fleet and send robots aside or back to their goals."""
