"""Coulomb friction, regularised: F = F_c tanh(v / v_eps) (docs/model.md §3).

sgn(v) is replaced by tanh(v / v_eps) with the velocity scale v_eps (1e-3 m/s by
default, as the device models use), so the force is smooth and the result does not
depend on where an integrator puts its steps. A friction element cannot carry a force
larger than F_c: a massless node held only by friction and springs has no solution once
the springs pull harder, so the system builder refuses such a node (it needs a damper
or an inertance beside the friction).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from ._base import FRICTION, NPAR, ElementBase, ForceLaw, Param

__all__ = ["Friction", "FrictionLaw", "friction_force"]


@nb.njit(cache=True, inline='always')
def friction_force(force, v_eps, v):
    """(F, dF/dv) of the regularised friction at relative velocity v [m/s]."""
    th = math.tanh(v / v_eps)
    return force * th, force / v_eps * (1.0 - th * th)


class FrictionLaw(ForceLaw):
    """The friction row: c_eq on its own law, the quadrature split at +-v_eps; the
    equivalent a friction row of the same v_eps whose slope at rest F_c / v_eps is
    c_eq."""

    code = FRICTION
    argument = "velocity"
    bounded = True

    @classmethod
    def force_law(cls, row):
        return (lambda v: friction_force(row[0], row[1], v)[0]), (row[1], -row[1])

    @classmethod
    def slope_at_rest(cls, row) -> float:
        return friction_force(row[0], row[1], 0.0)[1]

    @classmethod
    def gaussian_row(cls, row, gain: float) -> np.ndarray:
        out = np.zeros(NPAR)
        out[0], out[1] = gain * row[1], row[1]  # slope at rest F_c / v_eps = c_eq
        return out


@dataclass(frozen=True, kw_only=True)
class Friction(ElementBase):
    """Coulomb friction ``force`` F_c [N] > 0 smoothed over ``velocity`` v_eps [m/s] > 0."""

    force: float
    velocity: float = 1e-3

    prefix = "fric"
    description = "Coulomb friction"
    ROLE = "dissipative"
    EXAMPLE = {"force": 50.0}
    PARAMETERS = (Param("force", "N", design=(1.0, 1e4)), Param("velocity", "m/s"))
    code = FRICTION

    def row(self):
        return self._row(self.force, self.velocity)

    is_linear = False

    def scaled(self, factor):
        return dataclasses.replace(self, force=self.force * factor)

    def rest_network(self):
        """The slope at rest, a damper c = F_c / v_eps."""
        return "c", {"c": self.force / self.velocity}
