"""``examples/keepout.yaml`` against the real Nav2 (Jazzy) with its costmap filters: the
example's keepout and speed masks served by Nav2's own ``map_server`` and
``costmap_filter_info_server``, its KeepoutFilter in both costmaps and its SpeedFilter in
the global one (``tests/nav2/nav2_loopback.launch.py keepout_mask:= speed_mask:=``).
What a user notices is what the stand-in gives (tests/test_masks_every_navigator.py):
every waypoint reached, the trail never in the keepout zone, slower in the speed zone.
One bringup for the module; skipped with the reason where the real Nav2 is not there."""

from __future__ import annotations

import json
import statistics
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from cli_support import EXAMPLES, NAVSEQ, REPO, TURTLEBOT3_MAP
from nav2_real_support import RealNav2, nav2_missing_reason
from test_masks_every_navigator import in_keepout_zone, progress, speeds

pytestmark = [pytest.mark.ros2, pytest.mark.slow]

MISSING = nav2_missing_reason()
START = (-2.0, -0.5, 0.0)  # the example's start:
# The launch's Regulated Pure Pursuit drives at 0.5 m/s; the SpeedFilter's percent is
# of that speed (RPP's setSpeedLimit), so the example's zone allows 0.2 m/s.
RPP_SPEED = 0.5
ZONE_SPEED = 0.4 * RPP_SPEED


@pytest.fixture(scope="module")
def nav2(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RealNav2]:
    if MISSING is not None:
        pytest.skip(MISSING)
    stack = RealNav2(
        TURTLEBOT3_MAP,
        tmp_path_factory.mktemp("nav2-logs"),
        f"keepout_mask:={REPO / 'maps' / 'turtlebot3_world_keepout.yaml'}",
        f"speed_mask:={REPO / 'maps' / 'turtlebot3_world_speed.yaml'}",
    )
    try:
        stack.place(*START)
        yield stack
    finally:
        stack.stop()


def test_the_keepout_example_on_the_real_nav2_with_its_filters(
    nav2: RealNav2, tmp_path: Path
) -> None:
    out = tmp_path / "out"
    # The example as a user with a real stack would run it: a goal the controller gives up
    # on a loaded machine ("collision ahead" at a zone's edge, patience exceeded) is sent
    # again rather than skipped at once.
    mission = tmp_path / "keepout.yaml"
    text = (EXAMPLES / "keepout.yaml").read_text().replace("../maps/", f"{REPO / 'maps'}/")
    mission.write_text(text.replace("  on_failure: skip\n", "  on_failure: skip\n  retries: 2\n"))
    assert "retries: 2" in mission.read_text()
    done = subprocess.run(
        [NAVSEQ, "run", str(mission), "--navigator", "nav2", "--json", "--out", str(out)],
        env=nav2.env, cwd=tmp_path, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:] + nav2.log_tail()
    report = json.loads((out / "report.json").read_text())
    assert [visit["outcome"] for visit in report["visits"]] == ["reached"] * 4
    trail = progress(done.stdout)
    assert len(trail) > 100
    assert not [(r["x"], r["y"]) for r in trail if in_keepout_zone(r["x"], r["y"])]
    inside, outside = speeds(trail, inside=True), speeds(trail, inside=False)
    assert inside and outside
    # Nav2's SpeedFilter runs in its costmap's updates (the global costmap's 1 Hz here,
    # later on a loaded machine): the robot enters the zone at full speed and slows
    # within a second or two, so most of its stretches in the zone, not all, are at the
    # zone's speed.
    assert statistics.median(inside) <= ZONE_SPEED * 1.1, inside
    assert max(outside) > 1.5 * ZONE_SPEED, outside
