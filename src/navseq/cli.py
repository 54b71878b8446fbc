"""The ``navseq`` command line: parse arguments, dispatch to a subcommand, map errors
to exit statuses.

Exit statuses (the same for every subcommand):

- 0: done (for ``run``: every waypoint reached);
- 1: ``run`` finished but not every waypoint was reached;
- 2: bad input (mission, map, arguments) — a readable message, never a traceback;
- 130 / 143 / 129: interrupted by SIGINT / SIGTERM / SIGHUP (``run`` cancels the active
  goal first).

Anything else that goes wrong is a bug: one line "internal error" on stderr, and
``--debug`` shows the traceback.
"""

from __future__ import annotations

import argparse
import gc
import logging
import os
import re
import signal
import sys
import traceback
from types import FrameType

from navseq import __version__
from navseq.commands import SUBCOMMANDS
from navseq.errors import NavseqError, error_text
from navseq.signals import Terminated, ignore_until_exit
from navseq.text import printable

EXIT_OK = 0
EXIT_NOT_ALL_REACHED = 1
EXIT_BAD_INPUT = 2
EXIT_INTERNAL_ERROR = 3
EXIT_SIGINT = 128 + signal.SIGINT
EXIT_SIGTERM = 128 + signal.SIGTERM
EXIT_SIGPIPE = 128 + signal.SIGPIPE


#: Ending the process like SIGTERM: a closed terminal (SIGHUP) included.
_TERMINATING = (signal.SIGTERM, signal.SIGHUP)


def _raise_terminated(signum: int, frame: FrameType | None) -> None:
    raise Terminated(signal.Signals(signum).name)


def build_parser() -> argparse.ArgumentParser:
    # --debug is accepted before and after the subcommand name; SUPPRESS keeps the
    # subparser from overwriting a --debug given before it.
    debug_parent = argparse.ArgumentParser(add_help=False)
    debug_parent.add_argument(
        "--debug",
        action="store_true",
        default=argparse.SUPPRESS,
        help="show the traceback of an internal error",
    )
    parser = argparse.ArgumentParser(
        prog="navseq",
        description="Send a sequence of navigation goals to a robot and see the mission through.",
        parents=[debug_parent],
    )
    parser.add_argument("--version", action="version", version=f"navseq {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for sub in SUBCOMMANDS:
        module = sub.load()
        sub_parser = subparsers.add_parser(
            sub.name, help=sub.summary, description=sub.summary, parents=[debug_parent]
        )
        module.configure(sub_parser)
        sub_parser.set_defaults(command_module=module)
    return parser


# Options whose value may start with a minus sign (``--start -2,-0.5,0``), which
# argparse would otherwise take for an option.
NEGATIVE_VALUE_OPTIONS = ("--start",)
_NUMBER_START = re.compile(r"-[0-9.]")


def _attach_negative_values(argv: list[str]) -> list[str]:
    """``--start -2,-0.5,0`` -> ``--start=-2,-0.5,0`` so that argparse accepts it."""
    joined: list[str] = []
    index = 0
    while index < len(argv):
        arg = argv[index]
        following = argv[index + 1] if index + 1 < len(argv) else ""
        if arg in NEGATIVE_VALUE_OPTIONS and _NUMBER_START.match(following):
            joined.append(f"{arg}={following}")
            index += 2
        else:
            joined.append(arg)
            index += 1
    return joined


class _BriefFormatter(logging.Formatter):
    """Log records as one ``navseq: message`` line; tracebacks only with --debug."""

    def __init__(self, debug: bool):
        super().__init__("navseq: %(message)s")
        self.debug = debug

    def format(self, record: logging.LogRecord) -> str:
        if not self.debug:
            record.exc_info = None
            record.exc_text = None
        return super().format(record)


def _configure_logging(debug: bool) -> None:
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(_BriefFormatter(debug))
    logging.basicConfig(level=logging.DEBUG if debug else logging.WARNING, handlers=[handler])


def main(argv: list[str] | None = None) -> int:
    """The ``navseq`` command; ``argv`` (default: the process's arguments) without
    the program name. Returns the exit status."""
    try:
        status = _main(argv)
    except KeyboardInterrupt:
        # Ctrl-C before the command took over (while Python imports what it needs):
        # nothing has moved yet, and a traceback would tell the user nothing.
        print("navseq: interrupted", file=sys.stderr)
        status = EXIT_SIGINT
    if argv is None:  # the process's own command: it exits next
        # Python's exit walks every object still alive looking for reference cycles,
        # 0.4 s after a 100 000-waypoint run; a signal gives the run 2 s to end.
        gc.freeze()
    return status


def _main(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(_attach_negative_values(sys.argv[1:] if argv is None else argv))
    if getattr(args, "command_module", None) is None:
        parser.print_help(sys.stderr)
        return EXIT_BAD_INPUT
    debug = getattr(args, "debug", False)
    # The process's own command: its exit follows the command's return, so a command may
    # leave its signal handling in place rather than reopen a window before the exit.
    args.exits_after_command = argv is None
    _configure_logging(debug)
    previous = {signum: signal.signal(signum, _raise_terminated) for signum in _TERMINATING}
    try:
        return args.command_module.run(args)
    except NavseqError as error:
        print(f"navseq {args.command}: {error_text(error)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"navseq {args.command}: interrupted", file=sys.stderr)
        return EXIT_SIGINT
    except Terminated as terminated:
        print(f"navseq {args.command}: terminated ({terminated.signal_name})", file=sys.stderr)
        return 128 + signal.Signals[terminated.signal_name].value
    except BrokenPipeError:
        # The reader of our output went away (`navseq run ... | head`): stop quietly,
        # as a process killed by SIGPIPE would, and keep Python from complaining
        # about the unflushable stdout at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_SIGPIPE
    except Exception as error:
        if debug:
            traceback.print_exc()
        print(
            f"navseq {args.command}: internal error: {type(error).__name__}: "
            f"{printable(str(error))}"
            + ("" if debug else " (run again with --debug to see the traceback)"),
            file=sys.stderr,
        )
        return EXIT_INTERNAL_ERROR
    finally:
        if args.exits_after_command:
            ignore_until_exit()
        else:
            for signum, handler in previous.items():
                signal.signal(signum, handler)


if __name__ == "__main__":
    sys.exit(main())
