"""The typed settings of each navigator kind, and how each field is offered on a command line.

A kind's settings are a frozen dataclass; each field says, in its metadata
(:func:`setting`), its option flag, help, metavar and whether a run records it in its
journal, so that ``navseq run`` derives its options from the dataclasses alone and a
resume continues with the recorded values. The classes are ROS-free on purpose: any
face (CLI, Python API, studio, a fleet) builds them without the client libraries,
which only the kind's ``create`` module imports.

Each field is ``field(default=..., metadata=option(...))``. A journaled field's default is
None, meaning "not given": the kind's default (``option(default=...)``), or on a resume
the journal's value; :func:`with_defaults` resolves it. Another field's default is its
dataclass default.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Protocol

from navseq.navigators.stack_map import MAP_WAIT

#: The key of a field's :class:`SettingInfo` in its dataclass metadata.
SETTING_KEY = "navseq.setting"


class NavigatorSettings(Protocol):
    """Any kind's settings: a dataclass whose fields were declared with :func:`option` metadata."""

    __dataclass_fields__: ClassVar[dict[str, Any]]


@dataclass(frozen=True)
class SettingInfo:
    """How one settings field is given on a command line and kept for a resume.

    ``default`` is what a journaled field left None resolves to (another field's is
    its dataclass default); ``parse`` turns the
    option's text into the field's value (ValueError when it cannot); ``hidden`` keeps
    the option out of ``--help`` (the test double's).
    """

    flag: str
    help: str
    default: Any = None
    parse: Callable[[str], Any] | None = None
    metavar: str | None = None
    journaled: bool = True
    hidden: bool = False


@dataclass(frozen=True)
class SettingField:
    """One field of a settings class with its :class:`SettingInfo`."""

    name: str
    info: SettingInfo


def option(
    flag: str,
    help: str,
    *,
    default: Any = None,
    parse: Callable[[str], Any] | None = None,
    metavar: str | None = None,
    journaled: bool = True,
    hidden: bool = False,
) -> dict[str, SettingInfo]:
    """A settings field's metadata: its option (see :class:`SettingInfo`)."""
    return {SETTING_KEY: SettingInfo(flag, help, default, parse, metavar, journaled, hidden)}


def setting_fields(settings_type: type[Any]) -> Iterator[SettingField]:
    """The declared fields of a settings class, in declaration order."""
    for item in dataclasses.fields(settings_type):
        info = item.metadata.get(SETTING_KEY)
        if isinstance(info, SettingInfo):
            if not info.journaled:
                info = dataclasses.replace(info, default=item.default)
            yield SettingField(item.name, info)


def with_defaults(settings: Any) -> Any:
    """``settings`` with every journaled field left None set to its default."""
    filled = {
        field.name: field.info.default
        for field in setting_fields(type(settings))
        if field.info.journaled and getattr(settings, field.name) is None
    }
    return dataclasses.replace(settings, **filled) if filled else settings


# -- the options several kinds share: one declaration, one help -------------------------

_ACTION_HELP = "action server name (default: move_base with ros1, navigate_to_pose with nav2)"
_FRAME_HELP = "goal frame (default: the mission's frame:, usually map)"
_NS_HELP = "robot namespace, e.g. robot1 (default: none)"
_MAP_WAIT_HELP = (
    "without --map (or the mission's map:), pre-flight checks the waypoints on the stack's "
    "own map (NS/map, else /map) and the picture is drawn on it: wall seconds to wait for "
    f"it; none by then: pre-flight is skipped, said on stderr. 0: do not read it "
    f"(default {MAP_WAIT:g})"
)


_FRAME = option("--frame", _FRAME_HELP)
_NAMESPACE = option("--ns", _NS_HELP, default="")
_MAP_WAIT = option("--map-wait", _MAP_WAIT_HELP, parse=float, metavar="S", journaled=False)


@dataclass(frozen=True)
class SimNavigatorSettings:
    """The embedded simulator needs nothing beyond the run's map, start and pace."""


@dataclass(frozen=True)
class Ros1NavigatorSettings:
    """move_base over actionlib (``--navigator ros1``)."""

    action: str | None = field(
        default=None, metadata=option("--action", _ACTION_HELP, default="move_base")
    )
    frame: str | None = field(default=None, metadata=_FRAME)
    ns: str | None = field(default=None, metadata=_NAMESPACE)
    settle: float | None = field(
        default=None,
        metadata=option(
            "--settle",
            "wall seconds between a goal's result and the next goal, meant against "
            "move_base's SUCCEEDED race (navigation #949) but not shown to help: the "
            "arrival check catches the race; 0: off (default 0.05)",
            default=0.05,
            parse=float,
            metavar="S",
        ),
    )
    map_wait: float = field(default=MAP_WAIT, metadata=_MAP_WAIT)


@dataclass(frozen=True)
class Nav2NavigatorSettings:
    """Nav2's navigate_to_pose over rclpy (``--navigator nav2``)."""

    action: str | None = field(
        default=None, metadata=option("--action", _ACTION_HELP, default="navigate_to_pose")
    )
    frame: str | None = field(default=None, metadata=_FRAME)
    ns: str | None = field(default=None, metadata=_NAMESPACE)
    server_timeout: float = field(
        default=30.0,
        metadata=option(
            "--server-timeout",
            "wall seconds to wait for the navigate_to_pose server before giving up (exit 2, "
            "nothing moved; default 30). The mission's server_timeout: is how long to wait "
            "for a server that vanishes during the run",
            parse=float,
            metavar="S",
            journaled=False,
        ),
    )
    use_sim_time: str | None = field(
        default=None,
        metadata=option(
            "--use-sim-time",
            "auto, true or false: run on ROS time from /clock (auto: when /clock is "
            "published; default auto)",
            default="auto",
            metavar="auto|true|false",
        ),
    )
    map_wait: float = field(default=MAP_WAIT, metadata=_MAP_WAIT)
    from_ll: str | None = field(
        default=None,
        metadata=option(
            "--from-ll",
            "convert the mission's GPS waypoints through this service of the running "
            "stack (robot_localization's navsat_transform fromLL, e.g. fromLL) instead of "
            "with the mission's datum",
            metavar="SERVICE",
        ),
    )


def _hidden(flag: str, parse: Callable[[str], Any] | None) -> dict[str, SettingInfo]:
    return option(flag, "", parse=parse, journaled=False, hidden=True)


@dataclass(frozen=True)
class ScriptedNavigatorSettings:
    """The deterministic test double (``--navigator scripted``, hidden)."""

    scripted_speed: float = field(default=0.5, metadata=_hidden("--scripted-speed", float))
    scripted_realtime: float | None = field(
        default=None, metadata=_hidden("--scripted-realtime", float)
    )
    scripted_log: Path | None = field(default=None, metadata=_hidden("--scripted-log", Path))
    scripted_script: str = field(default="", metadata=_hidden("--scripted-script", None))


__all__ = [
    "Nav2NavigatorSettings",
    "NavigatorSettings",
    "Ros1NavigatorSettings",
    "ScriptedNavigatorSettings",
    "SettingField",
    "SettingInfo",
    "SimNavigatorSettings",
    "option",
    "setting_fields",
    "with_defaults",
]
