"""A past run's timeline: the waypoints' states at any time, in a size that grows with the run."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

from navseq import cli
from navseq.studio.replay import replay_of

REPO = Path(__file__).resolve().parents[1]


def states_over_time(replay: dict) -> list[list[str]]:
    """The waypoints' states after each change, as the page rebuilds them."""
    count = len(replay["mission"]["waypoints"])
    statuses = ["pending"] * count
    seen = []
    for change in replay["states"]:
        if change["reset"]:
            statuses = ["pending"] * count
        for index, status in change["changes"]:
            statuses[index] = status
        seen.append(list(statuses))
    return seen


def inside(folder: Path):
    return lambda path: path.resolve().is_relative_to(folder.resolve())


def run_folder(tmp_path: Path, waypoints: int, loops: int) -> Path:
    lines = [f"loops: {loops}", "waypoints:"]
    lines += [f"  - {{name: w{i}, x: {i * 0.5}, y: 0.0, yaw: 0}}" for i in range(waypoints)]
    mission = tmp_path / "line.yaml"
    mission.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    argv = ["run", str(mission), "--navigator", "scripted", "--out", str(out), "--no-picture"]
    assert cli.main(argv) == 0
    return out


def test_each_loop_starts_with_every_waypoint_pending_again(tmp_path: Path) -> None:
    replay = replay_of(run_folder(tmp_path, 3, 2), "out", tmp_path, inside(tmp_path))
    seen = states_over_time(replay)
    assert seen[-1] == ["reached"] * 3
    resets = [change for change in replay["states"] if change["reset"]]
    assert [change["loop"] for change in resets] == [0, 1]  # counted from 0, as in the journal
    second_loop = seen[replay["states"].index(resets[1])]
    assert second_loop == ["pending"] * 3


def test_the_timeline_grows_with_the_run_not_with_its_square(tmp_path: Path) -> None:
    replay = replay_of(run_folder(tmp_path, 400, 1), "out", tmp_path, inside(tmp_path))
    changed = sum(len(change["changes"]) for change in replay["states"])
    # driving, then reached: two changes per visit (a full list per change would be
    # 400 entries each).
    assert changed == 2 * 400
    assert states_over_time(replay)[-1] == ["reached"] * 400


def test_a_command_line_run_replays_with_its_mission_only_if_allowed_and_unchanged(
    tmp_path: Path,
) -> None:
    folder = run_folder(tmp_path, 2, 1)
    assert replay_of(folder, "out", tmp_path, inside(tmp_path))["mission"] is not None
    # Outside the folders the studio may read: no mission, but the run still replays.
    refused = replay_of(folder, "out", tmp_path, inside(folder))
    assert refused["mission"] is None and refused["poses"]
    # Edited since the run: the waypoints drawn would not be those that were run.
    (tmp_path / "line.yaml").write_text("waypoints:\n  - {x: 9.0, y: 9.0, yaw: 0}\n")
    assert replay_of(folder, "out", tmp_path, inside(tmp_path))["mission"] is None


def test_the_replayed_trail_is_the_driven_one_never_through_a_pillar(tmp_path: Path) -> None:
    """Every replayed pose is one the robot reported, and the trail drawn between them
    stays off the arena's pillars and walls (goals drawn as poses cut through them)."""
    from navseq.executor import events as ev
    from navseq.journal.reader import journal_events
    from navseq.sim.occupancy import load_map

    out = tmp_path / "out"
    mission = REPO / "examples" / "turtlebot3_world.yaml"
    assert cli.main(["run", str(mission), "--out", str(out), "--no-picture"]) == 0
    replay = replay_of(out, "out", tmp_path, inside(REPO))
    reported = [
        (event.x, event.y)
        for event in journal_events(out / "journal.jsonl")
        if isinstance(event, ev.WaypointProgress)
    ]
    assert len(replay["poses"]) == len(reported) > 10
    for (_, x, y, _), (rx, ry) in zip(replay["poses"], reported, strict=True):
        assert math.dist((x, y), (rx, ry)) <= 0.05
    grid = load_map(REPO / "maps" / "turtlebot3_world.yaml")
    occupied = grid.occupied_mask()
    for (_, x0, y0, _), (_, x1, y1, _) in itertools.pairwise(replay["poses"]):
        steps = max(2, int(math.dist((x0, y0), (x1, y1)) / 0.01))
        for k in range(steps + 1):
            row, col = grid.world_to_cell(x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps)
            assert not occupied[row, col], f"the trail crosses an obstacle at {x0:.2f},{y0:.2f}"


def test_a_recorded_run_whose_journal_is_gone_replays_from_its_recording(tmp_path: Path) -> None:
    folder = run_folder(tmp_path, 3, 1)
    from_journal = replay_of(folder, "out", tmp_path, inside(tmp_path))
    recorded = tmp_path / "recorded"
    mission = tmp_path / "line.yaml"
    argv = ["run", str(mission), "--navigator", "scripted", "--out", str(recorded)]
    assert cli.main([*argv, "--no-picture", "--record"]) == 0
    (recorded / "journal.jsonl").unlink()
    from navseq.studio.replay import run_folders

    assert recorded.resolve() in run_folders([tmp_path])
    replay = replay_of(recorded, "recorded", tmp_path, inside(tmp_path))
    assert replay["mission"] is not None
    assert states_over_time(replay)[-1] == ["reached"] * 3
    assert [s["changes"] for s in replay["states"]] == [
        s["changes"] for s in from_journal["states"]
    ]
    # Every progress event's pose (the journal keeps only the path's corners).
    assert len(replay["poses"]) >= len(from_journal["poses"]) > 0
    assert replay["duration_s"] == from_journal["duration_s"]
