"""Build hook for the one optional C extension; everything else is in pyproject.toml.

``navseq.sim._astar`` is the global planner's A* search. ``optional=True``: where
no C compiler is available the install still succeeds and the planner falls back
on its pure-Python search (same plans, slower).
"""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "navseq.sim._astar",
            sources=["src/navseq/sim/_astar.c"],
            extra_compile_args=["-O3"],
            optional=True,
        )
    ]
)
