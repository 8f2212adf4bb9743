"""Linear spring: F = k (x_top - x_bottom)."""

from __future__ import annotations

from dataclasses import dataclass

from ._base import SPRING, ElementBase, Param

__all__ = ["Spring"]


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
