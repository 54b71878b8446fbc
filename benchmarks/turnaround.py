"""Goal turnaround, as ``bench_ros1.py`` and ``bench_nav2.py`` measure it.

A bench action server logs, for every goal, when its request arrived and when its
result went out (server clock, seconds). The turnaround is the gap from result n to
goal n+1's arrival: what a client adds between two goals. Both benchmarks run a plain
client loop and navseq against the same server and print the same table.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np
from rich.table import Table

#: The table's columns after the ones naming the row.
COLUMNS = (
    "client",
    "goals",
    "all ok",
    "median ms",
    "p99 ms",
    "max ms",
    "median / base",
    "p99 / base",
    "goals/s",
)


@dataclasses.dataclass
class Turnaround:
    client: str
    goals_done: int
    gaps_ms: np.ndarray  # server clock: result n out -> goal n+1 arrived
    goals_per_s: float
    success: bool
    server: str = ""

    @property
    def median(self) -> float:
        return float(np.median(self.gaps_ms))

    @property
    def p99(self) -> float:
        return float(np.percentile(self.gaps_ms, 99))

    def cells(self, base: Turnaround) -> list[str]:
        """This row's cells under :data:`COLUMNS`, its ratios to ``base``."""
        return [
            self.client,
            str(self.goals_done),
            "yes" if self.success else "NO",
            f"{self.median:.2f}",
            f"{self.p99:.2f}",
            f"{self.gaps_ms.max():.2f}",
            f"{self.median / base.median:.2f}x",
            f"{self.p99 / base.p99:.2f}x",
            f"{self.goals_per_s:.1f}",
        ]


def last_json_line(text: str) -> dict[str, Any]:
    """The last line of ``text`` that is a JSON object (a client's reply), or {}."""
    for line in reversed(text.splitlines()):
        if line.startswith("{"):
            return dict(json.loads(line))
    return {}


def from_server_log(log: Path, client: str, reply: dict[str, Any], server: str = "") -> Turnaround:
    """The turnaround of one client run, from the bench server's log of it."""
    records = sorted(
        (json.loads(line) for line in log.read_text().splitlines()),
        key=lambda record: record["arrived"],
    )
    if len(records) < 2:
        raise RuntimeError(f"{client}: the server saw {len(records)} goal(s)")
    arrived = np.array([r["arrived"] for r in records])
    results = np.array([r["result"] for r in records])
    return Turnaround(
        client=client,
        goals_done=len(records),
        gaps_ms=(arrived[1:] - results[:-1]) * 1000.0,
        goals_per_s=len(records) / (results[-1] - arrived[0]),
        success=bool(reply.get("success")),
        server=server,
    )


def table(title: str, *, first: tuple[str, ...] = ()) -> Table:
    """An empty turnaround table, with ``first`` columns before :data:`COLUMNS`."""
    made = Table(title=title)
    for column in (*first, *COLUMNS):
        made.add_column(column, justify="right")
    return made
