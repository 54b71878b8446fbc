"""GPS waypoints: latitude/longitude through the mission's datum to the map frame, as
robot_localization's navsat_transform puts them, checked against known UTM figures."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import pytest

from cli_support import EXAMPLES, assert_clean_error, navseq
from navseq.errors import MissionErrors, NavseqError
from navseq.mission.geodesy import Datum, GeoPoint, utm_zone
from navseq.mission.loader import load_mission
from navseq.mission.writer import dump_mission_yaml
from navseq.navigators.gps_service import converted_through_from_ll
from navseq.sim.options import datum_of

# Wikipedia's UTM example: the CN Tower, 43.642567 N 79.387139 W, is at 630084 m E,
# 4833438 m N in zone 17.
CN_TOWER = GeoPoint(43.642567, -79.387139)
CN_TOWER_UTM = (630084.0, 4833438.0)
# On zone 17's central meridian (81 W) at the equator: UTM (500000, 0), no convergence.
ZONE_17_ORIGIN = GeoPoint(0.0, -81.0)


def test_a_position_lands_at_its_utm_figures_relative_to_the_datum() -> None:
    x, y, _ = Datum(ZONE_17_ORIGIN).to_map(CN_TOWER)
    assert x == pytest.approx(CN_TOWER_UTM[0] - 500000.0, abs=1.0)
    assert y == pytest.approx(CN_TOWER_UTM[1], abs=1.0)


def test_the_datum_heading_turns_the_map_frame() -> None:
    # The map's x axis pointing north: a point north of the datum is on +x, east on -y.
    north = Datum(ZONE_17_ORIGIN, math.radians(90)).to_map(GeoPoint(0.001, -81.0))
    east = Datum(ZONE_17_ORIGIN, math.radians(90)).to_map(GeoPoint(0.0, -80.999))
    assert north[0] == pytest.approx(110.53, abs=0.05) and abs(north[1]) < 1e-6
    assert east[1] == pytest.approx(-111.28, abs=0.05) and abs(east[0]) < 1e-6


def test_off_the_central_meridian_the_meridian_convergence_is_added() -> None:
    # At the CN Tower grid north is 1.11 degrees clockwise of true north (east of the
    # central meridian, north of the equator): a point due north of the datum (same
    # longitude) lies slightly west of the map's y axis (yaw 0: x east, y north).
    x, y, _ = Datum(CN_TOWER).to_map(GeoPoint(CN_TOWER.latitude + 0.01, CN_TOWER.longitude))
    assert y == pytest.approx(1111.0, abs=2.0)
    assert abs(x) < 0.05  # the convergence is undone: true north is the map's +y


def test_altitude_is_the_height_above_the_datum() -> None:
    datum = Datum(GeoPoint(52.0, 4.0, 10.0))
    assert datum.to_map(GeoPoint(52.0, 4.0, 12.5))[2] == pytest.approx(2.5)
    assert datum.to_map(GeoPoint(52.0, 4.0))[2] == 0.0


def test_map_points_go_back_to_the_same_latitude_and_longitude() -> None:
    datum = Datum(GeoPoint(52.0116, 4.3571), math.radians(30))
    geo = datum.to_geo(12.5, -7.25)
    x, y, _ = datum.to_map(geo)
    assert (x, y) == (pytest.approx(12.5, abs=1e-6), pytest.approx(-7.25, abs=1e-6))


@pytest.mark.parametrize(
    ("latitude", "longitude", "zone"),
    [(43.64, -79.39, 17), (52.0, 4.36, 31), (60.0, 5.0, 32), (78.0, 20.0, 33), (-33.9, 151.2, 56)],
)
def test_utm_zones_follow_the_standard_with_norway_and_svalbard(
    latitude: float, longitude: float, zone: int
) -> None:
    assert utm_zone(latitude, longitude) == zone


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "gps.yaml"
    path.write_text(text)
    return path


GPS_MISSION = """\
navseq: 1
datum: {latitude: 43.642567, longitude: -79.387139, altitude: 100, yaw: 90}
waypoints:
  - {name: north, latitude: 43.6435, longitude: -79.387139, altitude: 101}
  - {x: 1.0, y: 2.0}
"""


def test_a_mission_reads_gps_waypoints_in_map_coordinates(tmp_path: Path) -> None:
    mission = load_mission(write(tmp_path, GPS_MISSION))
    north, plain = mission.waypoints
    assert mission.datum is not None
    # 0.000933 degrees north, about 103.6 m; with the map's x axis pointing north.
    assert north.x == pytest.approx(103.6, abs=0.2) and abs(north.y) < 0.05
    assert north.z == pytest.approx(1.0)
    assert (plain.x, plain.y) == (1.0, 2.0)


def test_gps_waypoints_are_written_back_as_gps(tmp_path: Path) -> None:
    mission = load_mission(write(tmp_path, GPS_MISSION))
    text = dump_mission_yaml(mission)
    assert "latitude: 43.6435" in text and "datum:" in text
    again = tmp_path / "again.yaml"
    again.write_text(text)
    assert load_mission(again).waypoints == mission.waypoints


def problems_of(path: Path) -> list[str]:
    with pytest.raises(NavseqError) as caught:
        load_mission(path)
    error = caught.value
    errors = error.errors if isinstance(error, MissionErrors) else [error]
    return [str(e) for e in errors]


def test_bad_gps_input_is_refused_with_file_and_line(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        """\
navseq: 1
datum: {latitude: 52.0, longitude: 4.3}
waypoints:
  - {latitude: 95.0, longitude: 4.3}
  - {latitude: 52.0, longitude: 200}
  - {latitude: 52.0, longitude: 4.3, x: 1.0}
  - {latitude: 52.0}
