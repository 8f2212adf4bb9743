"""Damper: F = c v + c_2 v |v| (linear, with an optional quadratic term)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numba as nb

from ._base import DAMPER, ElementBase, ForceLaw, Param

__all__ = ["Damper", "DamperLaw", "damper_force"]


@nb.njit(cache=True, inline='always')
def damper_force(tab, o, v):
    """(F [N], dF/dv [N s/m]) at relative velocity v [m/s]. A row whose law code
    (row[2]) is 1 is an asymmetric damper (:mod:`.asymmetric_damper`): rate row[0]
    while extending (v > 0), row[3] while shortening."""
    if tab[o + 2] == 1.0:
        c = tab[o] if v > 0.0 else tab[o + 3]
        return c * v, c
    a = abs(v)
    c, c2 = tab[o], tab[o + 1]
    return c * v + c2 * v * a, c + 2.0 * c2 * a


class DamperLaw(ForceLaw):
    """The damper row (quadratic, asymmetric, bearing drag): c_eq on its own law; the
    equivalent a linear damper row."""

    code = DAMPER
    argument = "velocity"
    holds_velocity = True

    @classmethod
    def force_law(cls, row):
        return (lambda v: damper_force(row, 0, v)[0]), ()

    @classmethod
    def slope_at_rest(cls, row) -> float:
        return damper_force(row, 0, 0.0)[1]


@dataclass(frozen=True, kw_only=True)
class Damper(ElementBase):
    """Damper: ``damping`` c [N s/m] >= 0 and ``quadratic`` c_2 [N s^2/m^2] >= 0.

    F = c v + c_2 v |v| with v the relative velocity; linear (admittance c) when c_2 = 0.
    At least one coefficient must be positive.
    """

    damping: float
    quadratic: float = 0.0

    prefix = "c"
    description = "damper"
    ROLE = "dissipative"
    EXAMPLE = {"damping": 3e3, "quadratic": 1e3}
    ADMITTANCE = 0
    PARAMETERS = (
        Param("damping", "N s/m", low_open=False, design=(10.0, 1e5)),
        Param("quadratic", "N s^2/m^2", low_open=False),
    )
    code = DAMPER

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.damping == 0.0 and self.quadratic == 0.0:
            from ..errors import ParameterError

            raise ParameterError("damping", 0.0, "a value > 0 N s/m (or a quadratic term > 0)")

    def row(self):
        return self._row(self.damping, self.quadratic)

    def scaled(self, factor):
        return dataclasses.replace(
            self, damping=self.damping * factor, quadratic=self.quadratic * factor
        )

    @property
    def is_linear(self):
        return self.quadratic == 0.0

    def rest_network(self):
        """c: the quadratic term has no slope at rest (an open circuit if c = 0)."""
        return ("c", {"c": self.damping}) if self.damping > 0 else None
