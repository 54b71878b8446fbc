#!/usr/bin/env python3
"""The other side of a mission's ROS tasks, on ROS 2 (rclpy): ``ros_task_peer.py``'s twin.

The same topics, service and ``--log`` lines; ``{"event": "ready"}`` is logged too, and
"task peer ready" printed, once everything is up.
"""

from __future__ import annotations

import argparse
import json
import signal
import threading
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import Image
from std_msgs.msg import Int32, String
from std_srvs.srv import Trigger

from task_peer_image import IMAGE_FIELDS

PERIOD = 0.1  # s of wall time between two messages of each topic


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", required=True)
    args = parser.parse_args()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("task_peer")
    lock = threading.Lock()
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGINT, lambda *_: stop.set())

    def record(event: str, **fields: object) -> None:
        with lock, open(args.log, "a") as log:
            log.write(json.dumps({"event": event, **fields}) + "\n")

    def ready_check(_request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        record("called")
        response.success, response.message = True, "ready"
        return response

    node.create_service(Trigger, "/ready_check", ready_check)
    node.create_subscription(String, "/beep", lambda m: record("received", data=m.data), 10)
    counter = node.create_publisher(Int32, "/counter", 10)
    camera = node.create_publisher(Image, "/camera/image", 1)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    record("ready")
    print("task peer ready", flush=True)
    count = 0
    image = Image(**{**IMAGE_FIELDS, "data": list(IMAGE_FIELDS["data"])})
    while not stop.is_set():
        counter.publish(Int32(data=count))
        camera.publish(image)
        count += 1
        time.sleep(PERIOD)
    executor.shutdown(timeout_sec=1)


if __name__ == "__main__":
    main()
