"""The mission picture (PNG): ``draw`` puts it together from its helpers ``view``,
``marks``, ``labels``, ``thin``, ``legend`` and ``style``.

Nothing is imported here, so that reading a style constant does not load matplotlib.
"""
