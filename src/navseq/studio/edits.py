"""A check after an edit, worked out from the last check of the same draft.

A drag moves one waypoint of 5000. The page sends such an edit as the waypoints it
changed in a draft the studio kept (:func:`edited_document`; the whole draft, 180 kB of
JSON written, sent, read and compared at every edit, before), and anything else as the
whole draft. The last check's draft, mission, problems and legs are kept; a new draft
that differs from it only in some waypoints (same count, every other key the same, the
same map file and planner) is checked by reading only those waypoints, and by planning
only the legs that touch them (:func:`legs_touching`: found by their places, not by
walking every leg). Pre-flight (:mod:`navseq.preflight`) keeps its verdicts per point
and the expected duration its legs driven (:mod:`navseq.eta.memo`), so those cost only
what moved too. Anything else — a changed setting, a new map, a waypoint added, a name
(names must be unique across the list), an edit that does not read — is checked whole,
as before. Either way the answer is the one a full check gives (tests compare them).
A page that holds the legs of an earlier answer is sent only the legs that differ from
them (:func:`changed_legs`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError

if TYPE_CHECKING:
    from collections.abc import Iterable

    from navseq.eta.incremental import IncrementalPrediction
    from navseq.mission.model import Mission
    from navseq.studio.documents import CheckedDraft

#: Waypoints changed at most for an edit to be checked from the last check: past that
#: (an import, Order…), reading the whole draft again costs no more.
MAX_MOVED = 64


@dataclass
class LastCheck:
    """What the last check of a draft found, and what it was worked out on."""

    document: dict[str, Any]
    checked: CheckedDraft
    context: tuple[Any, ...]  # the map file's stamp and the planner the legs came from
    legs: list[dict[str, Any]]
    eta: IncrementalPrediction  # the expected duration, kept per visit


def moved_waypoints(before: dict[str, Any], after: Any) -> set[int] | None:
    """The indices of the waypoints ``after`` changed from ``before``, or None when the
    drafts differ in anything else (a setting, the waypoint count, a name)."""
    if not isinstance(after, dict) or after.keys() != before.keys():
        return None
    old, new = before.get("waypoints"), after.get("waypoints")
    if not isinstance(old, list) or not isinstance(new, list) or len(old) != len(new):
        return None
    if any(after[key] != before[key] for key in after if key != "waypoints"):
        return None
    return _moved(old, new, range(len(new)))


def moved_among(
    before: dict[str, Any], after: dict[str, Any], changed: set[int]
) -> set[int] | None:
    """:func:`moved_waypoints` of ``after``, a copy of ``before`` with only the
    waypoints ``changed`` (indices) given anew (:func:`edited_document`): only those are
    compared."""
    return _moved(before["waypoints"], after["waypoints"], changed)


def _moved(old: list[Any], new: list[Any], indices: Iterable[int]) -> set[int] | None:
    """Which of ``indices`` hold another waypoint in ``new`` than in ``old``, or None
    when one was renamed or more than :data:`MAX_MOVED` moved."""
    moved = set()
    for index in indices:
        was, now = old[index], new[index]
        if was == now:
            continue
        # A name must differ from every other: a renamed waypoint is checked whole.
        if not isinstance(now, dict) or not isinstance(was, dict) or "name" in now or "name" in was:
            return None
        moved.add(index)
        if len(moved) > MAX_MOVED:
            return None
    return moved


def edited_document(base: dict[str, Any], changes: Any) -> tuple[dict[str, Any], set[int]]:
    """The draft ``base`` with the waypoints of ``changes`` (``[[index, waypoint], ...]``,
    as the page sends an edit) put in their places, and those indices. ``base`` is not
    changed (the studio keeps it for other answers). Raises ValueError saying what is
    wrong with ``changes``."""
    waypoints = base.get("waypoints")
    if not isinstance(waypoints, list):
        raise ValueError("changes: the draft they apply to has no list of waypoints")
    if not isinstance(changes, list):
        raise ValueError("changes: give a list of [index, waypoint] pairs")
    edited = list(waypoints)
    indices: set[int] = set()
    for number, change in enumerate(changes, 1):
        if not isinstance(change, list) or len(change) != 2:
            raise ValueError(f"changes, item {number}: not an [index, waypoint] pair")
        index, waypoint = change
        if not isinstance(index, int) or isinstance(index, bool):
            raise ValueError(f"changes, item {number}: the index must be a whole number")
        if not 0 <= index < len(edited):
            raise ValueError(
                f"changes, item {number}: no waypoint at index {index} "
                f"(the draft has {len(edited)})"
            )
        edited[index] = waypoint
        indices.add(index)
    return {**base, "waypoints": edited}, indices


def legs_touching(
    legs: list[dict[str, Any]], moved: set[int], mission: Mission
) -> list[int] | None:
    """The positions in ``legs`` (:func:`~navseq.route.legs.legs_of` ``mission``'s, or of
    the same mission before the ``moved`` waypoints moved) of the legs from or to a
    moved waypoint, found by where :func:`~navseq.route.legs.legs_of` puts them; None
    when the legs are not laid out so (then every leg is looked at)."""
    count = len(mission.waypoints)
    first = 1 if mission.start is not None else 0  # the leg to waypoint 0 comes from the start
    plain = count - 1 + first  # legs before the way back of a patrol
    if len(legs) not in (plain, plain + 1):
        return None
    positions: set[int] = set()
    for index in moved:
        positions.update(p for p in (index - 1 + first, index + first) if 0 <= p < plain)
        if len(legs) > plain and index in (0, count - 1):
            positions.add(plain)
    names = {str(index) for index in moved}
    for position in positions:
        leg = legs[position]
        if leg["to"] not in moved and leg["from"] not in names:
            return None
    return sorted(positions)


def edited_mission(last: LastCheck, document: dict[str, Any], moved: set[int]) -> Mission | None:
    """The last check's mission with the ``moved`` waypoints read from ``document``, or
    None when they do not read on their own without a problem (then the draft is checked
    whole, which says what is wrong and where)."""
    from navseq.mission.loader import mission_from_yaml_text
    from navseq.studio.documents import draft_text

    mission = last.checked.mission
    if mission is None or last.checked.map_path is None:
        return None
    order = sorted(moved)
    # The draft as the full check writes it (its map resolved), with only the waypoints
    # that moved: the loader reads them with the same defaults and settings.
    part = {**document, "map": str(last.checked.map_path)}
    part["waypoints"] = [document["waypoints"][index] for index in order]
    try:
        read = mission_from_yaml_text(
            draft_text(part).text, "studio edit", last.checked.map_path.parent
        )
    except NavseqError:
        return None
    if read is None or len(read.waypoints) != len(order):
        return None
    waypoints = list(mission.waypoints)
    for index, waypoint in zip(order, read.waypoints, strict=True):
        # Where the full draft holds it: problems name their waypoint by that line.
        waypoints[index] = replace(waypoint, where=waypoints[index].where)
    return replace(mission, waypoints=tuple(waypoints))


def changed_legs(
    before: list[dict[str, Any]], after: list[dict[str, Any]], among: list[int] | None = None
) -> list[tuple[int, dict[str, Any]]]:
    """The legs of ``after`` (from :func:`~navseq.route.legs.legs_after_edit` of
    ``before``) that are not ``before``'s, by position: what an answer to a page holding
    ``before`` carries instead of all of them (0.7 MB at 5000 waypoints). ``among``:
    the only positions where ``after`` may differ (the legs an edit planned again)."""
    if among is not None:
        return [(p, after[p]) for p in among if after[p] is not before[p] and after[p] != before[p]]
    return [
        (position, leg)
        for position, (was, leg) in enumerate(zip(before, after, strict=True))
        if leg is not was and leg != was
    ]


def checked_after_edit(
    last: LastCheck, mission: Mission, problems_found: list[NavseqError], shown_as: str
) -> CheckedDraft:
    """The draft's check from its ``mission`` (read by :func:`edited_mission`) and its
    pre-flight problems, as :func:`~navseq.studio.documents.check_draft` would give it."""
    from navseq.studio.documents import CheckedDraft, problems_of

    checked = last.checked
    problems = problems_of(
        problems_found, drafted=checked.drafted, draft_path=checked.draft_path, shown_as=shown_as
    )
    return CheckedDraft(mission, problems, checked.map_path, checked.drafted, checked.draft_path)


__all__ = [
    "MAX_MOVED",
    "LastCheck",
    "changed_legs",
    "checked_after_edit",
    "edited_document",
    "edited_mission",
    "legs_touching",
    "moved_among",
    "moved_waypoints",
]
