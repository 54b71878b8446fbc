"""The quickest-order benchmark, small: navseq's route is never slower than the others."""

from __future__ import annotations

from bench_support import load_benchmark


def test_navseq_s_order_is_never_slower_than_the_file_s_or_nearest_neighbour() -> None:
    from navseq.commands.common import costmap_for_map

    bench = load_benchmark("bench_route")
    costmap = costmap_for_map(bench.ROOT / "maps" / "turtlebot3_world.yaml")
    row = bench.measure(
        "turtlebot3_world",
        costmap,
        size=9,
        seeds=2,
        time_limit_s=0.3,
        reference_s=0.6,
        exact_up_to=9,
    )
    assert len(row.exact_s) == len(row.searches_s) == len(row.errors) == 2  # both ways
    assert max(error.max() for error in row.errors) < 0.02  # a small map: exact both ways
    for mine, drawn, nearest in zip(row.navseq_s, row.file_s, row.nearest_s, strict=True):
        assert mine <= drawn + 1e-6 and mine <= nearest + 1e-6
    assert sum(row.navseq_s) < sum(row.file_s)  # random order takes longer
    assert len(row.reference_s) == 2


def test_spots_are_free_and_the_same_for_the_same_seed() -> None:
    from navseq.commands.common import costmap_for_map

    bench = load_benchmark("bench_route")
    costmap = costmap_for_map(bench.ROOT / "maps" / "turtlebot3_world.yaml")
    spots = bench.free_spots(costmap, 12, seed=4)
    assert spots == bench.free_spots(costmap, 12, seed=4)
    assert all(costmap.is_free(x, y) for x, y in spots)
