"""Shared pytest fixtures. ROS tests are skipped where their ROS is missing.

Marker ``ros``: needs ROS 1 (Debian's packages). Marker ``ros2``: needs ROS 2 (see
``ros2_support``).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ros2_support import ros2_available
from ros_support import RosMaster, rospy_available, running_master

ROS_AVAILABLE, ROS_MISSING_REASON = rospy_available()


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    # Tests against real ROS run several processes in real time on a 2-core machine; one
    # in a few full runs, one of them misses a timing window (a different one each time).
    # Each gets one rerun; a test that fails twice fails. Non-ROS tests never rerun.
    for item in items:
        if ("ros" in item.keywords or "ros2" in item.keywords) and not item.get_closest_marker(
            "flaky"
        ):
            item.add_marker(pytest.mark.flaky(reruns=1))
    if not ROS_AVAILABLE:
        skip = pytest.mark.skip(reason=f"ROS 1 not available: {ROS_MISSING_REASON}")
        for item in items:
            if "ros" in item.keywords:
                item.add_marker(skip)
    if any("ros2" in item.keywords for item in items):
        # Probing starts a process: only when a ros2 test was collected.
        available, reason = ros2_available()
        if not available:
            skip = pytest.mark.skip(reason=f"ROS 2 not available: {reason}")
            for item in items:
                if "ros2" in item.keywords:
                    item.add_marker(skip)


# A module whose ROS or browser tests share processes through a module-scoped fixture (a
# real Nav2 bringup, a Chromium): spread over xdist workers, each worker would start its
# own (four Nav2 bringups on two cores).
_SHARED_FIXTURE = re.compile(r"@pytest\.fixture\(scope=\"module\"")
_ROS_OR_BROWSER = re.compile(r"pytest\.mark\.(ros|ros2|browser)\b")


@pytest.hookimpl(tryfirst=True, optionalhook=True)  # before xdist's own schedulers
def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """``--dist loadgroup`` (``make test``): every test is a unit of work of its own,
    except that a module sharing processes (see above) is one unit, run on one worker and
    handed out first (the biggest units first: no long module starts last).

    xdist's own loadgroup reads ``xdist_group`` marks from test ids it suffixes, which
    pytest 9 no longer lets it change; and the controller process collects nothing, so
    which modules share processes is read from their source."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    shared: dict[str, bool] = {}

    def shares_processes(module: str) -> bool:
        if module not in shared:
            try:
                source = (config.rootpath / module).read_text()
            except OSError:
                source = ""
            shared[module] = bool(_SHARED_FIXTURE.search(source)) and bool(
                _ROS_OR_BROWSER.search(source)
            )
        return shared[module]

    class SharedModuleScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            module = nodeid.split("::", 1)[0]
            return module if shares_processes(module) else nodeid

    return SharedModuleScheduling(config, log)


@pytest.fixture
def ros_master(tmp_path: Path) -> Iterator[RosMaster]:
    """A private rosmaster on a free 127.0.0.1 port; everything started on it is stopped."""
    if not ROS_AVAILABLE:
        pytest.skip(f"ROS 1 not available: {ROS_MISSING_REASON}")
    with running_master(tmp_path / "ros") as master:
        yield master
