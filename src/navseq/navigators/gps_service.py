"""GPS waypoints converted by the running stack: robot_localization's ``fromLL``.

With ``--navigator nav2 --from-ll SERVICE`` the waypoints a mission gives as latitude /
longitude are converted by the stack's own navsat_transform (its ``fromLL`` service,
``robot_localization/srv/FromLL``) instead of with the mission's datum, so that they
land exactly where the robot's localisation puts them (its datum, its zone, its
yaw offset). Asked once per GPS waypoint, before pre-flight and before the robot moves;
a service that does not answer, or a type that does not load, is one NavseqError.
ROS-free: the call goes through the navigator's ROS port (:mod:`navseq.tasks.ros_port`).
"""

from __future__ import annotations

import threading
from typing import Any

from navseq.errors import NavseqError
from navseq.mission.model import Mission, Waypoint
from navseq.tasks.ros_port import RosPort

FROM_LL_TYPE = "robot_localization/FromLL"


def converted_through_from_ll(
    port: RosPort, service: str, mission: Mission, timeout: float
) -> Mission:
    """``mission`` with every GPS waypoint's x, y (and z) from ``service``'s answer.

    A mission without GPS waypoints comes back as it is. ``timeout``: wall seconds for
    each answer (the first also waits for the service to appear).
    """
    if not any(w.geo is not None for w in mission.waypoints):
        return mission
    waypoints = [
        _converted(port, service, waypoint, timeout) if waypoint.geo is not None else waypoint
        for waypoint in mission.waypoints
    ]
    from dataclasses import replace

    return replace(mission, waypoints=tuple(waypoints))


def _converted(port: RosPort, service: str, waypoint: Waypoint, timeout: float) -> Waypoint:
    geo = waypoint.geo
    assert geo is not None
    answered = threading.Event()
    answer: list[tuple[Any, str | None]] = []

    def on_answer(response: Any, why: str | None) -> None:
        answer.append((response, why))
        answered.set()

    point = {"latitude": geo.latitude, "longitude": geo.longitude}
    if geo.altitude is not None:
        point["altitude"] = geo.altitude
    try:
        stop = port.call(service, FROM_LL_TYPE, {"ll_point": point}, on_answer)
    except ValueError as error:  # the type does not load here
        raise NavseqError(
            f"cannot call {service}: {error}; without --from-ll navseq converts GPS "
            "waypoints with the mission's datum",
            source="--from-ll",
        ) from None
    try:
        if not answered.wait(timeout):
            raise NavseqError(
                f"{service} ({FROM_LL_TYPE}) did not answer within {timeout:g} s: is "
                "navsat_transform running, with its datum set?",
                source="--from-ll",
            )
    finally:
        stop()
    response, why = answer[0]
    if response is None:
        raise NavseqError(f"{service} failed: {why}", source="--from-ll")
    map_point = response.map_point
    return Waypoint(
        float(map_point.x),
        float(map_point.y),
        yaw_rad=waypoint.yaw_rad,
        z=float(map_point.z) if geo.altitude is not None else waypoint.z,
        name=waypoint.name,
        overrides=waypoint.overrides,
        where=waypoint.where,
        geo=geo,
    )


__all__ = ["FROM_LL_TYPE", "converted_through_from_ll"]
