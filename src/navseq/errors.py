"""The one error type navseq raises for anything a user wrote wrong."""

from __future__ import annotations

from navseq.text import printable


class NavseqError(Exception):
    """A problem in user input, reported as one readable paragraph.

    ``source`` names where the problem is (``mission.yaml:12``, ``param ~p_seq``),
    ``subject`` what it concerns (``waypoint 3 'dock'``, ``field goal_timeout``).
    ``details`` are lines of another program's output that explain it (shown after
    the paragraph). The CLI prints the error (user text escaped, ``navseq.cli.error_text``)
    and exits with status 2; it never shows a traceback.
    """

    def __init__(
        self,
        message: str,
        *,
        source: str | None = None,
        subject: str | None = None,
        details: str | None = None,
    ):
        self.message = message
        self.source = source
        self.subject = subject
        self.details = details
        super().__init__(self.__str__())

    @property
    def paragraph(self) -> str:
        """Place, subject and message: the error without its details."""
        where = ", ".join(part for part in (self.source, self.subject) if part)
        return f"{where}: {self.message}" if where else self.message

    def __str__(self) -> str:
        return f"{self.paragraph}:\n{self.details}" if self.details else self.paragraph


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
        self.summary = summary  # the first line, before the list
        super().__init__(summary + ":\n" + "\n".join(f"  - {line}" for line in lines))

    def __str__(self) -> str:
        return self.message


def error_text(error: BaseException) -> str:
    """An error as a face prints it: what the user wrote is escaped, so it can neither
    drive the terminal nor start a line of its own (a newline in a file's name); the
    only line breaks are those between the problems a :class:`MissionErrors` lists and
    before an error's ``details``."""
    if isinstance(error, MissionErrors):
        listed = "".join(f"\n  - {error_text(each)}" for each in error.errors)
        return f"{printable(error.summary)}:{listed}"
    if isinstance(error, NavseqError) and error.details:
        shown = "".join(f"\n{printable(line)}" for line in error.details.splitlines())
        return f"{printable(error.paragraph)}:{shown}"
    return printable(str(error))
