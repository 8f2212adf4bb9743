"""Gas spring: a polytropic gas column behind a piston (docs/model.md, "Gas spring").

A piston of area A closes a gas volume V0 at the spring's force-free length (extension
x = 0), where the gas pressure is p0. Compressing the spring by -x > 0 shrinks the volume
to V = V0 + A x; the gas follows the polytropic law p V^n = p0 V0^n (n = 1 isothermal,
n = 1.4 adiabatic for a diatomic gas; Bauer, *Hydropneumatic Suspension Systems*,
Springer 2011, ch. 2). The spring force is the rise of the gas pressure over p0 on the
piston,

    F = p0 A [1 - (V0 / (V0 + A x))^n]     (tension positive, as every element),

so the spring pushes its ends apart (F < 0) when compressed, and harder the more it is
compressed: the stiffness n p A^2 / V rises with the load (a gas spring's ride
frequency stays nearly constant as the load changes). Its stiffness at the force-free
length is n p0 A^2 / V0; about a static compression it is n p A^2 / V at that
compression, which is what :meth:`GasSpring.rest_network` gives once the static
equilibrium (:func:`inerterlab.systems.equilibrium`) has set the operating point.

The law is singular where the volume vanishes (x = -V0/A); the spring's working range
is its ``stroke`` of compression (default 0.9 V0/A; the gas itself limits a longer one),
and a static equilibrium beyond it is refused (the spring bottoms out).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numba as nb

from ._base import SPRING, ElementBase, Param

__all__ = ["GasSpring", "gas_force", "GAS_LAW"]

#: law code of the gas spring in the spring kernel row (row[2])
GAS_LAW = 1.0


@nb.njit(cache=True, inline="always")
def gas_force(tab, o, y):
    """F [N] at extension y [m] from the force-free length (row: [5] p0 A [N], [6]
    V0/A [m], [7] n); NaN where the gas volume would be gone (y <= -V0/A)."""
    length = tab[o + 6]
    r = length + y
    if r <= 0.0:
        return math.nan
    return tab[o + 5] * (1.0 - (length / r) ** tab[o + 7])


@dataclass(frozen=True, kw_only=True)
class GasSpring(ElementBase):
    """Polytropic gas spring: ``pressure`` p0 [Pa] of the gas at the force-free length,
    piston ``area`` A [m^2], gas ``volume`` V0 [m^3] there, polytropic ``exponent`` n
    [-] (1-2), compression ``stroke`` [m] (default 0.9 V0/A). Stiffness at the
    force-free length n p0 A^2 / V0."""

    pressure: float
    area: float = 3e-3
    volume: float = 1e-3
    exponent: float = 1.4
    stroke: float | None = None
    #: static extension [m] the law is taken about (set by the static equilibrium):
    #: the force is F(operating_point + x) - F(operating_point)
    operating_point: float = 0.0

    prefix = "gas"
    description = "gas spring"
    ROLE = "elastic"
    EXAMPLE = {"pressure": 2e6}
    PARAMETERS = (
        Param("pressure", "Pa", design=(2e5, 2e7)),
        Param("area", "m^2"),
        Param("volume", "m^3"),
        Param("exponent", "", low=1.0, high=2.0, low_open=False),
        Param("stroke", "m", optional=True),
    )
    code = SPRING
    is_linear = False

    def __post_init__(self) -> None:
        super().__post_init__()
        from ..errors import ParameterError

        lo = -self.working_stroke
        if not lo <= self.operating_point:
            raise ParameterError(
                "operating_point", self.operating_point, f"an extension >= {lo:.6g} m"
            )

    @property
    def length(self) -> float:
        """V0/A [m]: the compression at which the gas volume would vanish."""
        return self.volume / self.area

    @property
    def working_stroke(self) -> float:
        """Compression [m] the spring can take: its ``stroke`` (0.9 V0/A by default; a
        stroke beyond V0/A is limited by the gas, whose force grows without bound)."""
        return min(self.stroke, self.length) if self.stroke is not None else 0.9 * self.length

    def force(self, x: float) -> float:
        """F [N] (tension positive) at extension ``x`` [m] from the force-free length
        (NaN where the gas volume would be gone)."""
        r = self.length + x
        if r <= 0.0:
            return math.nan
        return self.pressure * self.area * (1.0 - (self.length / r) ** self.exponent)

    def tangent(self, x: float) -> float:
        """dF/dx [N/m] at extension ``x`` [m]: n p A^2 / V."""
        r = self.length + x
        return (
            self.exponent
            * self.pressure
            * self.area
            / self.length
            * (self.length / r) ** (self.exponent + 1.0)
        )

    def static_range(self) -> tuple[float, float, str]:
        """(lowest, highest extension [m], what the lowest is) of the working range."""
        return (
            -self.working_stroke,
            math.inf,
            f"its stroke {self.working_stroke:.6g} m (it bottoms out)",
        )

    def at_operating_point(self, extension: float) -> GasSpring:
        """This spring with its law taken about the static ``extension`` [m]."""
        return dataclasses.replace(self, operating_point=float(extension))

    def row(self):
        y = self.operating_point
        return self._row(
            self.tangent(y), 0.0, GAS_LAW, y, self.force(y),
            self.pressure * self.area, self.length, self.exponent,
        )  # fmt: skip

    def scaled(self, factor):  # copies in parallel: area and volume add up
        return dataclasses.replace(self, area=self.area * factor, volume=self.volume * factor)

    def rest_network(self):
        """k = n p A^2 / V at the operating point (the force-free length by default)."""
        return "k", {"k": self.tangent(self.operating_point)}
