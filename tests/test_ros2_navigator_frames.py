"""The nav2 navigator's robot pose: TF's planar transforms composed without tf2 (no ROS).

The minimal ROS 2 has no tf2 Python library, so the navigator keeps the latest
``/tf`` and ``/tf_static`` transforms in a :class:`navseq.geometry.FrameTree` and
composes ``map -> odom -> base_footprint`` itself.
"""

from __future__ import annotations

import math

import pytest

from navseq.geometry import FrameTree, Pose2D, compose, inverse


def approx(pose: Pose2D | None) -> tuple[float, float, float]:
    assert pose is not None
    return pytest.approx((pose.x, pose.y, pose.yaw), abs=1e-9)


def test_the_robot_in_the_map_is_map_to_odom_then_odom_to_base():
    tree = FrameTree()
    # Localisation has shifted odom 1 m along x and turned it a quarter turn.
    tree.set("map", "odom", Pose2D(1.0, 0.0, math.pi / 2))
    tree.set("odom", "base_footprint", Pose2D(2.0, 0.0, 0.0))  # 2 m ahead in odom
    assert approx(tree.lookup("map", "base_footprint")) == (1.0, 2.0, math.pi / 2)
    assert approx(tree.lookup("odom", "base_footprint")) == (2.0, 0.0, 0.0)
    assert approx(tree.lookup("map", "map")) == (0.0, 0.0, 0.0)


def test_the_latest_transform_wins_and_a_leading_slash_is_the_same_frame():
    tree = FrameTree()
    tree.set("/map", "/odom", Pose2D(0.0, 0.0, 0.0))
    tree.set("odom", "base_footprint", Pose2D(1.0, 1.0, 0.0))
    tree.set("odom", "base_footprint", Pose2D(3.0, -1.0, 0.5))
    assert approx(tree.lookup("map", "/base_footprint")) == (3.0, -1.0, 0.5)
    assert "odom" in tree and "/odom" in tree


def test_static_links_below_the_base_compose_too():
    tree = FrameTree()
    tree.set("map", "odom", Pose2D(-1.0, 2.0, 0.3))
    tree.set("odom", "base_footprint", Pose2D(0.5, 0.25, -1.0))
    tree.set("base_footprint", "base_link", Pose2D(0.0, 0.0, 0.0))
    expected = compose(Pose2D(-1.0, 2.0, 0.3), Pose2D(0.5, 0.25, -1.0))
    assert approx(tree.lookup("map", "base_link")) == (expected.x, expected.y, expected.yaw)
    # Composing a pose with its inverse gets back to the frame itself.
    there = tree.lookup("map", "odom")
    assert there is not None
    assert approx(compose(there, inverse(there))) == (0.0, 0.0, 0.0)


def test_unconnected_frames_and_loops_give_no_pose():
    tree = FrameTree()
    assert tree.lookup("map", "base_footprint") is None  # nothing published yet
    tree.set("odom", "base_footprint", Pose2D(1.0, 0.0, 0.0))
    assert tree.lookup("map", "base_footprint") is None  # no map -> odom (no localiser)
    assert tree.lookup("base_footprint", "odom") is None  # only ancestors are looked up
    tree.set("base_footprint", "odom", Pose2D(0.0, 0.0, 0.0))  # a loop published by mistake
    assert tree.lookup("map", "base_footprint") is None
