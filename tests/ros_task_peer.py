#!/usr/bin/env python3
"""The other side of a mission's ROS tasks, on ROS 1 (rospy): what a robot would offer.

- ``/counter`` (``std_msgs/Int32``): 0, 1, 2 ... every :data:`PERIOD` s, for ``wait_for``;
- ``/camera/image`` (``sensor_msgs/Image``): :data:`IMAGE` every period, for ``snapshot``;
- ``/ready_check`` (``std_srvs/Trigger``): answers success, message "ready", for ``call``;
- ``/beep`` (``std_msgs/String``): subscribed, for ``publish``.

Every call and every message received is a JSON line in ``--log`` (``{"event":
"called"}``, ``{"event": "received", "data": ...}``); "task peer ready" goes to stdout
once everything is up. ``ros2_task_peer.py`` is its ROS 2 twin; ``task_peer_image`` is
the picture both publish.
"""

from __future__ import annotations

import argparse
import json
import threading
import time

import rospy
from sensor_msgs.msg import Image
from std_msgs.msg import Int32, String
from std_srvs.srv import Trigger, TriggerResponse

from task_peer_image import IMAGE_FIELDS

PERIOD = 0.1  # s of wall time between two messages of each topic


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", required=True)
    args = parser.parse_args()
    rospy.init_node("task_peer")
    lock = threading.Lock()

    def record(event: str, **fields: object) -> None:
        with lock, open(args.log, "a") as log:
            log.write(json.dumps({"event": event, **fields}) + "\n")

    def ready_check(_request: object) -> TriggerResponse:
        record("called")
        return TriggerResponse(success=True, message="ready")

    rospy.Service("/ready_check", Trigger, ready_check)
    rospy.Subscriber("/beep", String, lambda message: record("received", data=message.data))
    counter = rospy.Publisher("/counter", Int32, queue_size=10)
    camera = rospy.Publisher("/camera/image", Image, queue_size=1)
    print("task peer ready", flush=True)
    count = 0
    while not rospy.is_shutdown():
        counter.publish(Int32(data=count))
        camera.publish(Image(**IMAGE_FIELDS))
        count += 1
        time.sleep(PERIOD)


if __name__ == "__main__":
    main()
