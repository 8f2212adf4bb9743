"""Asymmetric damper: damping ``rebound`` while the element extends, ``compression``
while it shortens.

A road vehicle's damper is valved to resist extension (rebound) more than compression
(typically two to three times: the wheel then follows a hole quickly and a bump pushes
less into the body; Dixon, *The Shock Absorber Handbook*, 2nd ed., Wiley 2007, ch. 5).
The law, tension positive as every element, with v the rate of extension,

    F = c_r v  (v > 0),     F = c_c v  (v <= 0),

is continuous with a kink at rest. It rides on the damper's kernel row: a law code in
row[2] (:data:`ASYMMETRIC_LAW`), the compression rate in row[3], so the compiled
right-hand side reads it through :func:`~inerterlab.elements.damper.damper_force`.

Its linearisation about rest (:meth:`AsymmetricDamper.rest_network`) is the linear
damper (c_r + c_c) / 2: the law is positively homogeneous (F(a v) = a F(v) for a > 0),
so under a sinusoidal rate of any amplitude the first harmonic of the force is that of
the mean damping (the Fourier coefficient of c_r v+ + c_c v- against sin), and the
Gaussian-equivalent damping of a zero-mean rate is the same mean. The rest of the force
(its mean and even harmonics) does not shrink relative to the motion as the motion
shrinks, so small motions are not linear about rest (tests/test_element_registry.py).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ._base import DAMPER, ElementBase, Param

__all__ = ["AsymmetricDamper", "ASYMMETRIC_LAW"]

#: law code of the asymmetric damper in the damper kernel row (row[2])
ASYMMETRIC_LAW = 1.0


@dataclass(frozen=True, kw_only=True)
class AsymmetricDamper(ElementBase):
    """Damper of ``rebound`` rate c_r [N s/m] while extending and ``compression`` rate
    c_c [N s/m] while shortening (both > 0)."""

    rebound: float
    compression: float

    prefix = "asym"
    description = "asymmetric damper"
    ROLE = "dissipative"
    EXAMPLE = {"rebound": 4e3, "compression": 1.5e3}
    PARAMETERS = (
        Param("rebound", "N s/m", design=(10.0, 1e5)),
        Param("compression", "N s/m", design=(10.0, 1e5)),
    )
    code = DAMPER

    def row(self):
        return self._row(self.rebound, 0.0, ASYMMETRIC_LAW, self.compression)

    def scaled(self, factor):
        return dataclasses.replace(
            self, rebound=self.rebound * factor, compression=self.compression * factor
        )

    @property
    def is_linear(self):
        return self.rebound == self.compression

    def rest_network(self):
        """c = (c_r + c_c) / 2, the first-harmonic (and Gaussian-equivalent) damping."""
        return "c", {"c": 0.5 * (self.rebound + self.compression)}
