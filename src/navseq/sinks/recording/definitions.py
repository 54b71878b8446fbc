"""The message definitions a recording's schemas carry, read from the package's files.

Each file is one type's full definition (its .msg text, then every type it uses under
a ``MSG: package/Type`` line), copied from the ROS 1 and ROS 2 message packages by
``scripts/ros_msg_definitions.py``: a reader (Foxglove, ``ros2 bag``, rosbags) decodes
the messages with exactly the definitions ROS has.
"""

from __future__ import annotations

from importlib import resources
from typing import Literal

Flavour = Literal["ros1", "ros2"]


def message_definition(flavour: Flavour, type_name: str) -> str:
    """The full definition of ``type_name`` (``nav_msgs/Path``) in ROS 1 or ROS 2."""
    files = resources.files("navseq.sinks.recording") / "definitions" / flavour
    return (files / f"{type_name.replace('/', '.')}.msg").read_text(encoding="utf-8")


def events_schema() -> str:
    """The JSON Schema of navseq's event records (docs/schemas/events.schema.json)."""
    files = resources.files("navseq.sinks.recording") / "definitions"
    return (files / "events.schema.json").read_text(encoding="utf-8")


__all__ = ["Flavour", "events_schema", "message_definition"]
