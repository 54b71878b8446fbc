"""The shortest-order benchmark, small: navseq's route is never longer than the others."""

from __future__ import annotations

from bench_support import load_benchmark


def test_navseq_s_order_is_never_longer_than_the_file_s_or_nearest_neighbour() -> None:
    from navseq.commands.common import costmap_for_map

    bench = load_benchmark("bench_route")
    costmap = costmap_for_map(bench.ROOT / "maps" / "turtlebot3_world.yaml")
    row = bench.measure(
        "turtlebot3_world", costmap, size=9, seeds=2, time_limit_s=0.3, pairs_up_to=9
    )
    assert len(row.pairs_s) == len(row.searches_s) == 2  # both ways, and they agreed
    for mine, drawn, nearest in zip(row.navseq_m, row.file_m, row.nearest_m, strict=True):
        assert mine <= drawn + 1e-6 and mine <= nearest + 1e-6
    assert sum(row.navseq_m) < sum(row.file_m)  # random order drives further


def test_spots_are_free_and_the_same_for_the_same_seed() -> None:
    from navseq.commands.common import costmap_for_map

    bench = load_benchmark("bench_route")
    costmap = costmap_for_map(bench.ROOT / "maps" / "turtlebot3_world.yaml")
    spots = bench.free_spots(costmap, 12, seed=4)
    assert spots == bench.free_spots(costmap, 12, seed=4)
    assert all(costmap.is_free(x, y) for x, y in spots)
