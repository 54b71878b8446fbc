"""The table printed at the end of ``navseq run``: readable whatever the mission's size.

A five-waypoint mission gets one row per waypoint, as a person would write it down.
A patrol of 1800 laps or a mission of 5000 waypoints gets a table of a few dozen rows
at most, because nobody reads 7225 rows in a terminal:

- loops are summarised per waypoint (visits, reached, not reached, total and mean
  time, distance), not listed per visit;
- consecutive waypoints that were not run are one row (``1201-4867 · not run (3667)``);
- when there are still too many rows, consecutive waypoints that were all reached are
  one row too, with their summed attempts, time and distance;
- waypoints not reached are always listed, up to :data:`MAX_PROBLEM_ROWS`; the rest is
  one last row that says how many more there are and points to the report, which
  keeps every visit.

The table reads the run only through :func:`waypoint_stats`, so that a result that
keeps per-waypoint aggregates instead of every visit (an endless patrol) changes that
one function. :func:`print_table` prints it without cutting anything when the output
is not a terminal (a pipe, a file, a CI log).
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass

from rich.console import Console
from rich.markup import escape
from rich.measure import Measurement
from rich.table import Table
from rich.text import Text

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import MissionResult, WaypointResult
from navseq.mission.model import Mission
from navseq.sinks.progress import OUTCOME_MARK, OUTCOME_STYLE
from navseq.sinks.progress import _why as why_text
from navseq.text import printable

#: Above this many rows, runs of waypoints that were all reached become one row each.
MAX_ROWS = 40
#: Waypoints not reached that are listed one by one; the others are counted in one row.
MAX_PROBLEM_ROWS = 20


class Standing(enum.Enum):
    """How a waypoint did over the whole run, which decides how its row may be merged."""

    PROBLEM = "problem"  # at least one visit ran and was not reached
    REACHED = "reached"  # every visit that ran was reached
    NOT_RUN = "not_run"  # no visit ran


@dataclass
class WaypointStats:
    """One waypoint's visits added up (or a range of waypoints', for a merged row)."""

    first: int  # 0-based index of the (first) waypoint
    last: int  # the last one, == first for a single waypoint
    name: str | None = None
    reached: int = 0
    skipped: int = 0
    failed: int = 0
    not_run: int = 0
    passed_through: int = 0
    attempts: int = 0
    duration: float = 0.0  # s, over the visits that ran
    distance: float = 0.0  # m
    reason: str = ""  # why the latest visit not reached was not

    @property
    def ran(self) -> int:
        return self.reached + self.skipped + self.failed

    @property
    def missed(self) -> int:
        return self.skipped + self.failed

    @property
    def waypoints(self) -> int:
        return self.last - self.first + 1

    @property
    def standing(self) -> Standing:
        if self.missed:
            return Standing.PROBLEM
        return Standing.REACHED if self.reached else Standing.NOT_RUN

    def add_visit(self, visit: WaypointResult) -> None:
        outcome = WaypointOutcome(visit.outcome)
        if outcome is WaypointOutcome.NOT_RUN:
            self.not_run += 1
            return
        if outcome is WaypointOutcome.REACHED:
            self.reached += 1
            self.passed_through += visit.passed_through
        elif outcome is WaypointOutcome.SKIPPED:
            self.skipped += 1
        else:
            self.failed += 1
        if outcome is not WaypointOutcome.REACHED:
            self.reason = visit_reason(visit) or self.reason
        self.attempts += visit.attempts
        self.duration += visit.duration
        self.distance += visit.distance_driven

    def merged(self, other: WaypointStats) -> WaypointStats:
        """This range extended by the waypoint(s) of ``other``, which come right after."""
        return WaypointStats(
            first=self.first,
            last=other.last,
            reached=self.reached + other.reached,
            skipped=self.skipped + other.skipped,
            failed=self.failed + other.failed,
            not_run=self.not_run + other.not_run,
            passed_through=self.passed_through + other.passed_through,
            attempts=self.attempts + other.attempts,
            duration=self.duration + other.duration,
            distance=self.distance + other.distance,
            reason=other.reason or self.reason,
        )


def visit_reason(visit: WaypointResult) -> str:
    """Why a visit was not reached: its last failure's reason and the stack's text."""
    if WaypointOutcome(visit.outcome) is WaypointOutcome.REACHED:
        return visit.reason
    failure = visit.last_failure
    if failure is None:
        return visit.reason
    return why_text(visit.reason or failure.reason, failure.text)


def waypoint_stats(mission: Mission, result: MissionResult) -> list[WaypointStats]:
    """Every waypoint's visits added up, in mission order (the table's only input)."""
    stats = [
        WaypointStats(index, index, name=waypoint.name)
        for index, waypoint in enumerate(mission.waypoints)
    ]
    for visit in result.visits:
        if 0 <= visit.index < len(stats):
            stats[visit.index].add_visit(visit)
            if visit.name is not None:  # the name the run knew it by
                stats[visit.index].name = visit.name
    if result.omitted_visits and result.waypoints:
        # A long patrol lists only some visits in full: the counts come from the
        # per-waypoint totals, which count every visit; reasons from the listed ones.
        for totals in result.waypoints:
            if 0 <= totals.index < len(stats):
                row = stats[totals.index]
                listed_reached = row.reached
                row.reached, row.skipped, row.failed = totals.reached, totals.skipped, totals.failed
                row.not_run, row.attempts = totals.not_run, totals.attempts
                row.duration, row.distance = totals.duration, totals.distance_driven
                if listed_reached:  # pass-throughs in the same share as among listed visits
                    row.passed_through = round(row.passed_through * row.reached / listed_reached)
    return stats


def summary_rows(
    stats: Sequence[WaypointStats],
    *,
    max_rows: int = MAX_ROWS,
    max_problems: int = MAX_PROBLEM_ROWS,
) -> tuple[list[WaypointStats], WaypointStats | None]:
    """The rows to print, and the row that sums up what comes after the last one listed.

    Not-run waypoints next to each other are merged always, reached ones only when the
    table would otherwise be longer than ``max_rows``; waypoints not reached never are.
    """
    rows = _merge_runs(stats, {Standing.NOT_RUN})
    if len(rows) > max_rows:
        rows = _merge_runs(rows, {Standing.NOT_RUN, Standing.REACHED})
    problems = [n for n, row in enumerate(rows) if row.standing is Standing.PROBLEM]
    if len(problems) <= max_problems:
        return rows, None
    cut = problems[max_problems - 1] + 1
    rest = rows[cut]
    for row in rows[cut + 1 :]:
        rest = rest.merged(row)
    return rows[:cut], rest


def _merge_runs(rows: Sequence[WaypointStats], mergeable: set[Standing]) -> list[WaypointStats]:
    merged: list[WaypointStats] = []
    for row in rows:
        previous = merged[-1] if merged else None
        if (
            previous is not None
            and row.standing is previous.standing
            and row.standing in mergeable
            and previous.last + 1 == row.first
        ):
            merged[-1] = previous.merged(row)
        else:
            merged.append(row)
    return merged


def summary_table(
    mission: Mission,
    result: MissionResult,
    *,
    numbers: Sequence[int] | None = None,
    part: str | None = None,
    max_rows: int = MAX_ROWS,
    max_problems: int = MAX_PROBLEM_ROWS,
) -> Table:
    """The run's outcome per waypoint (or range of waypoints), with totals in the footer.

    One visit per waypoint (a single loop) gives one column per visit detail: outcome,
    attempts, time, distance. Several visits (loops) give per-waypoint counts, total and
    mean time. A waypoint not reached says why: the last failure's reason and the
    navigation stack's own text (move_base's "Failed to find a valid plan").

    ``numbers`` are the waypoints' 0-based positions in the mission file when
    ``mission`` is a part of it (``--from``/``--to``/``--only``), so that rows carry the
    numbers the user knows; ``part`` says which part ran, in the title.
    """
    stats = waypoint_stats(mission, result)
    rows, rest = summary_rows(stats, max_rows=max_rows, max_problems=max_problems)
    loops = any(row.ran + row.not_run > 1 for row in stats)
    title = f"mission {mission.source}" + (f" ({part})" if part else "") + f": {result.reason}"
    title_text = Text(printable(title))
    # At least as wide as its title: rich wraps a title to the table's width.
    table = Table(title=title_text, show_footer=True, min_width=title_text.cell_len)

    def number(index: int) -> str:
        if numbers is None:  # a part's mission knows its file numbers
            return str(mission.number(index))
        return str(numbers[index] + 1)

    def label(row: WaypointStats) -> str:
        if row.waypoints == 1:
            return number(row.first)
        return f"{number(row.first)}-{number(row.last)}"

    every = WaypointStats(0, max(len(stats) - 1, 0))
    for row in stats:
        every = every.merged(row)
    table.add_column("#", justify="right", footer="total")
    table.add_column("name")
    if loops:
        table.add_column("visits", justify="right", footer=str(every.ran))
        table.add_column("reached", justify="right", footer=str(every.reached))
        table.add_column("not reached", justify="right", footer=str(every.missed))
    else:
        table.add_column("outcome")
    table.add_column("attempts", justify="right", footer=str(every.attempts))
    # Brackets are rich markup: escape the unit.
    table.add_column(escape("time [s]"), justify="right", footer=f"{result.duration:.1f}")
    if loops:
        table.add_column(escape("mean [s]"), justify="right")
    table.add_column(
        escape("distance [m]"), justify="right", footer=f"{result.distance_driven:.2f}"
    )
    shown = [*rows, *([rest] if rest is not None else [])]
    any_reason = any(row.reason for row in shown)
    if any_reason:
        table.add_column("reason")
    for row in rows:
        _add_row(table, row, label(row), loops=loops, reason=any_reason)
    if rest is not None:  # it holds waypoints not reached: more than could be listed
        name = (
            f"… and {_plural(_missed_waypoints(stats, rest), 'more waypoint')} not reached, "
            "see report.json"
        )
        _add_row(table, rest, label(rest), loops=loops, reason=any_reason, name=name)
    return table


def _missed_waypoints(stats: Sequence[WaypointStats], rest: WaypointStats) -> int:
    return sum(row.missed > 0 for row in stats[rest.first : rest.last + 1])


def _plural(count: int, word: str) -> str:
    return f"{count} {word}{'' if count == 1 else 's'}"


def _outcome_text(row: WaypointStats) -> tuple[str, WaypointOutcome]:
    """``✓ reached``, ``↷ skipped``, ``· not run (3667)``: the mark, word and count."""
    if row.waypoints == 1 and row.ran + row.not_run == 1:
        if row.failed:
            outcome = WaypointOutcome.FAILED
        elif row.skipped:
            outcome = WaypointOutcome.SKIPPED
        elif row.reached:
            outcome = WaypointOutcome.REACHED
        else:
            outcome = WaypointOutcome.NOT_RUN
        word = "passed through" if row.passed_through else outcome.value.replace("_", " ")
        return f"{OUTCOME_MARK[outcome]} {word}", outcome
    parts = [
        (count, outcome)
        for count, outcome in (
            (row.reached, WaypointOutcome.REACHED),
            (row.skipped, WaypointOutcome.SKIPPED),
            (row.failed, WaypointOutcome.FAILED),
            (row.not_run, WaypointOutcome.NOT_RUN),
        )
        if count
    ]
    text = ", ".join(
        f"{OUTCOME_MARK[outcome]} {outcome.value.replace('_', ' ')} ({count})"
        for count, outcome in parts
    )
    return text, _worst(row)


def _worst(row: WaypointStats) -> WaypointOutcome:
    if row.failed:
        return WaypointOutcome.FAILED
    if row.skipped:
        return WaypointOutcome.SKIPPED
    return WaypointOutcome.REACHED if row.reached else WaypointOutcome.NOT_RUN


def _add_row(
    table: Table,
    row: WaypointStats,
    label: str,
    *,
    loops: bool,
    reason: bool,
    name: str | None = None,
) -> None:
    if name is None:
        if row.waypoints == 1:
            name = row.name or ""
        elif loops and row.ran == 0:  # no count says it: words do
            name = f"{OUTCOME_MARK[WaypointOutcome.NOT_RUN]} {row.waypoints} waypoints not run"
        else:
            name = f"{row.waypoints} waypoints"
    outcome_text, outcome = _outcome_text(row)
    cells = [label, name]
    if loops:
        cells += [str(row.ran), str(row.reached), str(row.missed)]
    else:
        cells.append(outcome_text)
    if row.ran:
        cells += [str(row.attempts), f"{row.duration:.1f}"]
        if loops:
            cells.append(f"{row.duration / row.ran:.1f}")
        cells.append(f"{row.distance:.2f}")
    else:  # nothing ran: no figures to give
        cells += [""] * (4 if loops else 3)
    if reason:
        cells.append(row.reason)
    # Text cells: a name or reason with [brackets] is not markup; a control character
    # in one is shown escaped, never sent to the terminal.
    table.add_row(*(Text(printable(cell)) for cell in cells), style=OUTCOME_STYLE[outcome])


def print_table(table: Table, console: Console) -> None:
    """Print ``table``; outside a terminal at the width it needs, so nothing is cut.

    In a terminal rich fits the table to the window and wraps long cells. A pipe or a
    file has no window: rich would assume 80 columns and cut names short ("north-m…"),
    so there the table gets its natural width.
    """
    if not console.is_terminal:
        wide = console.options.update_width(100_000)
        parts = [table, *([table.title] if table.title is not None else [])]
        console.width = max(max(Measurement.get(console, wide, p).maximum for p in parts), 20)
    console.print(table)
