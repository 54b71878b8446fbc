"""Build hook shared by pip and catkin; pip's project metadata lives in pyproject.toml.

- pip: packages from ``src/`` plus two optional C extensions, ``navseq.sim._astar``
  (the global planner's A* search) and ``navseq.route._tour`` (the ordering's local
  search). ``optional=True``: without a C compiler the install still succeeds: the
  planner falls back on its pure-Python search (same plans, slower), the ordering on
  OR-tools' routing solver.
- catkin: ``catkin_python_setup()`` (CMakeLists.txt) runs this file through catkin's
  ``interrogate_setup_dot_py.py`` to learn where the package lives (devel space), and
  ``catkin_make install`` runs it for real with ``CATKIN_BINARY_DIR`` set. Catkin needs
  the name and version in the ``setup()`` call: they come from package.xml (keep its
  version equal to pyproject.toml's). Catkin installs use the pure-Python search and
  order with OR-tools.
"""

import os
import sys
from pathlib import Path

from setuptools import Extension, find_namespace_packages, setup

# Namespace discovery: the studio's static folders (no __init__.py) are packages of
# data files, so setuptools ships them without a "package would be ignored" warning.
PACKAGES = find_namespace_packages("src", include=["navseq", "navseq.*"])
PACKAGE_DIR = {"": "src"}


def _run_by_catkin() -> bool:
    # The interrogation runs this file with runpy from catkin's own script, which stays
    # the __main__ module; the install step sets CATKIN_BINARY_DIR.
    main_file = getattr(sys.modules.get("__main__"), "__file__", None) or ""
    interrogated = Path(main_file).name == "interrogate_setup_dot_py.py"
    return interrogated or "CATKIN_BINARY_DIR" in os.environ


if _run_by_catkin():
    from catkin_pkg.python_setup import generate_distutils_setup

    setup(
        **generate_distutils_setup(
            packages=PACKAGES,
            package_dir=PACKAGE_DIR,
            package_data={
                "navseq": ["py.typed"],
                # navseq run --record's message definitions (needs pip's mcap packages).
                "navseq.sinks.recording": [
                    "definitions/*.json",
                    "definitions/ros1/*.msg",
                    "definitions/ros2/*.msg",
                ],
            },
        )
    )
else:
    setup(
        # pyproject.toml lists license as dynamic (see the comment there).
        license="Apache-2.0",
        packages=PACKAGES,
        package_dir=PACKAGE_DIR,
        ext_modules=[
            Extension(
                "navseq.sim._astar",
                sources=["src/navseq/sim/_astar.c"],
                extra_compile_args=["-O3"],
                optional=True,
            ),
            Extension(
                "navseq.route._tour",
                sources=["src/navseq/route/_tour.c"],
                extra_compile_args=["-O3"],
                optional=True,
            ),
        ],
    )
