"""Missions inside a ROS parameter tree: a rosparam YAML file or what a launch file sets.

The mission's parameters may sit at the top of the tree or under a node's name
(``move_base_seq: {p_seq: [...], yea_seq: [...]}``). Exactly one namespace may hold
them; other parameters in the tree are ignored.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from navseq.mission.located import Located
from navseq.mission.model import Mission
from navseq.mission.params import WAYPOINT_SOURCES, OpenMission, mission_from_namespace
from navseq.mission.problems import Problems


def find_mission_namespaces(tree: Located, name: str = "/") -> list[tuple[str, Located]]:
    """Every namespace (mapping) that gives waypoints, with its ROS name, outermost first."""
    if not tree.is_mapping:
        return []
    if any(key in tree.value for key in WAYPOINT_SOURCES):
        return [(name, tree)]
    found: list[tuple[str, Located]] = []
    for key, child in tree.value.items():
        found.extend(find_mission_namespaces(child, f"{name.rstrip('/')}/{key}"))
    return found


def mission_from_tree(
    tree: Located,
    source: str,
    base_dir: Path | None,
    problems: Problems,
    *,
    open_mission: OpenMission,
    not_followed: list[str] | None = None,
) -> Mission | None:
    """The one mission in a parameter tree; ``not_followed`` names files navseq skipped,
    ``open_mission`` reads a file a ``mission`` parameter names."""
    namespaces = find_mission_namespaces(tree)
    if not namespaces:
        hint = ""
        if not_followed:
            hint = f" (navseq could not follow: {', '.join(not_followed)})"
        problems.add(f"sets no p_seq/yea_seq, waypoints or mission parameter{hint}", source=source)
        return None
    if len(namespaces) > 1:
        names = ", ".join(name for name, _ in namespaces)
        problems.add(
            f"several namespaces give waypoints ({names}); navseq reads one mission per file",
            source=source,
        )
        return None
    _, namespace = namespaces[0]
    mission = mission_from_namespace(
        namespace, problems, base_dir=base_dir, strict=False, open_mission=open_mission
    )
    return None if mission is None else dataclasses.replace(mission, source=source)
