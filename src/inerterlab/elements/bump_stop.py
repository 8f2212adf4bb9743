"""Progressive bump stop (docs/model.md, "Bump stop").

An elastomer buffer that the spring meets after a ``clearance`` s of compression and
that stiffens as it is squeezed. With the compression beyond contact
delta = -x - s (x the extension, x < 0 compressed),

    F = 0                               for delta <= 0 (clear of the stop),
    F = -k delta (1 + (delta / d)^2)    for delta > 0 (tension positive: it pushes),

k [N/m] the rate at first contact and d [m] the ``progression``: the rate
k (1 + 3 (delta/d)^2) is four times the first rate d beyond contact. The cubic is our
choice of a smooth progressive law (one stiffening term, the force and its rate
continuous beyond contact, the rate jumping from 0 to k at contact, where the
integrator locates the switch); it is not fitted to a particular buffer. The stop is
solid after its ``travel`` (compression beyond contact; default 4 d): a static
equilibrium that would squeeze it further is refused.

Clear of the stop at rest the bump stop carries no force for small motions (an open
circuit); resting on it (after :func:`inerterlab.systems.equilibrium`) its
linearisation is the rate at the static compression.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numba as nb

from ._base import SPRING, ElementBase, Param

__all__ = ["BumpStop", "bump_force", "BUMP_LAW"]

#: law code of the bump stop in the spring kernel row (row[2])
BUMP_LAW = 2.0


@nb.njit(cache=True, inline="always")
def bump_force(tab, o, y):
    """F [N] at extension y [m] (row: [1] clearance s [m], [5] k [N/m], [6] d [m])."""
    delta = -y - tab[o + 1]
    if delta <= 0.0:
        return 0.0
    q = delta / tab[o + 6]
    return -tab[o + 5] * delta * (1.0 + q * q)


@dataclass(frozen=True, kw_only=True)
class BumpStop(ElementBase):
    """Progressive compression bump stop: first ``stiffness`` k [N/m] at contact after
    ``clearance`` s [m] > 0 of compression, ``progression`` d [m] (the rate is 4 k a
    compression d beyond contact), ``travel`` [m] beyond contact before it is solid
    (default 4 d)."""

    stiffness: float
    clearance: float
    progression: float = 0.01
    travel: float | None = None
    #: static extension [m] the law is taken about (set by the static equilibrium)
    operating_point: float = 0.0

    prefix = "bump"
    description = "progressive bump stop"
    ROLE = "elastic"
    EXAMPLE = {"stiffness": 1e5, "clearance": 0.002}
    PARAMETERS = (
        Param("stiffness", "N/m", design=(1e3, 1e7)),
        Param("clearance", "m"),
        Param("progression", "m"),
        Param("travel", "m", optional=True),
    )
    code = SPRING
    is_linear = False

    def force(self, x: float) -> float:
        """F [N] (tension positive) at extension ``x`` [m]."""
        delta = -x - self.clearance
        if delta <= 0.0:
            return 0.0
        return -self.stiffness * delta * (1.0 + (delta / self.progression) ** 2)

    def tangent(self, x: float) -> float:
        """dF/dx [N/m] at extension ``x`` [m] (0 clear of the stop)."""
        delta = -x - self.clearance
        if delta <= 0.0:
            return 0.0
        return self.stiffness * (1.0 + 3.0 * (delta / self.progression) ** 2)

    @property
    def working_travel(self) -> float:
        return self.travel if self.travel is not None else 4.0 * self.progression

    def static_range(self) -> tuple[float, float, str]:
        """(lowest, highest extension [m], what the lowest is) of the working range."""
        lo = -(self.clearance + self.working_travel)
        return lo, math.inf, f"its travel {self.working_travel:.6g} m beyond contact (it is solid)"

    def at_operating_point(self, extension: float) -> BumpStop:
        """This bump stop with its law taken about the static ``extension`` [m]."""
        return dataclasses.replace(self, operating_point=float(extension))

    def row(self):
        y = self.operating_point
        return self._row(
            self.tangent(y), self.clearance, BUMP_LAW, y, self.force(y), self.stiffness,
            self.progression,
        )  # fmt: skip

    def scaled(self, factor):
        return dataclasses.replace(self, stiffness=self.stiffness * factor)

    def rest_network(self):
        """The rate at the operating point; clear of the stop, an open circuit."""
        k = self.tangent(self.operating_point)
        return ("k", {"k": k}) if k > 0.0 else None
