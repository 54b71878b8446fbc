"""The navigator registry: ``--navigator`` and its options come from the kinds' typed
settings, and a new kind is one module, one settings class and one entry (no change to
``navseq run`` or the run service)."""

from __future__ import annotations

import argparse
import importlib
import sys
import types
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from navseq.cli import build_parser
from navseq.commands import run as run_command
from navseq.errors import NavseqError
from navseq.navigators import registry
from navseq.navigators.registry import NavigatorKind, NavigatorSetup
from navseq.navigators.scripted import ScriptedNavigator
from navseq.navigators.settings import (
    Ros1NavigatorSettings,
    ScriptedNavigatorSettings,
    option,
)
from navseq.run import prepare
from navseq.run.values import pose_from_text

REPO = Path(__file__).resolve().parents[1]
MISSION = REPO / "examples" / "turtlebot3_world.yaml"


def run_help() -> str:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return " ".join(sub.choices["run"].format_help().split())  # unwrapped


def test_navigator_choices_and_option_groups_come_from_the_registry() -> None:
    text = run_help()
    assert "--navigator {sim,ros1,nav2}" in text  # the hidden test double is not offered
    assert "sim: the embedded simulator (default); ros1: move_base over actionlib" in text
    assert "nav2: ROS 2 Nav2's navigate_to_pose over rclpy" in text
    # --action, --frame, --ns and --map-wait are shared: listed once, saying by which kinds.
    assert "ros1 and nav2 navigators: --action ACTION action server name" in text
    assert text.count("--action ACTION") == 2  # the usage line, then its one entry
    assert "--frame FRAME goal frame" in text and text.count("--map-wait S") == 2
    assert "ros1 navigator: --settle S" in text
    assert "nav2 navigator: --server-timeout S" in text
    assert "--use-sim-time auto|true|false" in text
    assert "scripted" not in text
    args = build_parser().parse_args(["run", "m.yaml", "--navigator", "scripted"])
    navigator = run_command.request_of(args).navigator
    assert isinstance(navigator, ScriptedNavigatorSettings) and navigator.scripted_speed == 0.5


def test_every_kind_module_creates_a_navigator() -> None:
    for kind in registry.NAVIGATORS:
        if kind.name == "ros1":
            pytest.importorskip("rospy", reason="ROS 1 not installed")
        if kind.name == "nav2":
            continue  # imports rclpy: never in pytest's process (test_ros2_navigator.py)
        assert callable(importlib.import_module(kind.module).create), kind.name


@dataclass(frozen=True)
class FakeSettings:
    fake_speed: float | None = field(
        default=None, metadata=option("--fake-speed", "m/s", default=2.0, parse=float)
    )
    # Shared with ros1 and nav2: added once, this kind's default applies to it.
    frame: str | None = field(
        default=None, metadata=option("--frame", "goal frame", default="odom")
    )


def _fake_module(made: list[FakeSettings]) -> types.ModuleType:
    module = types.ModuleType("navseq_test_fake_kind")

    def create(settings: FakeSettings, draft: registry.NavigatorDraft) -> NavigatorSetup:
        made.append(settings)
        draft.start = draft.start or pose_from_text("-2,-0.5,0")
        return NavigatorSetup(
            make_navigator=lambda: ScriptedNavigator(start=draft.start, speed=settings.fake_speed),
            info={"kind": "fake", "speed": settings.fake_speed, "frame": settings.frame},
            grid=draft.optional_map(),
        )

    module.create = create  # type: ignore[attr-defined]
    return module


def test_a_new_kind_is_one_entry_with_its_options_defaults_and_journal(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    made: list[FakeSettings] = []
    monkeypatch.setitem(sys.modules, "navseq_test_fake_kind", _fake_module(made))
    fake = NavigatorKind(
        "fake", "a stack made up for this test", "navseq_test_fake_kind", FakeSettings
    )
    monkeypatch.setattr(registry, "NAVIGATORS", (*registry.NAVIGATORS, fake))
    assert "fake: a stack made up for this test" in run_help()
    assert "ros1, nav2 and fake navigators: --frame FRAME" in run_help()
    args = build_parser().parse_args(
        ["run", str(MISSION), "--navigator", "fake", "--out", str(tmp_path)]
    )
    session = prepare(run_command.request_of(args))
    assert made == [FakeSettings(fake_speed=2.0, frame="odom")]
    assert session.navigator_info == {"kind": "fake", "speed": 2.0, "frame": "odom"}
    # What a resume continues with: the kind's journaled settings, not another kind's.
    assert {k: session.run_options[k] for k in ("navigator", "fake_speed", "frame")} == {
        "navigator": "fake",
        "fake_speed": 2.0,
        "frame": "odom",
    }
    assert "settle" not in session.run_options
    assert session.run().exit_status == 0


def test_settings_go_to_their_kind_and_another_kinds_are_refused() -> None:
    ros1 = registry.navigator_kind("ros1")
    assert registry.kind_of(Ros1NavigatorSettings(ns="robot1")) is ros1
    assert ros1.option_defaults() == {
        "action": "move_base",
        "frame": None,
        "ns": "",
        "settle": 0.05,
        "map_wait": 2.0,
    }
    assert ros1.journaled() == ("action", "frame", "ns", "settle")
    with pytest.raises(TypeError, match="ros1 navigator takes Ros1NavigatorSettings"):
        ros1.create(registry.navigator_kind("nav2").settings(), None)  # type: ignore[arg-type]


def test_a_kind_whose_module_cannot_load_is_one_clear_error() -> None:
    broken = NavigatorKind(
        "nowhere", "", "navseq_no_such_module_here", requires="the Nowhere client library"
    )
    with pytest.raises(NavseqError, match="the nowhere navigator needs the Nowhere client"):
        broken.create(broken.settings(), None)  # type: ignore[arg-type]


def test_a_journal_naming_an_unknown_navigator_is_refused() -> None:
    from navseq.run.resume import known_kind

    with pytest.raises(NavseqError, match="unknown navigator 'nav9'"):
        known_kind("nav9")
