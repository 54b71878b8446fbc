"""docs/cli.md documents exactly the options ``navseq --help`` offers.

The options are read from the parsers themselves (``navseq.cli.build_parser``, every
subcommand's actions), so a new option, a renamed one or a new choice fails here until
the page says it. A subcommand's section is its ``### `navseq NAME ...``` heading up to
the next heading; the options it documents are the ones in that heading and in the
first column of its tables.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

import pytest

from navseq.cli import build_parser

REPO = Path(__file__).resolve().parents[1]
CLI_DOC = REPO / "docs" / "cli.md"
OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")
# Every subcommand has --help and --debug (the page says so once, for all of them).
COMMON = {"--help", "--debug"}


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    raise AssertionError("navseq has no subcommands")


def _shown(parser: argparse.ArgumentParser) -> dict[str, argparse.Action]:
    """The long options ``--help`` shows (hidden test-only ones left out), by name."""
    return {
        name: action
        for action in parser._actions
        if action.help != argparse.SUPPRESS
        for name in action.option_strings
        if name.startswith("--")
    }


def _sections(text: str) -> dict[str, str]:
    """Each subcommand's section of the page: heading and body, by subcommand name."""
    sections: dict[str, str] = {}
    parts = re.split(r"^(?=#{1,3} )", text, flags=re.MULTILINE)
    for part in parts:
        match = re.match(r"### `navseq (\w+)", part)
        if match:
            sections[match.group(1)] = part
    return sections


def _documented(section: str) -> dict[str, str]:
    """The options a section documents, each with the text that describes its value."""
    heading, _, body = section.partition("\n")
    documented = {name: heading for name in OPTION.findall(heading)}
    for row in re.findall(r"^\| `([^|]*(?:\\\|[^|]*)*)` \|", body, flags=re.MULTILINE):
        for name in OPTION.findall(row):
            documented[name] = row
    return documented


PARSER = build_parser()
SUBCOMMANDS = _subparsers(PARSER)
SECTIONS = _sections(CLI_DOC.read_text(encoding="utf-8"))


def test_every_subcommand_has_a_section() -> None:
    assert sorted(SECTIONS) == sorted(SUBCOMMANDS)


@pytest.mark.parametrize("name", sorted(SUBCOMMANDS))
def test_the_section_documents_every_option_and_no_other(name: str) -> None:
    shown = set(_shown(SUBCOMMANDS[name])) - COMMON
    documented = set(_documented(SECTIONS[name]))
    assert shown - documented == set(), f"docs/cli.md's `navseq {name}` lacks these options"
    assert documented - shown == set(), f"`navseq {name}` has no such options"


def _values_shown(action: argparse.Action) -> list[str]:
    """The values ``--help`` lists for an option: ``{sim,ros1,nav2}``, ``auto|true|false``."""
    metavar = action.metavar if isinstance(action.metavar, str) else None
    if metavar is None:
        return [str(choice) for choice in action.choices or ()]
    if "|" in metavar or metavar.startswith("{"):
        return [word for word in re.split(r"[{},|\[\]]", metavar) if word]
    return []


@pytest.mark.parametrize("name", sorted(SUBCOMMANDS))
def test_every_value_help_lists_for_an_option_is_named(name: str) -> None:
    documented = _documented(SECTIONS[name])
    for option, action in _shown(SUBCOMMANDS[name]).items():
        for value in _values_shown(action):
            assert re.search(rf"\b{re.escape(value)}\b", documented.get(option, "")), (
                f"docs/cli.md: `navseq {name} {option}` does not name the value {value!r}"
            )


def test_every_option_the_page_names_exists() -> None:
    text = CLI_DOC.read_text(encoding="utf-8")
    text = re.sub(r"\]\([^)]*\)", "]", text)  # link targets: anchors spell options too
    known = set(_shown(PARSER)) | {n for sub in SUBCOMMANDS.values() for n in _shown(sub)}
    assert set(OPTION.findall(text)) - known == set()


def test_the_global_options_are_documented() -> None:
    text = CLI_DOC.read_text(encoding="utf-8")
    for option in set(_shown(PARSER)) - {"--help"}:
        assert f"{option}" in text


def test_convert_help_says_a_launch_output_is_the_tutorials_launch_file() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "navseq", "convert", "--help"],
        capture_output=True,
        text=True,
        check=True,
    )
    text = " ".join(done.stdout.split())
    assert ".launch, the tutorial's launch file" in text
    assert "p_seq / yea_seq" in text


def test_the_schema_versions_the_docs_name_are_the_ones_written() -> None:
    import json

    from navseq.sinks import json_events, report

    readme = (REPO / "README.md").read_text(encoding="utf-8")
    assert re.findall(r"`report\.json` \(schema (\d+)\)", readme) == [str(report.SCHEMA_VERSION)]
    schema = json.loads((REPO / "docs/schemas/report.schema.json").read_text())
    assert schema["properties"]["schema_version"]["const"] == report.SCHEMA_VERSION
    events = re.findall(r'\{"event": "<type>", "schema_version": (\d+)', CLI_DOC.read_text())
    assert events == [str(json_events.SCHEMA_VERSION)]


def test_every_exit_status_of_the_cli_is_in_the_readme_and_cli_md() -> None:
    import navseq.cli as cli

    statuses = {value for name, value in vars(cli).items() if name.startswith("EXIT_")}
    statuses |= {128 + 1}  # SIGHUP ends a run like SIGTERM (cli._TERMINATING)
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    sentence = re.search(r"Exit status: (.*?)\n\n", readme, flags=re.S)
    assert sentence is not None
    in_readme = {int(n) for n in re.findall(r"\b(\d+)\b", sentence.group(1))}
    in_cli_md = {int(n) for n in re.findall(r"^\| (\d+) \|", CLI_DOC.read_text(), re.M)}
    assert statuses <= in_cli_md
    # The README's short list leaves out only a reader that went away (`| head`).
    assert statuses - {cli.EXIT_SIGPIPE} <= in_readme
