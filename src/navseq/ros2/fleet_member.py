"""One robot of ``navseq run --fleet FLEET --navigator nav2``: its Nav2 stack, connected.

The fleet run (:mod:`navseq.fleet.stack_run`) asks this module for each robot's
navigator in the robot's namespace, before anything moves; a namespace no
``navigate_to_pose`` server answers in is one :class:`~navseq.errors.NavseqError`
(said with the other robots' problems, exit 2). The robot's model, map and pre-flight
come from the fleet file, not from the stack.
"""

from __future__ import annotations

from navseq.navigators.settings import Nav2NavigatorSettings, with_defaults
from navseq.ros2.navigator import Nav2Navigator
from navseq.ros2.run_setup import sim_time_setting


def connect(
    settings: Nav2NavigatorSettings, namespace: str
) -> tuple[Nav2Navigator, dict[str, object]]:
    """The robot's navigator, its server found; and the report's navigator section."""
    settings = with_defaults(settings)
    assert settings.action is not None
    navigator = Nav2Navigator(
        settings.action,
        settings.frame,
        namespace=namespace,
        use_sim_time=sim_time_setting(str(settings.use_sim_time)),
    )
    try:
        navigator.require_server(float(settings.server_timeout))
    except BaseException:
        navigator.close()
        raise
    info: dict[str, object] = {
        "kind": "nav2",
        "action": navigator.resolved_action,
        "frame": settings.frame,
        "ns": navigator.namespace,
        "use_sim_time": navigator.uses_sim_time,
    }
    return navigator, info


__all__ = ["connect"]
