"""A tiny mission runner for subprocess tests (signals, kill -9 and resume).

    python helpers_mission_script.py MISSION.json CALLS.jsonl [--journal J] [--resume]
                                     [--realtime F]

``MISSION.json`` is ``{"count": N, "speed": v}``: N waypoints 1 m apart, driven by a
:class:`ScriptedNavigator` at v m/s, in wall time scaled by ``--realtime`` (simulated
seconds per wall second; omitted: as fast as possible). Every navigator call is
appended to ``CALLS.jsonl``. The script exits like the CLI will: 0 when every
waypoint was reached, 1 otherwise, 2 on a user error, 130/143 on SIGINT/SIGTERM; it
prints the result as JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from helpers_executor import line_mission
from navseq.errors import NavseqError
from navseq.executor import MissionInterrupted, MissionResult, run_mission
from navseq.journal.writer import JournalWriter, mission_digest, read_journal, resume_point
from navseq.navigators.scripted import ScriptedNavigator


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("mission", type=Path)
    parser.add_argument("calls", type=Path)
    parser.add_argument("--journal", type=Path)
    parser.add_argument("--resume", action="store_true")
    parser.add_argument("--realtime", type=float)
    args = parser.parse_args()

    settings = json.loads(args.mission.read_text())
    mission = line_mission(int(settings["count"]))
    navigator = ScriptedNavigator(
        speed=float(settings.get("speed", 1.0)), realtime=args.realtime, log_path=args.calls
    )
    listeners = []
    point = None
    try:
        if args.journal is not None:
            digest = mission_digest(args.mission)
            if args.resume:
                point = resume_point(read_journal(args.journal), mission_digest=digest)
                listeners.append(JournalWriter.resume(args.journal, point))
            else:
                listeners.append(JournalWriter(args.journal, str(args.mission), digest))
        result = run_mission(mission, navigator, listeners, resume=point)
    except NavseqError as error:
        print(f"navseq: {error}", file=sys.stderr)
        return 2
    except MissionInterrupted as interrupted:
        report(interrupted.result)
        return interrupted.exit_code
    report(result)
    return result.exit_code


def report(result: MissionResult) -> None:
    print(json.dumps(result.to_dict()), flush=True)


if __name__ == "__main__":
    sys.exit(main())
