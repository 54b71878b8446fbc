"""Pre-flight for a retry's recoveries: each one the chosen navigator cannot run is a
problem naming where the mission asks for it (file:line), found before anything moves."""

from __future__ import annotations

from collections.abc import Collection, Iterator

from navseq.errors import NavseqError
from navseq.mission.model import Mission
from navseq.mission.recovery import Recovery


def recovery_problems(
    mission: Mission, navigator: str, supported: Collection[str]
) -> list[NavseqError]:
    """One problem per recovery of ``mission`` whose kind ``navigator`` cannot run."""
    problems: list[NavseqError] = []
    can = ", ".join(sorted(supported)) or "none"
    for where, owner, number, recovery in _every_recovery(mission):
        if recovery.kind not in supported:
            problems.append(
                NavseqError(
                    f"the {navigator} navigator cannot run the recovery {recovery.describe()}"
                    f" (it runs {can}); take it out of recovery:, or run on another navigator",
                    source=where,
                    subject=f"{owner}, recovery {number}",
                )
            )
    return problems


def _every_recovery(mission: Mission) -> Iterator[tuple[str, str, int, Recovery]]:
    """Each recovery once: the defaults' list (if a waypoint uses it), then each
    waypoint's own list."""
    defaults_used = any("recoveries" not in w.overrides for w in mission.waypoints)
    if defaults_used:
        for number, recovery in enumerate(mission.defaults.recoveries, 1):
            yield mission.source, "defaults", number, recovery
    for index, waypoint in enumerate(mission.waypoints):
        for number, recovery in enumerate(waypoint.overrides.get("recoveries", ()), 1):
            yield waypoint.where or mission.source, mission.waypoint_label(index), number, recovery


__all__ = ["recovery_problems"]
