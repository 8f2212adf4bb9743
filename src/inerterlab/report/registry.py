"""Result types shared by the chapter modules of the reproduction report."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True, kw_only=True)
class ReproduceSettings:
    """Settings of one reproduction run.

    Parameters
    ----------
    quick : bool
        Reduced grids and horizons so the whole run takes seconds (used by tests);
        every table says in its settings which reductions were applied.
    workers : int
        Worker processes for sweeps (1 = serial).
    """

    quick: bool = False
    workers: int = 1


@dataclass(kw_only=True)
class TableResult:
    """One thesis table regenerated.

    Attributes
    ----------
    table_id : str
        Thesis table number, e.g. "4.1".
    title : str
        What the table shows.
    frame : pandas.DataFrame
        Our values beside the thesis's: for every quantity a ``<name>_ours``,
        ``<name>_thesis`` and ``<name>_diff`` column (diff = ours - thesis, or relative
        where the column says so).
    claim : str
        The thesis's qualitative claim for this table, in our words.
    claim_holds : bool or None
        Whether the claim holds in our physics (None if it cannot be judged).
    reason : str
        Why not, or what differs, in a sentence or two.
    settings : dict
        Every setting used (horizon, input shape, inertia law, ...), written into the
        CSV header.
    units : dict
        Unit of a column whose name does not carry it (shown in the report's column
        headers and the CSV header); columns not listed get the unit their name implies
        (:func:`inerterlab.report.build.column_unit`).
    """

    table_id: str
    title: str
    frame: Any
    claim: str = ""
    claim_holds: bool | None = None
    reason: str = ""
    settings: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)


@dataclass(kw_only=True)
class FigureResult:
    """One thesis figure regenerated: a matplotlib figure and the data behind it.

    Attributes
    ----------
    caption : str
        What the figure shows, with the numbers read from ``data`` (never a statement
        the data do not support).
    statement : str
        The thesis's statement the figure bears on, in our words ("" for a figure of
        ours that the thesis does not have).
    verdict : str
        One line computed from the data: what they show against ``statement``.
    holds : bool or None
        Whether the data support ``statement`` (None where there is nothing to judge).
    """

    figure_id: str
    title: str
    figure: Any
    data: Any  # pandas.DataFrame
    caption: str = ""
    statement: str = ""
    verdict: str = ""
    holds: bool | None = None


TableFn = Callable[[ReproduceSettings], TableResult]
FigureFn = Callable[[ReproduceSettings], FigureResult]
