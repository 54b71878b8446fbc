"""The executor's states, what moves it between them, and the one table that allows it.

The table is the rule: :class:`~navseq.executor.machine.MissionExecutor` changes state
only through :func:`next_state`, which looks the (state, trigger) pair up in
:data:`TRANSITIONS` and raises :class:`InvalidTransition` for a pair that is not there.
A trigger is the executor's own decision about what happened (a goal went out, the
visit's dwell begins...), taken after the waypoint's policy had its say; it is neither
a navigator's event nor a mission event told to sinks.
"""

from __future__ import annotations

import enum


class ExecutorState(enum.Enum):
    """Where the mission run is. Exactly one waypoint visit is current outside IDLE/FINISHED.

    The values are written to the journal (a pause records the state it interrupted).
    """

    IDLE = "idle"  # start() not called yet
    ACTIVE = "active"  # a goal is out; waiting for its result, a timeout or pass-through
    DWELLING = "dwelling"  # goal reached; waiting the waypoint's dwell time
    RUNNING_TASK = "running_task"  # goal reached; a task runs (or waits to run again)
    WAITING_RETRY = "waiting_retry"  # attempt failed; back-off before the next attempt
    RECOVERING = "recovering"  # a recovery of the retry's recovery: list runs
    WAITING_SERVER = "waiting_server"  # server gone; the goal is resent when it is back
    PAUSED = "paused"  # the operator paused: no goal out, no deadline running
    FINISHED = "finished"  # the mission ended (see result.reason)


class Trigger(enum.Enum):
    """What happened to move the executor on (the event of the state-machine table)."""

    GOAL_SENT = "goal sent"  # the current visit's goal went out (first, next or again)
    SERVER_AWAY = "server away"  # the server is gone: the goal waits for it to come back
    DWELL = "dwell"  # the goal was reached; the waypoint's dwell time runs
    TASK = "task"  # a task of the reached waypoint starts (the first, next, or again)
    RETRY_LATER = "retry later"  # the attempt failed; back off before the next one
    RECOVER = "recover"  # a recovery runs before the retry (the first, next, or again)
    PAUSE = "pause"  # the operator paused the run
    DWELL_GOES_ON = "dwell goes on"  # a pause during a dwell ended
    BACKOFF_GOES_ON = "back-off goes on"  # a pause during a back-off ended
    END = "end"  # the mission is over (completed, stopped, cancelled, interrupted)


_S, _T = ExecutorState, Trigger

#: Every allowed state change: (state, trigger) → next state. Nothing leaves FINISHED.
#: A pause ends by going back to what it interrupted: a goal sent again (or held for
#: the server), the dwell or back-off going on with its deadline moved, or the
#: interrupted task started again.
TRANSITIONS: dict[tuple[ExecutorState, Trigger], ExecutorState] = {
    (_S.IDLE, _T.GOAL_SENT): _S.ACTIVE,
    (_S.IDLE, _T.SERVER_AWAY): _S.WAITING_SERVER,
    (_S.IDLE, _T.END): _S.FINISHED,
    (_S.ACTIVE, _T.GOAL_SENT): _S.ACTIVE,  # the next visit's goal replaces this one
    (_S.ACTIVE, _T.SERVER_AWAY): _S.WAITING_SERVER,
    (_S.ACTIVE, _T.DWELL): _S.DWELLING,
    (_S.ACTIVE, _T.TASK): _S.RUNNING_TASK,
    (_S.ACTIVE, _T.RETRY_LATER): _S.WAITING_RETRY,
    (_S.ACTIVE, _T.PAUSE): _S.PAUSED,
    (_S.ACTIVE, _T.END): _S.FINISHED,
    (_S.DWELLING, _T.GOAL_SENT): _S.ACTIVE,
    (_S.DWELLING, _T.SERVER_AWAY): _S.WAITING_SERVER,
    (_S.DWELLING, _T.PAUSE): _S.PAUSED,
    (_S.DWELLING, _T.TASK): _S.RUNNING_TASK,
    (_S.DWELLING, _T.END): _S.FINISHED,
    (_S.RUNNING_TASK, _T.TASK): _S.RUNNING_TASK,  # the next task, or a failed one again
    (_S.RUNNING_TASK, _T.GOAL_SENT): _S.ACTIVE,  # the tasks are done: the next visit
    (_S.RUNNING_TASK, _T.SERVER_AWAY): _S.WAITING_SERVER,
    (_S.RUNNING_TASK, _T.PAUSE): _S.PAUSED,
    (_S.RUNNING_TASK, _T.END): _S.FINISHED,
    (_S.WAITING_RETRY, _T.GOAL_SENT): _S.ACTIVE,
    (_S.WAITING_RETRY, _T.SERVER_AWAY): _S.WAITING_SERVER,
    (_S.WAITING_RETRY, _T.PAUSE): _S.PAUSED,
    (_S.WAITING_RETRY, _T.END): _S.FINISHED,
    (_S.WAITING_RETRY, _T.RECOVER): _S.RECOVERING,
    (_S.RECOVERING, _T.RECOVER): _S.RECOVERING,  # the next recovery of the list
    (_S.RECOVERING, _T.GOAL_SENT): _S.ACTIVE,  # the recoveries are done: the retry
    (_S.RECOVERING, _T.SERVER_AWAY): _S.WAITING_SERVER,
    (_S.RECOVERING, _T.PAUSE): _S.PAUSED,
    (_S.RECOVERING, _T.END): _S.FINISHED,
    (_S.WAITING_SERVER, _T.GOAL_SENT): _S.ACTIVE,
    (_S.WAITING_SERVER, _T.SERVER_AWAY): _S.WAITING_SERVER,  # skipped to the next visit
    (_S.WAITING_SERVER, _T.PAUSE): _S.PAUSED,
    (_S.WAITING_SERVER, _T.END): _S.FINISHED,
    (_S.PAUSED, _T.GOAL_SENT): _S.ACTIVE,
    (_S.PAUSED, _T.SERVER_AWAY): _S.WAITING_SERVER,
    (_S.PAUSED, _T.TASK): _S.RUNNING_TASK,  # the interrupted task runs again from its start
    (_S.PAUSED, _T.RECOVER): _S.RECOVERING,  # the interrupted recovery runs again
    (_S.PAUSED, _T.DWELL_GOES_ON): _S.DWELLING,
    (_S.PAUSED, _T.BACKOFF_GOES_ON): _S.WAITING_RETRY,
    (_S.PAUSED, _T.END): _S.FINISHED,
}


class InvalidTransition(RuntimeError):
    """A trigger the table does not allow in the executor's state (a bug in navseq)."""

    def __init__(self, state: ExecutorState, trigger: Trigger):
        super().__init__(
            f"the executor cannot take trigger {trigger.name} ({trigger.value}) "
            f"in state {state.name}"
        )
        self.state = state
        self.trigger = trigger


def next_state(state: ExecutorState, trigger: Trigger) -> ExecutorState:
    """The state ``trigger`` leads to from ``state``; :class:`InvalidTransition` if none."""
    try:
        return TRANSITIONS[state, trigger]
    except KeyError:
        raise InvalidTransition(state, trigger) from None


__all__ = ["TRANSITIONS", "ExecutorState", "InvalidTransition", "Trigger", "next_state"]
