"""Fleet files as hostile input: whatever a fleet file holds, reading it ends in a fleet
or in NavseqErrors naming where, never in another exception."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from navseq.errors import NavseqError
from navseq.fleet.fleet_format import inspect_fleet

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**6), 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=12,
)
robot = st.fixed_dictionaries(
    {},
    optional={
        "name": st.one_of(st.sampled_from(["a", "b", "a b", ""]), values),
        "namespace": st.one_of(st.sampled_from(["a", "/x/y", "1x"]), values),
        "start": st.one_of(
            st.fixed_dictionaries({"x": st.floats(-3, 3), "y": st.floats(-3, 3)}), values
        ),
        "robot": st.one_of(st.sampled_from(["turtlebot3_waffle", "nope"]), values),
        "max_time": values,
        "other": values,
    },
)
fleet_documents = st.fixed_dictionaries(
    {},
    optional={
        "navseq_fleet": st.one_of(st.just(1), values),
        "mission": st.one_of(st.just("turtlebot3_world.yaml"), values),
        "robots": st.one_of(st.lists(robot, max_size=4), values),
        "waypoints": st.one_of(
            st.dictionaries(
                st.sampled_from(["home", "1", "9", "x"]),
                st.one_of(st.fixed_dictionaries({"robots": st.lists(values)}), values),
                max_size=3,
            ),
            values,
        ),
        "map": values,
    },
)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(document=fleet_documents)
def test_any_fleet_file_reads_or_names_its_problems(
    document: dict, tmp_path_factory: pytest.TempPathFactory
) -> None:
    folder = tmp_path_factory.mktemp("fleet")
    (folder / "turtlebot3_world.yaml").write_text((EXAMPLES / "turtlebot3_world.yaml").read_text())
    path = folder / "fleet.yaml"
    path.write_text(yaml.safe_dump(document, allow_unicode=True))
    fleet, problems = inspect_fleet(path)
    assert all(isinstance(error, NavseqError) and str(error) for error in problems.errors)
    if not problems.errors:
        assert fleet is not None and fleet.robots
