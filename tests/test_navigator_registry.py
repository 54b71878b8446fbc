"""The navigator registry: ``--navigator`` and its options come from the kinds' declarations,
and a new kind is one module plus one entry (no change to ``navseq run``)."""

from __future__ import annotations

import argparse
import importlib
import sys
import types
from pathlib import Path

import pytest

from navseq.cli import build_parser
from navseq.commands import run as run_command
from navseq.errors import NavseqError
from navseq.navigators import registry
from navseq.navigators.registry import NavigatorKind, NavigatorOption, NavigatorSetup
from navseq.navigators.scripted import ScriptedNavigator

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
    assert "ros1 navigator: --action ACTION" in text and "--settle S" in text
    # --action, --frame and --ns are shared: listed once, under ros1.
    assert "nav2 navigator: --server-timeout S" in text
    assert "--use-sim-time auto|true|false" in text
    assert "scripted" not in text
    args = build_parser().parse_args(["run", "m.yaml", "--navigator", "scripted"])
    assert args.navigator == "scripted" and args.scripted_speed == 0.5


def test_every_kind_module_creates_a_navigator() -> None:
    for kind in registry.NAVIGATORS:
        if kind.name == "ros1":
            pytest.importorskip("rospy", reason="ROS 1 not installed")
        if kind.name == "nav2":
            continue  # imports rclpy: never in pytest's process (test_ros2_navigator.py)
        assert callable(importlib.import_module(kind.module).create), kind.name


def _fake_module(made: list[argparse.Namespace]) -> types.ModuleType:
    module = types.ModuleType("navseq_test_fake_kind")

    def create(args: argparse.Namespace, draft: registry.NavigatorDraft) -> NavigatorSetup:
        made.append(args)
        draft.start = draft.start or run_command.parse_pose("-2,-0.5,0")
        return NavigatorSetup(
            make_navigator=lambda: ScriptedNavigator(start=draft.start, speed=args.fake_speed),
            info={"kind": "fake", "speed": args.fake_speed, "frame": args.frame},
            grid=draft.optional_map(),
        )

    module.create = create  # type: ignore[attr-defined]
    return module


def test_a_new_kind_is_one_entry_with_its_options_defaults_and_journal(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    made: list[argparse.Namespace] = []
    monkeypatch.setitem(sys.modules, "navseq_test_fake_kind", _fake_module(made))
    fake = NavigatorKind(
        "fake",
        "a stack made up for this test",
        "navseq_test_fake_kind",
        options=(
            NavigatorOption("--fake-speed", "m/s", 2.0, type=float),
            # Shared with ros1: added once, this kind's default applies to it.
            NavigatorOption("--frame", "goal frame", "odom"),
        ),
    )
    monkeypatch.setattr(registry, "NAVIGATORS", (*registry.NAVIGATORS, fake))
    assert "fake: a stack made up for this test" in run_help()
    parser = build_parser()
    args = parser.parse_args(["run", str(MISSION), "--navigator", "fake", "--out", str(tmp_path)])
    setup = run_command.prepare(args)
    assert made and made[0].fake_speed == 2.0 and made[0].frame == "odom"
    assert setup.navigator_info == {"kind": "fake", "speed": 2.0, "frame": "odom"}
    # What a resume continues with: the kind's journaled options, not another kind's.
    assert {k: setup.run_options[k] for k in ("navigator", "fake_speed", "frame")} == {
        "navigator": "fake",
        "fake_speed": 2.0,
        "frame": "odom",
    }
    assert "settle" not in setup.run_options
    assert run_command.execute(setup, args) == 0


def test_a_kind_whose_module_cannot_load_is_one_clear_error() -> None:
    broken = NavigatorKind(
        "nowhere", "", "navseq_no_such_module_here", requires="the Nowhere client library"
    )
    with pytest.raises(NavseqError, match="the nowhere navigator needs the Nowhere client"):
        broken.create(argparse.Namespace(), None)  # type: ignore[arg-type]


def test_a_journal_naming_an_unknown_navigator_is_refused() -> None:
    with pytest.raises(NavseqError, match="unknown navigator 'nav9'"):
        run_command.apply_run_defaults(argparse.Namespace(navigator="nav9"))
