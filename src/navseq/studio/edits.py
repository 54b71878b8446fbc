"""A check after an edit, worked out from the last check of the same draft.

The page sends the whole draft on every edit; a drag moves one waypoint of 5000. The
last check's draft, mission, problems and legs are kept; a new draft that differs from it
only in some waypoints (same count, every other key the same, the same map file and
planner) is checked by reading only those waypoints, and by planning only the legs that
touch them. Pre-flight (:mod:`navseq.preflight`) keeps its verdicts per point and the
expected duration its legs driven (:mod:`navseq.eta.memo`), so those cost only what
moved too. Anything else — a changed setting, a new map, a waypoint added, a name
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
    moved = set()
    for index, (was, now) in enumerate(zip(old, new, strict=True)):
        if was == now:
            continue
        # A name must differ from every other: a renamed waypoint is checked whole.
        if not isinstance(now, dict) or not isinstance(was, dict) or "name" in now or "name" in was:
            return None
        moved.add(index)
        if len(moved) > MAX_MOVED:
            return None
    return moved


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
    before: list[dict[str, Any]], after: list[dict[str, Any]]
) -> list[tuple[int, dict[str, Any]]]:
    """The legs of ``after`` (from :func:`~navseq.route.legs.legs_after_edit` of
    ``before``) that are not ``before``'s, by position: what an answer to a page holding
    ``before`` carries instead of all of them (0.7 MB at 5000 waypoints)."""
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
    "edited_mission",
    "moved_waypoints",
]
