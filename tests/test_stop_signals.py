"""A node kept up after its mission waits for SIGINT / SIGTERM, then puts the handlers back."""

from __future__ import annotations

import os
import signal

from navseq.signals import StopSignals


def test_a_signal_ends_the_wait_and_is_named() -> None:
    before = signal.getsignal(signal.SIGTERM)
    with StopSignals() as stop:
        assert stop.wait(0.01) is False  # nothing came: the wait times out
        os.kill(os.getpid(), signal.SIGTERM)  # would end the test process if not caught
        assert stop.wait(5.0) is True
    assert stop.received == ["SIGTERM"]
    assert signal.getsignal(signal.SIGTERM) is before
