"""Ideal inerter: F = b (a_top - a_bottom) [S02]."""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb

from ._base import INERTER, ElementBase, Param

__all__ = ["Inerter", "inerter_inertance"]


@nb.njit(cache=True)
def inerter_inertance(tab, o):
    """b [kg]: F = b (a_top - a_bottom)."""
    return tab[o]


@dataclass(frozen=True, kw_only=True)
class Inerter(ElementBase):
    """Ideal inerter of inertance ``inertance`` b [kg] > 0; admittance b s."""

    inertance: float

    prefix = "b"
    description = "ideal inerter"
    PARAMETERS = (Param("inertance", "kg"),)
    code = INERTER

    def row(self):
        return self._row(self.inertance)

    def linear(self):
        return ("b", self.inertance)
