"""navseq: send a sequence of navigation goals to a robot and see the mission through."""

__version__ = "0.1.0"
