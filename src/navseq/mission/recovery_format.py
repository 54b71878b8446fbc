"""Reading and writing a policy's ``recovery:`` list.

Each entry is a kind with its amount, ``spin: 90`` (a one-key mapping), or a kind that
takes none, ``clear_costmaps`` (plain text)::

    recovery: [spin: 90, backup: 0.15, wait: 2, clear_costmaps]

Every bad entry is reported with its file:line, all of them at once.
"""

from __future__ import annotations

import functools
from typing import Any

from navseq.errors import MissionErrors, NavseqError
from navseq.mission import fields
from navseq.mission.located import Located, describe
from navseq.mission.problems import Problems, closest_hint
from navseq.mission.recovery import RECOVERY_KINDS, Recovery

#: More recoveries than this before one retry is no recovery, it is a program.
MAX_RECOVERIES = 20


def read_recoveries(node: Located, subject: str) -> tuple[Recovery, ...]:
    """The recoveries a ``recovery:`` value lists; raises every problem at once."""
    if node.value is None:
        return ()
    items = fields.sequence(node, subject)
    if len(items) > MAX_RECOVERIES:
        raise NavseqError(
            f"lists {len(items)} recoveries; at most {MAX_RECOVERIES} may run before a retry",
            source=node.where,
            subject=subject,
        )
    problems = Problems()
    recoveries: list[Recovery] = []
    for number, item in enumerate(items, 1):
        read = functools.partial(_recovery, item, f"{subject} {number}")
        recovery = fields.attempt(problems, read)
        if recovery is not None:
            recoveries.append(recovery)
    if len(problems.errors) == 1:
        raise problems.errors[0]
    if problems.errors:
        raise MissionErrors(problems.errors)
    return tuple(recoveries)


def _recovery(item: Located, subject: str) -> Recovery:
    if isinstance(item.value, str):
        kind_name, amount = item.value, None
    elif item.is_mapping and len(item.value) == 1:
        kind_name = next(iter(item.value))
        amount = item.value[kind_name]
    else:
        raise NavseqError(
            "must be a recovery such as spin: 90, backup: 0.15, wait: 2 or clear_costmaps, "
            f"got {describe(item.value)}",
            source=item.where,
            subject=subject,
        )
    kind = RECOVERY_KINDS.get(kind_name)
    where = item.where_key(kind_name) if amount is not None else item.where
    if kind is None:
        raise NavseqError(
            f"unknown recovery {fields.shortened(kind_name)!r}"
            f"{closest_hint(kind_name, RECOVERY_KINDS)}",
            source=where,
            subject=subject,
        )
    if kind.unit is None:
        if amount is not None and amount.value is not None:
            raise NavseqError(
                f"{kind.name} takes no amount; write it alone: {kind.name}",
                source=where,
                subject=subject,
            )
        return Recovery(kind.name)
    if amount is None or amount.value is None:
        raise NavseqError(
            f"{kind.name} needs an amount in {kind.unit}: {kind.name}: <{kind.unit}>",
            source=where,
            subject=subject,
        )
    label = f"{subject} ({kind.name})"
    if kind.signed:
        value = fields.within(amount, label, limit=kind.maximum, unit=f" {kind.unit}")
        if value == 0:
            raise NavseqError(f"must not be 0 {kind.unit}", source=amount.where, subject=label)
    else:
        value = fields.bounded_number(
            amount,
            label,
            minimum=0.0,
            inclusive=False,
            unit=f" {kind.unit}",
            maximum=kind.maximum,
        )
    return Recovery(kind.name, value)


# The policy key ``recovery:`` reads through this module (fields cannot import it back).
fields.POLICY_READERS["recovery"] = read_recoveries


def recovery_document(recoveries: tuple[Recovery, ...]) -> list[Any]:
    """The recoveries as a mission file writes them (read back by :func:`read_recoveries`)."""
    return [r.kind if r.amount is None else {r.kind: _tidy(r.amount)} for r in recoveries]


def _tidy(value: float) -> float | int:
    return int(value) if float(value).is_integer() else value


__all__ = ["MAX_RECOVERIES", "read_recoveries", "recovery_document"]
