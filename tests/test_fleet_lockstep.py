"""The fleet's clock: robots in threads of their own move only together, and a robot
whose run ends no longer holds the others up."""

from __future__ import annotations

import threading

import pytest

from navseq.fleet.lockstep import FleetClock


class CountingFleet:
    """A fleet stand-in: counts its steps; optionally fails at one."""

    dt = 0.05

    def __init__(self, fail_at: int | None = None) -> None:
        self.steps = 0
        self.fail_at = fail_at

    @property
    def now(self) -> float:
        return self.steps * self.dt

    def step(self) -> None:
        if self.steps == self.fail_at:
            raise ValueError("broken step")
        self.steps += 1


def run_members(clock: FleetClock, spins: dict[str, int]) -> dict[str, BaseException | None]:
    """Each member spins 0.1 s ``spins[name]`` times in its own thread, then leaves."""
    errors: dict[str, BaseException | None] = {}

    def member(name: str, count: int) -> None:
        errors[name] = None
        try:
            for _ in range(count):
                clock.advance(name, 0.1)
        except BaseException as error:
            errors[name] = error
        finally:
            try:
                clock.leave(name)
            except BaseException as error:
                errors[name] = errors[name] or error

    threads = [threading.Thread(target=member, args=item) for item in spins.items()]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=30)
        assert not thread.is_alive(), "a member is stuck"
    return errors


def test_members_move_together_and_one_that_leaves_holds_nobody_up() -> None:
    fleet = CountingFleet()
    seen: list[tuple[int, int]] = []
    clock = FleetClock(fleet, ["a", "b"])
    clock.on_step("a", lambda: seen.append((fleet.steps, 0)))
    errors = run_members(clock, {"a": 10, "b": 3})
    assert errors == {"a": None, "b": None}
    # 10 spins of 0.1 s at 0.05 s a step: a's 20 steps, 6 of them with b still in.
    assert fleet.steps == 20
    assert [step for step, _ in seen] == list(range(1, 21))


def test_a_failing_step_ends_every_member_instead_of_leaving_them_waiting() -> None:
    fleet = CountingFleet(fail_at=7)
    clock = FleetClock(fleet, ["a", "b", "c"])
    errors = run_members(clock, {"a": 10, "b": 10, "c": 10})
    assert all(errors[name] is not None for name in "abc")
    assert fleet.steps == 7


@pytest.mark.parametrize("members", [[], ["a"]])
def test_leaving_a_clock_nobody_waits_on_steps_nothing(members: list[str]) -> None:
    fleet = CountingFleet()
    clock = FleetClock(fleet, members)
    for name in members:
        clock.leave(name)
    assert fleet.steps == 0
