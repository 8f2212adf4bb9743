"""Result types shared by the chapter modules of the reproduction report."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

#: relative tolerance within which our values count as agreeing in magnitude with the
#: thesis's (the same 10 % the ride tables use for "about equal"); a table may state its own
MAGNITUDE_TOLERANCE = 0.10


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
    judges : str
        What ``claim_holds`` judges, completing "the verdict judges ..." (e.g. "the
        ordering of the suspensions at every mass and the trend with mass, not the
        values"); required when ``claim_holds`` is not None.
    reason : str
        Why not, or what differs, in a sentence or two.
    settings : dict
        Every setting used (horizon, input shape, inertia law, ...), written into the
        CSV header.
    units : dict
        Unit of a column whose name does not carry it (shown in the report's column
        headers and the CSV header); columns not listed get the unit their name implies
        (:func:`inerterlab.report.build.column_unit`).
    magnitude_tolerance : float
        Relative tolerance of the magnitude check: every value of ours against the
        thesis's printed counterpart (:func:`inerterlab.report.build.magnitude_check`);
        a disagreement beyond it is flagged beside the verdict.
    magnitude_pairs : dict, optional
        {our column: the thesis's column} for the magnitude check; by default the pairs
        ``<name>_ours`` / ``<name>_thesis``, ``ours`` / ``thesis`` and
        ``<name> ours [unit]`` / ``<name> thesis [unit]``.
    """

    table_id: str
    title: str
    frame: Any
    claim: str = ""
    claim_holds: bool | None = None
    reason: str = ""
    settings: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    judges: str = ""
    magnitude_tolerance: float = MAGNITUDE_TOLERANCE
    magnitude_pairs: dict | None = None

    def __post_init__(self) -> None:
        _require_judges(self.claim_holds, self.judges, f"table {self.table_id}")


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
    judges : str
        What ``holds`` judges (see :class:`TableResult`); required when ``holds`` is
        not None.
    """

    figure_id: str
    title: str
    figure: Any
    data: Any  # pandas.DataFrame
    caption: str = ""
    statement: str = ""
    verdict: str = ""
    holds: bool | None = None
    judges: str = ""

    def __post_init__(self) -> None:
        _require_judges(self.holds, self.judges, self.figure_id)


def _require_judges(verdict: bool | None, judges: str, what: str) -> None:
    """A verdict that does not say what it judges is refused."""
    if verdict is not None and not judges.strip():
        raise ValueError(f"{what}: a verdict needs 'judges' (what it judges)")


TableFn = Callable[[ReproduceSettings], TableResult]
FigureFn = Callable[[ReproduceSettings], FigureResult]
