"""The mission journal: the append-only record of a run that a resume, a rebuilt report
and a replay read back.

``writer`` is the mission listener that writes it, ``path`` thins the driven path it
keeps, ``format`` is the line format and its chain, ``reader`` streams the lines with a
per-line limit and ``state`` folds them into a bounded state and finds the resume point.
"""
