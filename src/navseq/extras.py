"""Optional capabilities installed as pip extras, and one clear error when one is missing.

A ROS node's install needs neither a web server nor a 30 MB route solver, so they are
extras: ``navseq[studio]`` (starlette, uvicorn, ruamel.yaml) for ``navseq studio`` and
``navseq[plan]`` (OR-tools) for the shortest visiting order; ``navseq[record]`` (mcap and
its ROS support) for ``navseq run --record``. Whatever needs one calls
:func:`require_extra` before it imports the modules, and the user reads which
``pip install`` brings them instead of a traceback.
"""

from __future__ import annotations

import importlib

from navseq.errors import NavseqError

#: Each extra's name (as in ``pip install 'navseq[NAME]'``) and the modules it brings.
EXTRAS: dict[str, tuple[str, ...]] = {
    "studio": ("starlette", "uvicorn", "ruamel.yaml"),
    "plan": ("ortools.constraint_solver.pywrapcp",),
    "record": ("mcap.writer", "mcap_ros2", "mcap_ros1"),
}


class MissingExtra(NavseqError):
    """An optional capability is asked for but its extra is not installed."""

    def __init__(self, message: str, extra: str):
        super().__init__(message)
        self.extra = extra


def require_extra(extra: str, what: str) -> None:
    """Raise :class:`MissingExtra` unless every module of ``extra`` imports.

    ``what`` names what needs it, as the message starts: ``"the studio"``.
    """
    missing: list[str] = []
    broken: list[str] = []
    for module in EXTRAS[extra]:
        package = module.split(".")[0]
        try:
            importlib.import_module(module)
        except ModuleNotFoundError as error:
            if (error.name or package).split(".")[0] != package:
                broken.append(f"{package}, which does not import ({error})")
            elif package not in missing:
                missing.append(package)
        except ImportError as error:  # installed but broken: a library or version clash
            broken.append(f"{package}, which does not import ({error})")
    parts = broken
    if missing:
        verb = "is" if len(missing) == 1 else "are"
        parts = [f"{' and '.join(missing)}, which {verb} not installed", *broken]
    if parts:
        raise MissingExtra(
            f"{what} needs {'; and '.join(parts)}: pip install 'navseq[{extra}]'", extra
        )


__all__ = ["EXTRAS", "MissingExtra", "require_extra"]
