"""A mission run as one typed service, the same for every face.

::

    from navseq.run import Outputs, RunRequest, prepare

    session = prepare(RunRequest(Path("patrol.yaml"), outputs=Outputs(Path("out"))))
    outcome = session.run([my_listener])
    print(outcome.exit_status, outcome.report_path)

The CLI, the Python API, the studio and the ROS nodes each build a
:class:`~navseq.run.request.RunRequest` (mission, navigator kind and its typed settings
or a navigator of their own, outputs, resume point, pace), :func:`~navseq.run.session.prepare`
checks it and makes the navigator ready (raising :class:`~navseq.errors.NavseqError`
before anything moves or is written), and :meth:`~navseq.run.session.Session.run` runs
it with the face's listeners and returns a :class:`~navseq.run.outcome.RunOutcome`.

The modules, one concern each:

- :mod:`~navseq.run.request`: what a face asks for, checked on creation;
- :mod:`~navseq.run.session`: prepare and run;
- :mod:`~navseq.run.resume`: the journal's rules (continue as started, or refuse);
- :mod:`~navseq.run.runlock`: one live run per output folder;
- :mod:`~navseq.run.folder`: the output folder and its new files' names;
- :mod:`~navseq.run.files`: the report and picture written whole, in order;
- :mod:`~navseq.run.products`: what the report and picture say;
- :mod:`~navseq.run.outcome`: how a run ended;
- :mod:`~navseq.run.values`: option values written as text (pose, loops, pace).
"""

from __future__ import annotations

from navseq.run.outcome import RunOutcome
from navseq.run.request import Outputs, RunRequest, UseNavigator
from navseq.run.session import Session, prepare

__all__ = [
    "Outputs",
    "RunOutcome",
    "RunRequest",
    "Session",
    "UseNavigator",
    "prepare",
]
