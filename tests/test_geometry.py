import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from navseq.geometry import (
    Pose2D,
    compose,
    inverse,
    normalize_angle,
    quaternion_to_yaw,
    yaw_degrees_to_quaternion,
    yaw_to_quaternion,
)

# Known values: rotations about z by 0, 90, 180, -90 and 45 degrees.
KNOWN = [
    (0.0, (0.0, 0.0, 0.0, 1.0)),
    (90.0, (0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5))),
    (180.0, (0.0, 0.0, 1.0, 0.0)),
    (-90.0, (0.0, 0.0, -math.sqrt(0.5), math.sqrt(0.5))),
    (45.0, (0.0, 0.0, 0.38268343236508984, 0.9238795325112867)),
]


@pytest.mark.parametrize(("degrees", "quaternion"), KNOWN)
def test_degrees_to_quaternion_matches_known_values(degrees, quaternion):
    got = yaw_degrees_to_quaternion(degrees)
    assert all(abs(a - b) < 1e-9 for a, b in zip(got, quaternion, strict=True))


@pytest.mark.parametrize(("degrees", "quaternion"), KNOWN)
def test_quaternion_to_yaw_matches_known_values(degrees, quaternion):
    yaw = quaternion_to_yaw(*quaternion)
    assert abs(normalize_angle(yaw - math.radians(degrees))) < 1e-9


@given(st.floats(min_value=-10 * math.pi, max_value=10 * math.pi))
def test_round_trip_is_exact_to_1e9(yaw):
    back = quaternion_to_yaw(*yaw_to_quaternion(yaw))
    assert abs(normalize_angle(back - yaw)) < 1e-9


def test_normalize_angle_range():
    assert normalize_angle(math.pi) == pytest.approx(-math.pi)
    assert normalize_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)


def test_compose_places_a_pose_given_in_a_rotated_frame():
    # A frame at (1, 2) turned 90 degrees left: its +x axis is the parent's +y.
    frame = Pose2D(1.0, 2.0, math.pi / 2)
    placed = compose(frame, Pose2D(3.0, 0.5, math.pi / 4))
    assert (placed.x, placed.y, placed.yaw) == pytest.approx((0.5, 5.0, 3 * math.pi / 4))


poses = st.builds(
    Pose2D,
    st.floats(min_value=-100, max_value=100),
    st.floats(min_value=-100, max_value=100),
    st.floats(min_value=-math.pi, max_value=math.pi),
)


@given(poses)
def test_a_pose_composed_with_its_inverse_is_the_identity(pose):
    for result in (compose(pose, inverse(pose)), compose(inverse(pose), pose)):
        assert result.x == pytest.approx(0.0, abs=1e-9)
        assert result.y == pytest.approx(0.0, abs=1e-9)
        assert abs(normalize_angle(result.yaw)) < 1e-9
