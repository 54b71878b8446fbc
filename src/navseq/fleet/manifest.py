"""A fleet run folder's ``fleet-run.json``: what ``navseq run --fleet --resume`` needs.

Written when a fleet run starts, before any robot moves: the fleet file (path and
sha256, so a resume with another or a changed fleet file is refused), the mission and
map the run used, the navigator kind (``sim``, ``nav2``, ``ros1``), and the split
(each robot's waypoints, the planned makespan, the waypoints left out), so that a
resume continues the same split instead of making a new one. Each robot's own
progress is in its journal (``RUN/<robot>/journal.jsonl``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError
from navseq.fleet.model import Fleet
from navseq.fleet.split import Share, Split

if TYPE_CHECKING:
    from navseq.fleet.recording import FleetRecordingChoice

MANIFEST_NAME = "fleet-run.json"
MANIFEST_VERSION = 1


@dataclass(frozen=True)
class FleetManifest:
    """A fleet run as started: its fleet file and digest, mission, map and split."""

    fleet: Path
    fleet_sha256: str
    mission: Path | None  # None: the fleet file's mission:
    map: Path | None  # None: the fleet file's map:
    shares: dict[str, tuple[tuple[int, ...], float, float]]  # robot: order, metres, seconds
    dropped: tuple[int, ...]
    navigator: str = "sim"  # the kind the robots ran on: sim (one world), nav2, ros1
    # Whether the run is recorded (fleet.mcap), and its encoding: a resume records too.
    record: bool = False
    record_format: str = "ros2"

    def with_navigator(self, kind: str) -> FleetManifest:
        """This manifest for a run on ``kind``'s stacks (a resume runs on the same kind)."""
        import dataclasses

        return dataclasses.replace(self, navigator=kind)

    def with_recording(self, choice: FleetRecordingChoice) -> FleetManifest:
        """This manifest for a run recorded (or not) as ``choice`` says."""
        import dataclasses

        return dataclasses.replace(self, record=choice.record, record_format=choice.record_format)

    @property
    def recording(self) -> FleetRecordingChoice:
        """Whether the run was recorded, and how (for its resume)."""
        from navseq.fleet.recording import FleetRecordingChoice

        return FleetRecordingChoice(self.record, "ros1" if self.record_format == "ros1" else "ros2")

    def split(self, fleet: Fleet) -> Split:
        """The run's split, for ``fleet`` (the same fleet file, checked by its digest)."""
        shares = []
        for robot in fleet.robots:
            order, distance_m, time_s = self.shares.get(robot.name, ((), 0.0, 0.0))
            shares.append(Share(robot, order, distance_m, time_s))
        return Split(tuple(shares), self.dropped)

    def to_json(self) -> dict[str, Any]:
        return {
            "navseq_fleet_run": MANIFEST_VERSION,
            "fleet": str(self.fleet),
            "fleet_sha256": self.fleet_sha256,
            "mission": None if self.mission is None else str(self.mission),
            "map": None if self.map is None else str(self.map),
            "shares": {
                name: {"order": list(order), "distance_m": distance, "time_s": time_s}
                for name, (order, distance, time_s) in self.shares.items()
            },
            "dropped": list(self.dropped),
            "navigator": self.navigator,
            "record": self.record,
            "record_format": self.record_format,
        }


def file_digest(path: Path) -> str:
    import hashlib

    return hashlib.sha256(path.read_bytes()).hexdigest()


def manifest_of(
    fleet_path: Path, mission: Path | None, map_path: Path | None, split: Split
) -> FleetManifest:
    """The manifest of a run starting now with this fleet file and split."""
    return FleetManifest(
        fleet=fleet_path.resolve(),
        fleet_sha256=file_digest(fleet_path),
        mission=None if mission is None else mission.resolve(),
        map=None if map_path is None else map_path.resolve(),
        shares={
            share.robot.name: (tuple(share.order), share.distance_m, share.time_s)
            for share in split.shares
        },
        dropped=tuple(split.dropped),
    )


def write_manifest(folder: Path, manifest: FleetManifest) -> None:
    from navseq.files import write_atomically

    text = json.dumps(manifest.to_json(), indent=2) + "\n"
    write_atomically(folder / MANIFEST_NAME, text.encode())


def read_manifest(folder: Path) -> FleetManifest:
    """The manifest of the fleet run in ``folder``, or one NavseqError saying what is wrong."""
    path = folder / MANIFEST_NAME
    if not folder.is_dir():
        raise NavseqError(
            "is not a folder; give the run folder of the fleet run to continue "
            "(the one holding fleet-run.json)",
            source=str(folder),
        )
    if not path.is_file():
        raise NavseqError(
            f"is not a fleet run folder: it has no {MANIFEST_NAME} (written when a fleet "
            "run starts); give the folder of navseq run --fleet's run",
            source=str(folder),
        )
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        if doc.get("navseq_fleet_run") != MANIFEST_VERSION:
            raise ValueError(f"navseq_fleet_run is {doc.get('navseq_fleet_run')!r}")
        shares = {
            str(name): (
                tuple(int(i) for i in share["order"]),
                float(share["distance_m"]),
                float(share["time_s"]),
            )
            for name, share in doc["shares"].items()
        }
        return FleetManifest(
            fleet=Path(doc["fleet"]),
            fleet_sha256=str(doc["fleet_sha256"]),
            mission=None if doc["mission"] is None else Path(doc["mission"]),
            map=None if doc["map"] is None else Path(doc["map"]),
            shares=shares,
            dropped=tuple(int(i) for i in doc["dropped"]),
            navigator=str(doc.get("navigator", "sim")),  # runs before stacks: the simulator
            # runs before recording: not recorded
            record=bool(doc.get("record", False)),
            record_format=str(doc.get("record_format", "ros2")),
        )
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as error:
        raise NavseqError(
            f"is damaged ({error}); the fleet run cannot be resumed from it", source=str(path)
        ) from None


__all__ = [
    "MANIFEST_NAME",
    "FleetManifest",
    "file_digest",
    "manifest_of",
    "read_manifest",
    "write_manifest",
]
