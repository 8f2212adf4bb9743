"""Fluid inerter with a helical channel [SW13]: b = rho l A1^2 / A2, plus parasitic damping.

A piston of area A1 drives fluid of density rho through a helical channel of length l
and cross-section A2; the fluid in the channel moves A1/A2 times faster than the
piston, so its kinetic energy is that of an inertance

    b = rho l A1^2 / A2                                              [kg]

[SW13]. The channel's losses are modelled as a parallel damper F = c v + c_2 v |v|:
the linear part for the viscous (laminar) loss, the quadratic part the usual model of
turbulent and entry/exit losses of a pipe flow (pressure drop proportional to the
square of the flow velocity); [SW13] discusses these parasitic effects. The loss
coefficients are the user's. With c = c_2 = 0 the element is an ideal inerter of
inertance b (docs/model.md §11).

[SW13] S. J. Swift, M. C. Smith, A. R. Glover, C. Papageorgiou, B. Gartner and
N. E. Houghton, "Design and modelling of a fluid inerter", International Journal of
Control 86(11), 2035-2051, 2013.
"""

from __future__ import annotations

from dataclasses import dataclass

from ._base import ElementBase, Param
from .damper import Damper
from .inerter import Inerter

__all__ = ["FluidInerter"]


@dataclass(frozen=True, kw_only=True)
class FluidInerter(ElementBase):
    """Fluid inerter: ``density`` rho [kg/m^3], ``length`` l [m] of the helical channel,
    ``piston_area`` A1 [m^2], ``channel_area`` A2 [m^2], ``damping`` c [N s/m] and
    ``quadratic`` c_2 [N s^2/m^2] of the parasitic loss (both 0 by default)."""

    density: float
    length: float
    piston_area: float
    channel_area: float
    damping: float = 0.0
    quadratic: float = 0.0

    prefix = "fluid"
    description = "fluid inerter"
    EXAMPLE = {
        "density": 860.0,
        "length": 3.0,
        "piston_area": 2e-3,
        "channel_area": 3e-5,
        "damping": 300.0,
    }
    PARAMETERS = (
        Param("density", "kg/m^3"),
        Param("length", "m", design=(0.01, 100.0)),
        Param("piston_area", "m^2"),
        Param("channel_area", "m^2"),
        Param("damping", "N s/m", low_open=False),
        Param("quadratic", "N s^2/m^2", low_open=False),
    )

    @property
    def inertance(self) -> float:
        """b = rho l A1^2 / A2 [kg]."""
        return self.density * self.length * self.piston_area**2 / self.channel_area

    def expansion(self):
        parts = {"b": Inerter(inertance=self.inertance)}
        if self.damping == 0.0 and self.quadratic == 0.0:
            return "b", parts
        parts["c"] = Damper(damping=self.damping, quadratic=self.quadratic)
        return "b | c", parts
