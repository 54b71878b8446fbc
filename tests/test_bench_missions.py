"""The missions-at-scale benchmark, small: generated office and warehouse maps, random
missions pre-flighted and run on the simulator — nothing trapped, every accepted
waypoint reached."""

from __future__ import annotations

from bench_support import load_benchmark


def test_small_seeded_benchmark_reaches_every_accepted_waypoint() -> None:
    bench = load_benchmark("bench_missions")
    policies = {"no stall limit": bench.POLICIES["no stall limit"]}
    rows = bench.run_benchmark(6, seed=11, waypoints=(3, 4), policies=policies)
    assert {row.kind for row in rows} == {"office", "warehouse"}
    for row in rows:
        assert row.accepted > 0, row
        assert row.reached == row.accepted, row.failures
        assert row.trapped == 0 and row.collisions == 0, row.failures
        assert row.accepted < row.waypoints or row.kind == "warehouse"  # pre-flight refuses some


def test_generated_maps_are_the_same_for_the_same_seed() -> None:
    from navseq.sim.mapgen import office_map, warehouse_map

    assert (office_map(4).data == office_map(4).data).all()
    assert not (office_map(4).data == office_map(5).data).all()
    assert (warehouse_map(2).data == warehouse_map(2).data).all()
