"""The ``navseq`` subcommands, one module each, listed in :data:`SUBCOMMANDS`.

A subcommand module provides two functions:

- ``configure(parser: argparse.ArgumentParser) -> None`` adds its arguments;
- ``run(args: argparse.Namespace) -> int`` does the work and returns the exit status.

Modules are imported when the parser is built, so they must import only light
things at module level (argparse, pathlib) and import the heavy machinery (the
simulator, matplotlib, rospy) inside ``run``. Adding a subcommand is one module
plus one line in :data:`SUBCOMMANDS`.
"""

from __future__ import annotations

import argparse
import importlib
from dataclasses import dataclass
from typing import Protocol, cast


class CommandModule(Protocol):
    def configure(self, parser: argparse.ArgumentParser) -> None: ...

    def run(self, args: argparse.Namespace) -> int: ...


@dataclass(frozen=True)
class Subcommand:
    """One ``navseq NAME ...`` command: its name, one-line summary and module."""

    name: str
    summary: str
    module: str

    def load(self) -> CommandModule:
        return cast(CommandModule, importlib.import_module(self.module))


SUBCOMMANDS: tuple[Subcommand, ...] = (
    Subcommand("run", "run a mission (embedded simulator by default)", "navseq.commands.run"),
    Subcommand(
        "validate",
        "list every problem of a mission file (and against a map)",
        "navseq.commands.validate",
    ),
    Subcommand(
        "report",
        "rebuild a run's report and picture from its journal",
        "navseq.commands.report",
    ),
    Subcommand(
        "convert",
        "write any supported mission format as navseq YAML",
        "navseq.commands.convert",
    ),
    Subcommand(
        "plan",
        "plan a mission's legs on the map, and find the order that drives the least",
        "navseq.commands.plan",
    ),
    Subcommand(
        "sim",
        "run the simulated robot and its navigation stand-in as ROS nodes "
        "(--ros1: move_base; --ros2: Nav2)",
        "navseq.commands.sim",
    ),
    Subcommand(
        "studio", "make, check and run missions on the map in a browser", "navseq.commands.studio"
    ),
    Subcommand(
        "record",
        "record waypoints from RViz goals (or a pose topic) into a mission file (ROS 1)",
        "navseq.commands.record",
    ),
)
