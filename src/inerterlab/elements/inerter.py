"""Ideal inerter: F = b (a_top - a_bottom) [S02]."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numba as nb

from ._base import INERTER, ElementBase, KernelLaw, Param

__all__ = ["Inerter", "InerterLaw", "inerter_inertance"]


@nb.njit(cache=True, error_model="numpy")
def inerter_inertance(tab, o):
    """b [kg]: F = b (a_top - a_bottom)."""
    return tab[o]


class InerterLaw(KernelLaw):
    """The ideal inerter's row: linear, it keeps its law."""

    code = INERTER
    argument = "acceleration"
    inertial = True

    @classmethod
    def nominal_inertance(cls, element) -> float:
        return element.inertance

    @classmethod
    def gaussian_keeps(cls, row) -> bool:
        return True


@dataclass(frozen=True, kw_only=True)
class Inerter(ElementBase):
    """Ideal inerter of inertance ``inertance`` b [kg] > 0; admittance b s."""

    inertance: float

    prefix = "b"
    description = "ideal inerter"
    ROLE = "inertial"
    EXAMPLE = {"inertance": 200.0}
    ADMITTANCE = 1
    PARAMETERS = (Param("inertance", "kg", design=(0.1, 2000.0)),)
    code = INERTER

    def row(self):
        return self._row(self.inertance)

    is_linear = True

    def scaled(self, factor):
        return dataclasses.replace(self, inertance=self.inertance * factor)

    def rest_network(self):
        return "b", {"b": self.inertance}
