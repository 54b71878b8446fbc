"""Tasks at waypoints, run outside the executor: ``runner`` does what ``StartTask`` and
``CancelTask`` ask, ``permissions`` says which tasks a run may start (``--allow-run``,
``--simulate-tasks``, the navigator kind), ``base`` is what the executor imports."""
