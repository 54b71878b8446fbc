"""The fleet benchmark, small: random missions on generated maps end with every
reachable waypoint reached, no collision and no deadlock abort."""

from __future__ import annotations

import pytest

from bench_support import load_benchmark


@pytest.mark.parametrize("seed", [4, 12])  # offices: 7 and 4 robots, robots sent aside
def test_a_random_fleet_mission_reaches_every_reachable_waypoint(seed: int) -> None:
    bench = load_benchmark("bench_fleet")
    result = bench.run_mission(seed, right_of_way=True)
    assert result.reachable > 0
    assert result.reached == result.reachable, result
    assert result.collisions == result.deadlock_aborts == result.unfinished == 0, result
    assert result.yields > 0  # the mission had conflicts for the rule to resolve
