"""What a fleet run on ROS stacks adds without ROS: the run folder's manifest names the
navigator kind (a resume goes on with it), and a resume on another kind is refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from navseq.errors import NavseqError
from navseq.fleet.manifest import FleetManifest, read_manifest, write_manifest
from navseq.fleet.resume import prepare_fleet_resume
from navseq.fleet.run import FleetRunRequest
from navseq.navigators.settings import Nav2NavigatorSettings


def manifest(navigator: str = "sim") -> FleetManifest:
    return FleetManifest(
        fleet=Path("/nowhere/fleet.yaml"),
        fleet_sha256="0" * 64,
        mission=None,
        map=None,
        shares={"a": ((0, 1), 3.0, 14.0), "b": ((), 0.0, 0.0)},
        dropped=(),
        navigator=navigator,
    )


def test_the_manifest_keeps_the_navigator_kind_and_an_older_one_ran_on_the_simulator(
    tmp_path: Path,
):
    write_manifest(tmp_path, manifest("nav2"))
    assert read_manifest(tmp_path).navigator == "nav2"
    text = (tmp_path / "fleet-run.json").read_text().replace('"navigator": "nav2"', '"x": 0')
    (tmp_path / "fleet-run.json").write_text(text)
    assert read_manifest(tmp_path).navigator == "sim"


def test_resuming_a_simulator_fleet_run_on_ros_stacks_is_refused(tmp_path: Path):
    write_manifest(tmp_path, manifest("sim"))
    request = FleetRunRequest(
        fleet=tmp_path / "fleet.yaml", resume=tmp_path, navigator=Nav2NavigatorSettings()
    )
    with pytest.raises(NavseqError) as refused:
        prepare_fleet_resume(request)
    assert "ran on the embedded simulator" in str(refused.value)
    assert "--navigator" in str(refused.value)
