"""Typed access to a ROS node's private parameters, with errors that name the parameter.

``rospy.get_param`` returns whatever the parameter server holds (roslaunch and ``_x:=``
arguments give numbers, strings or booleans). These helpers turn a wrong type into a
:class:`NavseqError` whose source is the fully resolved parameter name, so a node can
log one clear line and exit instead of failing later with a traceback.
"""

from __future__ import annotations

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
