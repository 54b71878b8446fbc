"""Ending the ``roslaunch`` that started a node, the way Ctrl-C would.

roslaunch has one way for a node to end a launch, ``required="true"``: when such a node
exits, roslaunch prints a red "REQUIRED process [...] has died! ... Initiating shutdown!"
banner, the same one a crash gets. A mission that simply finished is not a crash, so the
navseq node (``~end_launch``) instead sends SIGINT to the roslaunch process that started
it and stays up until that shutdown reaches it: roslaunch then stops every node quietly,
as on Ctrl-C. roslaunch offers no remote call for this (its XML-RPC server only lists
and registers processes), hence the signal.

Only a parent process that is roslaunch is signalled: a node started by ``rosrun``, by
a ``launch-prefix`` wrapper or by hand is left alone (the caller logs why).
"""

from __future__ import annotations

import os
import signal
from pathlib import Path

ROSLAUNCH = "roslaunch"


def command_line(pid: int) -> list[str]:
    """The argv of process ``pid`` (Linux ``/proc``); empty when it cannot be read."""
    try:
        raw = Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return []
    return [part.decode(errors="replace") for part in raw.split(b"\0") if part]


def is_roslaunch(argv: list[str]) -> bool:
    """Whether a command line runs roslaunch (``python3 /usr/bin/roslaunch ...`` or direct)."""
    return any(Path(word).name == ROSLAUNCH for word in argv[:2])


def end_parent_launch() -> str | None:
    """SIGINT the roslaunch that is this process's parent.

    Returns None when it was signalled, else why not (for the log).
    """
    parent = os.getppid()
    if not is_roslaunch(command_line(parent)):
        return f"the parent process (pid {parent}) is not roslaunch"
    try:
        os.kill(parent, signal.SIGINT)
    except OSError as error:
        return f"could not signal roslaunch (pid {parent}): {error.strerror}"
    return None
