import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from navseq.geometry import (
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
