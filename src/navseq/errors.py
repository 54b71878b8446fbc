"""The one error type navseq raises for anything a user wrote wrong."""

from __future__ import annotations


class NavseqError(Exception):
    """A problem in user input, reported as one readable paragraph.

    ``source`` names where the problem is (``mission.yaml:12``, ``param ~p_seq``),
    ``subject`` what it concerns (``waypoint 3 'dock'``, ``field goal_timeout``).
    The CLI prints ``str(error)`` and exits with status 2; it never shows a traceback.
    """

    def __init__(self, message: str, *, source: str | None = None, subject: str | None = None):
        self.message = message
        self.source = source
        self.subject = subject
        super().__init__(self.__str__())

    def __str__(self) -> str:
        where = ", ".join(part for part in (self.source, self.subject) if part)
        return f"{where}: {self.message}" if where else self.message


class MissionErrors(NavseqError):
    """Several problems found at once (``navseq validate`` lists them all).

    ``context`` says what found them where the user could not tell otherwise
    (``pre-flight on the map on /map``: a map the user did not name).
    """

    def __init__(self, errors: list[NavseqError], context: str = ""):
        self.errors = list(errors)
        lines = [str(e) for e in self.errors]
        summary = f"{len(lines)} problem{'s' if len(lines) != 1 else ''} found"
        if context:
            summary += f" ({context})"
        super().__init__(summary + ":\n" + "\n".join(f"  - {line}" for line in lines))

    def __str__(self) -> str:
        return self.message
