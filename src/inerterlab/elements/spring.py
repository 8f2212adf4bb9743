"""Linear spring: F = k (x_top - x_bottom); with free play (backlash), see backlash.py."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numba as nb

from ._base import SPRING, ElementBase, Param

__all__ = ["Spring", "spring_force", "spring_switch"]


@nb.njit(cache=True, inline='always')
def spring_force(tab, o, x):
    """F [N] at relative displacement x [m]: k x, or with a half play g = row[1] > 0
    (:class:`~inerterlab.elements.backlash.Backlash`) k (x - g) beyond +g, k (x + g)
    beyond -g and 0 between."""
    k = tab[o]
    g = tab[o + 1]
    if g == 0.0:
        return k * x
    if x > g:
        return k * (x - g)
    if x < -g:
        return k * (x + g)
    return 0.0


@nb.njit(cache=True, inline="always")
def spring_switch(tab, o, x):
    """Switching function of the force law at relative displacement x [m]: |x| - g,
    changing sign where a spring with free play makes or breaks contact; 1 (never)
    without play."""
    g = tab[o + 1]
    return abs(x) - g if g > 0.0 else 1.0


@dataclass(frozen=True, kw_only=True)
class Spring(ElementBase):
    """Linear spring of stiffness ``stiffness`` k [N/m] > 0; admittance k/s."""

    stiffness: float

    prefix = "k"
    description = "linear spring"
    ROLE = "elastic"
    EXAMPLE = {"stiffness": 5e4}
    ADMITTANCE = -1
    PARAMETERS = (Param("stiffness", "N/m", design=(1e3, 1e7)),)
    code = SPRING

    def row(self):
        return self._row(self.stiffness)

    is_linear = True

    def scaled(self, factor):
        return dataclasses.replace(self, stiffness=self.stiffness * factor)

    def rest_network(self):
        return "k", {"k": self.stiffness}
