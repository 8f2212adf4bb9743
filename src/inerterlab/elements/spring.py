"""Linear spring: F = k (x_top - x_bottom); with free play (backlash), see backlash.py.

The spring kernel row is shared by every elastic element: [0] stiffness (at rest, or
about the operating point), [1] half play (backlash) or clearance (bump stop), [2] law
(0 linear or backlash, 1 gas spring, 2 bump stop), and for laws 1 and 2 [3] the
operating point y0 [m] and [4] the force there [N] (the force is F(y0 + x) - F(y0)),
then the law's own numbers."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numba as nb

from ._base import SPRING, ElementBase, ForceLaw, Param
from .bump_stop import BUMP_LAW, bump_force
from .gas_spring import GAS_LAW, gas_force

__all__ = ["Spring", "SpringLaw", "spring_force", "spring_slope", "spring_switch"]


@nb.njit(cache=True, inline='always')
def spring_force(tab, o, x):
    """F [N] at relative displacement x [m]: k x, or with a half play g = row[1] > 0
    (:class:`~inerterlab.elements.backlash.Backlash`) k (x - g) beyond +g, k (x + g)
    beyond -g and 0 between; the gas spring's and the bump stop's laws by row[2]."""
    k = tab[o]
    g = tab[o + 1]
    law = tab[o + 2]
    if law == GAS_LAW:
        return gas_force(tab, o, x + tab[o + 3]) - tab[o + 4]
    if law == BUMP_LAW:
        return bump_force(tab, o, x + tab[o + 3]) - tab[o + 4]
    if g == 0.0:
        return k * x
    if x > g:
        return k * (x - g)
    if x < -g:
        return k * (x + g)
    return 0.0


@nb.njit(cache=True, inline="always")
def spring_slope(tab, o, x):
    """dF/dx [N/m] at relative displacement x [m]: k, or 0 inside a free play; the gas
    spring's and the bump stop's by a central difference of their law."""
    law = tab[o + 2]
    if law == GAS_LAW or law == BUMP_LAW:
        h = 1e-7 * max(abs(x + tab[o + 3]), 1e-3)
        return (spring_force(tab, o, x + h) - spring_force(tab, o, x - h)) / (2.0 * h)
    g = tab[o + 1]
    if g == 0.0 or abs(x) > g:
        return tab[o]
    return 0.0


@nb.njit(cache=True, inline="always")
def spring_switch(tab, o, x):
    """Switching function of the force law at relative displacement x [m]: |x| - g,
    changing sign where a spring with free play makes or breaks contact (a bump stop:
    x + y0 + s, at its contact); 1 (never) without play or clearance."""
    g = tab[o + 1]
    if g <= 0.0:
        return 1.0
    if tab[o + 2] == BUMP_LAW:
        return x + tab[o + 3] + g
    return abs(x) - g


class SpringLaw(ForceLaw):
    """The elastic row (springs, backlash, gas springs, bump stops): k_eq on its own law,
    the quadrature split at a free play's ends and at a bump stop's contact; the
    equivalent a linear spring row."""

    code = SPRING
    argument = "displacement"
    elastic = True

    @classmethod
    def force_law(cls, row):
        if row[2] == BUMP_LAW:
            kinks = (-(row[3] + row[1]),)  # the contact (spring_switch)
        elif cls.free_play(row):
            kinks = (row[1], -row[1])  # a free play's ends
        else:
            kinks = ()
        return (lambda y: spring_force(row, 0, y)), kinks

    @classmethod
    def slope_at_rest(cls, row) -> float:
        return spring_slope(row, 0, 0.0)

    @classmethod
    def free_play(cls, row) -> bool:
        return row[2] != GAS_LAW and row[2] != BUMP_LAW and row[1] > 0.0


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
