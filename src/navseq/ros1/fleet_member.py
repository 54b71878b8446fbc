"""One robot of ``navseq run --fleet FLEET --navigator ros1``: its move_base, connected.

The fleet run (:mod:`navseq.fleet.stack_run`) asks this module for each robot's
navigator in the robot's namespace, before anything moves; a namespace no
``move_base`` server answers in is one :class:`~navseq.errors.NavseqError` (said with
the other robots' problems, exit 2). All robots share this process's one rospy node.
The robot's model, map and pre-flight come from the fleet file, not from the stack.
Its frames are ROS 1's multi-robot convention (``launch/multi_robot.launch``, tf_prefix):
``NS/base_footprint`` (or ``NS/base_link``) and ``NS/odom`` on the one ``/tf``, so the
coordinator sees every robot, idle ones too.
"""

from __future__ import annotations

from navseq.navigators.settings import Ros1NavigatorSettings, with_defaults
from navseq.ros1.navigator import Ros1Navigator
from navseq.ros1.run_setup import SERVER_WAIT


def connect(
    settings: Ros1NavigatorSettings, namespace: str, server_wait: float = SERVER_WAIT
) -> tuple[Ros1Navigator, dict[str, object]]:
    """The robot's navigator, its server found; and the report's navigator section."""
    settings = with_defaults(settings)
    assert settings.action is not None and settings.settle is not None
    prefix = f"{namespace.strip('/')}/" if namespace.strip("/") else ""
    navigator = Ros1Navigator(
        settings.action,
        settings.frame,
        namespace=namespace,
        settle=settings.settle,
        base_frames=(f"{prefix}base_footprint", f"{prefix}base_link"),
        odom_frame=f"{prefix}odom",
    )
    try:
        navigator.require_server(server_wait)
    except BaseException:
        navigator.close()
        raise
    info: dict[str, object] = {
        "kind": "ros1",
        "action": navigator.resolved_action,
        "frame": settings.frame,
        "ns": namespace,
    }
    return navigator, info


__all__ = ["connect"]
