"""Linear spring: F = k (x_top - x_bottom)."""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb

from ._base import SPRING, ElementBase, Param

__all__ = ["Spring", "spring_force"]


@nb.njit(cache=True)
def spring_force(row, x):
    """F [N] at relative displacement x [m]."""
    return row[0] * x


@dataclass(frozen=True, kw_only=True)
class Spring(ElementBase):
    """Linear spring of stiffness ``stiffness`` k [N/m] > 0; admittance k/s."""

    stiffness: float

    prefix = "k"
    description = "linear spring"
    PARAMETERS = (Param("stiffness", "N/m"),)
    code = SPRING

    def row(self):
        return self._row(self.stiffness)

    def linear(self):
        return ("k", self.stiffness)
