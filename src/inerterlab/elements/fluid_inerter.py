"""Fluid inerter with a helical channel [SW13]: b = rho l A1^2 / A2, with the channel's
losses computed from its geometry unless given.

A piston of area A1 drives fluid of density rho through a helical channel of length l
and cross-section A2; the fluid in the channel moves A1/A2 times faster than the
piston, so its kinetic energy is that of an inertance

    b = rho l A1^2 / A2                                              [kg]

[SW13]. Either ``length`` or ``inertance`` is given (the other follows). The channel's
losses are a parallel damper F = c v + c_2 v |v| (docs/model.md §11):

* ``damping`` c, by default the laminar loss of a circular pipe of the channel's
  length and area (Hagen-Poiseuille, [WHI] §6.4): dp = 8 pi mu l Q / A2^2 with
  Q = A1 v and F = A1 dp, so c = 8 pi mu l A1^2 / A2^2 (``viscosity`` mu
  [N s/m^2 = Pa s]);
* ``quadratic`` c_2, by default the entry and exit losses dp = K rho u^2 / 2 at the
  channel velocity u = (A1/A2) v ([IDE]: K = 0.5 for a
  sharp-edged entry, 1.0 for the exit into a wide chamber; ``loss_coefficient`` K,
  default 1.5), so c_2 = K rho A1^3 / (2 A2^2).

Both are lower bounds for a real helix: the curvature raises the friction above the
straight pipe's once the Dean number grows [DEA], and the flow becomes turbulent at
high speed; give ``damping`` and ``quadratic`` where they are measured. With both
set to 0 the element is an ideal inerter of inertance b.

[SW13] S. J. Swift, M. C. Smith, A. R. Glover, C. Papageorgiou, B. Gartner and
N. E. Houghton, "Design and modelling of a fluid inerter", International Journal of
Control 86(11), 2035-2051, 2013.
[WHI] F. M. White, Fluid Mechanics, 7th ed., McGraw-Hill, 2011.
[IDE] I. E. Idelchik, Handbook of Hydraulic Resistance, 3rd ed., Begell House, 1996.
[DEA] W. R. Dean, "The stream-line motion of fluid in a curved pipe", Philosophical
Magazine 5(30), 673-695, 1928.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError
from ._base import ElementBase, Param
from .damper import Damper
from .hydraulic import CONSISTENT
from .inerter import Inerter

__all__ = ["FluidInerter", "laminar_damping", "minor_loss_quadratic"]


def laminar_damping(viscosity: float, length: float, piston_area: float, channel_area: float) -> float:
    """c = 8 pi mu l A1^2 / A2^2 [N s/m]: Hagen-Poiseuille in a circular channel [WHI]."""
    return 8.0 * math.pi * viscosity * length * piston_area**2 / channel_area**2


def minor_loss_quadratic(loss_coefficient: float, density: float, piston_area: float, channel_area: float) -> float:
    """c_2 = K rho A1^3 / (2 A2^2) [N s^2/m^2]: entry and exit losses [IDE]."""
    return 0.5 * loss_coefficient * density * piston_area**3 / channel_area**2


@dataclass(frozen=True, kw_only=True)
class FluidInerter(ElementBase):
    """Fluid inerter: ``density`` rho [kg/m^3], ``length`` l [m] of the helical channel
    or the ``inertance`` b [kg] it gives, ``piston_area`` A1 [m^2], ``channel_area`` A2
    [m^2]; the loss ``damping`` c [N s/m] (default from ``viscosity`` mu [N s/m^2]) and
    ``quadratic`` c_2 [N s^2/m^2] (default from ``loss_coefficient`` K, 1.5). After
    construction every field holds its resolved value."""

    density: float
    length: float | None = None
    piston_area: float
    channel_area: float
    damping: float | None = None
    quadratic: float | None = None
    viscosity: float | None = None
    loss_coefficient: float = 1.5
    inertance: float | None = None

    prefix = "fluid"
    ALTERNATIVES = {"inertance": "length"}
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
        Param("length", "m", optional=True, design=(0.01, 100.0)),
        Param("piston_area", "m^2"),
        Param("channel_area", "m^2"),
        Param("damping", "N s/m", low_open=False, optional=True),
        Param("quadratic", "N s^2/m^2", low_open=False, optional=True),
        Param("viscosity", "N s/m^2", optional=True),
        Param("loss_coefficient", "", low_open=False),
        Param("inertance", "kg", optional=True),
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        rho, a1, a2 = self.density, self.piston_area, self.channel_area
        length, b = self.length, self.inertance
        if b is not None:
            lb = b * a2 / (rho * a1 * a1)
            if length is not None and abs(length - lb) > CONSISTENT * lb:
                raise ParameterError(
                    "inertance",
                    b,
                    f"one of inertance and length, or both consistent: length={length:g} m "
                    f"gives rho l A1^2/A2 = {rho * length * a1 * a1 / a2:.6g} kg; "
                    f"inertance={b:g} kg needs length={lb:.6g} m",
                )
            length = lb
        elif length is None:
            raise ParameterError("length", None, "a value [m] (required), or give inertance [kg]")
        else:
            b = rho * length * a1 * a1 / a2
        object.__setattr__(self, "length", float(length))
        object.__setattr__(self, "inertance", float(b))  # as given, to the bit
        if self.damping is None:
            if self.viscosity is None:
                raise ParameterError(
                    "viscosity",
                    None,
                    "a value [N s/m^2 = Pa s] (required for the channel's laminar loss), or give "
                    "damping [N s/m] (0 for none)",
                )
            object.__setattr__(self, "damping", laminar_damping(self.viscosity, length, a1, a2))
        if self.quadratic is None:
            q = minor_loss_quadratic(self.loss_coefficient, rho, a1, a2)
            object.__setattr__(self, "quadratic", q)

    def parameters(self) -> dict:
        """The parameter values by name; the size as the ``length`` (``inertance`` None)."""
        return {**super().parameters(), "inertance": None}

    def expansion(self):
        parts = {"b": Inerter(inertance=self.inertance)}
        if self.damping == 0.0 and self.quadratic == 0.0:
            return "b", parts
        parts["c"] = Damper(damping=self.damping, quadratic=self.quadratic)
        return "b | c", parts
