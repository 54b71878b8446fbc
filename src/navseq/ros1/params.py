"""Typed access to a ROS node's private parameters, with errors that name the parameter.

``rospy.get_param`` returns whatever the parameter server holds (roslaunch and ``_x:=``
arguments give numbers, strings or booleans). These helpers turn a wrong type into a
:class:`NavseqError` whose source is the fully resolved parameter name, so a node can
log one clear line and exit instead of failing later with a traceback.
"""

from __future__ import annotations

from collections.abc import Sequence

import rospy

from navseq.errors import NavseqError


def param_error(name: str, message: str) -> NavseqError:
    """A NavseqError about the private parameter ``~name`` (source: its resolved name)."""
    return NavseqError(message, source=f"param {rospy.resolve_name('~' + name)}")


def float_param(name: str, default: float) -> float:
    """``~name`` as a float; anything else is a NavseqError naming the parameter."""
    value = rospy.get_param(f"~{name}", default)
    if isinstance(value, bool):
        raise param_error(name, f"expected a number, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise param_error(name, f"expected a number, got {value!r}") from None


def str_param(name: str, default: str) -> str:
    """``~name`` as a string (numbers are accepted and converted)."""
    return str(rospy.get_param(f"~{name}", default))


def bool_param(name: str, default: bool) -> bool:
    """``~name`` as a boolean (``true``/``false`` strings from roslaunch are accepted)."""
    value = rospy.get_param(f"~{name}", default)
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.lower() in ("true", "false"):
        return value.lower() == "true"
    raise param_error(name, f"expected true or false, got {value!r}")


def str_list_param(name: str, default: Sequence[str]) -> tuple[str, ...]:
    """``~name`` as a list of non-empty strings (a YAML list: ``[a, b]``)."""
    value = rospy.get_param(f"~{name}", list(default))
    if not isinstance(value, list) or not all(
        isinstance(item, str) and item.strip() for item in value
    ):
        hint = (
            f' (a string: in a launch file, <rosparam param="{name}">[a, b]</rosparam> '
            "gives a list)"
            if isinstance(value, str)
            else ""
        )
        raise param_error(name, f"expected a list of non-empty strings, got {value!r}{hint}")
    return tuple(item.strip() for item in value)
