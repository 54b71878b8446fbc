"""Navigators: adapters from the executor to a navigation stack (sim, ros1, ...)."""

from navseq.navigators.base import (
    Goal,
    GoalAccepted,
    GoalDone,
    GoalFeedback,
    GoalHeld,
    GoalOutcome,
    GoalPlan,
    GoalReleased,
    NavEvent,
    Navigator,
    ServerBack,
    ServerLost,
)

__all__ = [
    "Goal",
    "GoalAccepted",
    "GoalDone",
    "GoalFeedback",
    "GoalHeld",
    "GoalOutcome",
    "GoalPlan",
    "GoalReleased",
    "NavEvent",
    "Navigator",
    "ServerBack",
    "ServerLost",
]
