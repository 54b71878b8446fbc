"""Build hook shared by pip and catkin; project metadata lives in pyproject.toml.

- pip: builds the one optional C extension, ``navseq.sim._astar`` (the global
  planner's A* search). ``optional=True``: without a C compiler the install still
  succeeds and the planner falls back on its pure-Python search (same plans, slower).
- catkin: ``catkin_python_setup()`` in CMakeLists.txt reads ``packages`` and
  ``package_dir`` from this call to install the ``navseq`` Python package into the
  workspace (it ignores the extension, so catkin installs use the Python search).
"""

from setuptools import Extension, find_packages, setup

setup(
    packages=find_packages("src"),
    package_dir={"": "src"},
    ext_modules=[
        Extension(
            "navseq.sim._astar",
            sources=["src/navseq/sim/_astar.c"],
            extra_compile_args=["-O3"],
            optional=True,
        )
    ],
)
