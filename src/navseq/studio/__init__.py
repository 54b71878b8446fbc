"""navseq studio: make, check and watch missions in the browser (``navseq studio``).

A thin face over navseq's core, like the CLI: the mission loader, validation and
pre-flight (``navseq validate --map``), the planner, the mission writer and ``navseq
run``'s own setup and outputs do the work; the studio only translates HTTP and JSON.

- :mod:`~navseq.studio.security`: the token every request needs, and the folders
  files may be read from and written to;
- :mod:`~navseq.studio.documents`: a mission as a JSON document, and a draft checked
  and planned as ``navseq validate`` would;
- :mod:`~navseq.studio.mapview`: the map and the inflated costmap as PNG images;
- :mod:`~navseq.studio.runs`: a mission run on the simulator in a thread, watched live;
- :mod:`~navseq.studio.fleet_runs`: a fleet run (``navseq run --fleet``'s) in a thread,
  watched live; :mod:`~navseq.studio.fleet_replay`: a fleet run folder replayed on the
  fleet's one clock; :mod:`~navseq.studio.fleet_api`: their endpoints;
- :mod:`~navseq.studio.http`: the 4xx answers, JSON bodies and limits every endpoint shares;
- :mod:`~navseq.studio.app`: the HTTP API (docs/studio.md) and the static page;
- :mod:`~navseq.studio.server`: serving it with uvicorn until Ctrl-C.

Nothing here imports ROS.
"""