""",
    )
    found = problems_of(path)
    assert len(found) == 4, found
    assert f"{path}:4, waypoint 1, field latitude: a latitude is within -90 .. 90" in found[0]
    assert f"{path}:5, waypoint 2, field longitude" in found[1]
    assert f"{path}:6, waypoint 3: gives both x and latitude/longitude" in found[2]
    assert "'longitude' is missing" in found[3]


def test_gps_waypoints_need_a_datum(tmp_path: Path) -> None:
    path = write(tmp_path, "navseq: 1\nwaypoints:\n  - {latitude: 52.0, longitude: 4.3}\n")
    (found,) = problems_of(path)
    assert f"{path}:3, waypoint 1: is given as latitude/longitude but the mission has no datum" in (
        found
    )


def test_a_faulty_datum_is_reported_once(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "navseq: 1\ndatum: {latitude: 91, longitude: 4}\nwaypoints:\n"
        "  - {latitude: 52.0, longitude: 4.3}\n  - {latitude: 52.1, longitude: 4.3}\n",
    )
    (found,) = problems_of(path)
    assert f"{path}:2, field datum: a latitude is within -90 .. 90 degrees, got 91" in found


def test_the_datum_as_navsat_transforms_parameter_list(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "navseq: 1\ndatum: [0.0, -81.0, 1.5707963]\nwaypoints:\n"
        "  - {latitude: 0.001, longitude: -81.0}\n",
    )
    (waypoint,) = load_mission(path).waypoints
    assert waypoint.x == pytest.approx(110.53, abs=0.05) and abs(waypoint.y) < 1e-3


def test_validate_refuses_gps_without_datum_cleanly(tmp_path: Path) -> None:
    path = write(tmp_path, "navseq: 1\nwaypoints:\n  - {latitude: 52.0, longitude: 4.3}\n")
    result = navseq("validate", path, cwd=tmp_path)
    assert_clean_error(result)
    assert "has no datum" in result.stderr


def test_the_gps_example_runs_on_the_simulator(tmp_path: Path) -> None:
    result = navseq("run", EXAMPLES / "gps.yaml", "--out", tmp_path / "run", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "run" / "mission.png").stat().st_size > 0
    assert "north-dock" in result.stdout


class FromLLPort:
    """A ROS port whose fromLL answers with the datum of Delft, or never, or fails."""

    def __init__(self, datum: Datum, mode: str = "answer") -> None:
        self.datum, self.mode, self.calls = datum, mode, []

    def call(self, service, type_name, fields, on_answer):
        self.calls.append((service, type_name, fields))
        if self.mode == "no type":
            raise ValueError("the package robot_localization is not in this ROS 2")
        if self.mode == "answer":
            point = fields["ll_point"]
            x, y, _ = self.datum.to_map(GeoPoint(point["latitude"], point["longitude"]))
            on_answer(SimpleNamespace(map_point=SimpleNamespace(x=x + 0.5, y=y, z=0.0)), None)
        return lambda: None


def test_nav2_can_convert_gps_waypoints_through_the_stacks_from_ll() -> None:
    mission = load_mission(EXAMPLES / "gps.yaml")
    assert mission.datum is not None
    port = FromLLPort(mission.datum)  # the stack's datum is 0.5 m off navseq's
    converted = converted_through_from_ll(port, "fromLL", mission, timeout=1.0)
    assert [call[:2] for call in port.calls] == [("fromLL", "robot_localization/FromLL")] * 4
    for before, after in zip(mission.waypoints, converted.waypoints, strict=True):
        shift = 0.5 if before.geo is not None else 0.0  # home is given as x/y
        assert after.x == pytest.approx(before.x + shift, abs=1e-6)
        assert (after.y, after.name, after.yaw_rad) == (
            pytest.approx(before.y, abs=1e-6),
            before.name,
            before.yaw_rad,
        )


@pytest.mark.parametrize(
    ("mode", "message"),
    [
        ("silent", "fromLL (robot_localization/FromLL) did not answer within 0.05 s"),
        ("no type", "--from-ll: cannot call fromLL: the package robot_localization"),
    ],
)
def test_a_from_ll_that_cannot_answer_is_one_clear_error(mode: str, message: str) -> None:
    mission = load_mission(EXAMPLES / "gps.yaml")
    assert mission.datum is not None
    with pytest.raises(NavseqError) as caught:
        converted_through_from_ll(FromLLPort(mission.datum, mode), "fromLL", mission, 0.05)
    assert message in str(caught.value)


def test_the_simulators_datum_option_is_checked() -> None:
    datum = datum_of("52.0116,4.3571,90")
    assert (datum.point.latitude, datum.point.longitude) == (52.0116, 4.3571)
    assert datum.yaw_rad == pytest.approx(math.pi / 2)
    for bad, message in (("52.0", "expected LAT,LON"), ("95,4", "a latitude is within")):
        with pytest.raises(NavseqError, match=message) as caught:
            datum_of(bad)
        assert caught.value.source == "--datum"
