"""bench_nav2_pass_modes' table says what each mode did (no ROS: outcomes made here)."""

from __future__ import annotations

from rich.console import Console

from bench_support import load_benchmark

bench = load_benchmark("bench_nav2_pass_modes")


def rendered(outcomes: list[object]) -> str:
    console = Console(width=200, record=True)
    console.print(bench.table(outcomes))
    return console.export_text()


def test_the_table_counts_completions_passes_and_failures_per_mode() -> None:
    text = rendered(
        [
            bench.Outcome("preempt (navseq)", True, 25.0, "exit 0", 1, [5.0, 10.0, 15.0, 20.0]),
            bench.Outcome("preempt (navseq)", True, 27.0, "exit 0", 0, [5.0, 10.0, 15.0, 21.0]),
            bench.Outcome("through-poses", True, 23.0, "SUCCEEDED 0", 0, [6.0, 12.0, 15.0, 18.0]),
            bench.Outcome("through-poses", False, 28.7, "ABORTED 104", 0, [6.0]),
            bench.Outcome("closed tour, through-poses", True, 0.1, "SUCCEEDED 0", 0, []),
        ]
    )
    rows = {line.split("│")[1].strip(): line for line in text.splitlines() if "│" in line}
    assert "2/2" in rows["preempt (navseq)"] and "26.0" in rows["preempt (navseq)"]
    assert "4-4" in rows["preempt (navseq)"]
    assert "1/2" in rows["through-poses"] and "1x ABORTED 104" in rows["through-poses"]
    # A closed tour "succeeds" without passing anything: the table must show it.
    assert "0-0" in rows["closed tour, through-poses"]
