"""A device of the model core at a vehicle corner, in parallel with the strut.

A device is any element of :mod:`inerterlab.elements` (the thesis's hydraulic, rectifier
and screw devices, the fluid inerter, ...) or a network of them. At a corner it acts
between the body and the wheel, in parallel with the corner's :class:`Strut`. It is
expanded into primitive elements (:mod:`inerterlab.systems`) and split in two:

* **Direct elements**, connected straight across the two terminals: springs, linear
  dampers and ideal inerters join the strut's stiffness, damping and inertance (the
  mass and stiffness matrices of the vehicle); an adaptive-flywheel inerter (laws
  ``thesis`` and ``momentum``) becomes the strut's adaptive inerter (the speed-dependent
  mass matrix of :mod:`inerterlab.vehicles.nonlinear`).
* **The rest**, everything with internal nodes (for the hydraulic device: the series
  spring and the branch of damper, friction and flywheel behind it) and any other
  direct element (friction, quadratic dampers), stays a core *rig*: the network
  between a driven terminal, whose prescribed motion is the strut's extension, and a
  fixed one. The vehicle integrates the rig's states with its own and adds the rig's
  force to the strut's. This is exact, not an approximation, as the device's internal
  nodes are massless: every force inside it depends only on motion relative to the
  wheel, so the wheel's own acceleration does not enter.

Two conditions make the rig's force a function of the states alone, and are checked:
no inertial element (inerter, flywheel) may touch the body-side terminal except
straight across the device (write ``c - b``, not ``b - c``: a series connection's law
does not depend on its order), and the rig part must carry no static load (the strut's
springs carry the car; the device's series springs relax at rest), except gas springs and
bump stops straight across, which the vehicle's static equilibrium
(:mod:`inerterlab.vehicles.statics`) takes about their static extension.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = ["CornerDevice", "corner_device"]


@dataclass(frozen=True, eq=False)
class CornerDevice:
    """A device split for a vehicle corner (build with :func:`corner_device`).

    Attributes
    ----------
    source : str
        What the user gave (network text or element description), for messages.
    stiffness, damping, inertance : float
        The direct springs, linear dampers and ideal inerters [N/m, N s/m, kg].
    adaptive : AdaptiveFlywheelInerter or None
        The direct adaptive-flywheel inerter.
    system : System or None
        The rest, as a core rig in relative coordinates (drive = strut extension).
    drive_elements : tuple of (int, float)
        (element index in ``system``, sign): the device's tension is
        sum sign * element force over these.
    edges : tuple
        The primitive edges (name, element, top, bottom) the device was built from.
    """

    source: str
    stiffness: float
    damping: float
    inertance: float
    adaptive: Any
    system: Any
    drive_elements: tuple
    edges: tuple = field(repr=False)
    nodes: tuple = field(repr=False)

    def __repr__(self) -> str:
        return f"CornerDevice({self.source!r})"

    @property
    def n_states(self) -> int:
        """States of the rig part (0 without one)."""
        return 0 if self.system is None else int(self.system.n_states)

    def initial_state(self, extension: float) -> np.ndarray:
        """Rig state at rest with the strut extended by ``extension`` [m] (internal
        nodes at the spring equilibrium)."""
        if self.system is None:
            return np.zeros(0)
        from ..systems.core import _initial

        return _initial(self.system, {}, float(extension))

    def tension(self, x, extension: float, rate: float) -> float:
        """Force of the rig part [N] resisting an extension (Python, for checks)."""
        from ..systems import _kernel

        if self.system is None:
            return 0.0
        itab, ftab = self.system.tables
        nn = int(itab[_kernel.I_NN])
        W = np.empty(_kernel.work_size(itab))
        dx = np.empty(self.n_states)
        road = np.array([extension, rate, 0.0])
        _kernel.evaluate(0.0, np.asarray(x, float), road, itab, ftab, W, dx, _kernel._NO_IMPULSE)
        return float(sum(s * W[3 * nn + e] for e, s in self.drive_elements))

    def fastest_rate(self) -> float:
        """Largest |eigenvalue| [1/s] of the rig part's dynamics at rest, the drive
        held (a finite-difference Jacobian at zero velocity, where regularised friction
        is stiffest); 0 without states. Sets the explicit step limit."""
        if self.n_states == 0:
            return 0.0
        from ..systems import _kernel

        itab, ftab = self.system.tables
        x0 = self.initial_state(0.0)
        road = np.zeros(3)
        f0 = np.empty(x0.size)
        _kernel.rhs(0.0, x0, road, itab, ftab, f0)
        J = np.empty((x0.size, x0.size))
        scales = self.system.state_scales
        for i in range(x0.size):
            h = 1e-7 * max(float(scales[i]), 1e-6)
            xp = x0.copy()
            xp[i] += h
            fp = np.empty(x0.size)
            _kernel.rhs(0.0, xp, road, itab, ftab, fp)
            J[:, i] = (fp - f0) / h
        return float(np.max(np.abs(np.linalg.eigvals(J))))

    def scaled(self, factor: float) -> CornerDevice:
        """``factor`` identical devices in parallel, moving together, as one."""
        edges = tuple((n, el.scaled(factor), t, b) for n, el, t, b in self.edges)
        return _split(f"{factor:g} x {self.source}", self.nodes, edges)


def corner_device(device, params: dict | None = None) -> CornerDevice:
    """Split ``device`` (an element object, or a core network text with ``params``) for
    a vehicle corner. ParameterError naming the offending element when it cannot sit
    there (see the module docstring)."""
    from ..elements import ElementBase
    from ..networks import NetworkError
    from ..systems._network import Layout, elements_of

    if isinstance(device, CornerDevice):
        return device
    if isinstance(device, ElementBase):
        text, params, source = device.prefix, {device.prefix: device}, device.description
    elif isinstance(device, str):
        text, source = device, device
    else:
        raise ParameterError("device", device, "an element of inerterlab.elements or a network text")
    try:
        tree, els = elements_of(text, params)
        lay = Layout()
        top = lay.node("drive", "road")
        bot = lay.node("ground", "ground")
        lay.place(tree, top, bot, els)
    except NetworkError as e:
        raise ParameterError("device", source, str(e)) from None
    return _split(source, tuple(lay.nodes), tuple(lay.edges))


def _split(source: str, nodes: tuple, edges: tuple) -> CornerDevice:
    from ..elements._base import FLYWHEEL
    from ..networks import NetworkError
    from ..systems._network import Layout
    from ..systems.core import build

    k = c = b = 0.0
    adaptive = None
    rest = []
    for name, el, t, bt in edges:
        direct = {t, bt} == {0, 1}
        if direct and el.is_linear:  # one spring, damper or inerter by its linear law
            (kind, value), = el.rest_network()[1].items()
            if kind == "k":
                k += value
            elif kind == "c":
                c += value
            else:
                b += value
        elif direct and el.code == FLYWHEEL:
            if el.law not in ("thesis", "momentum"):
                raise ParameterError(
                    f"device {source!r}: {name}.law", el.law, "'thesis' or 'momentum' at a corner"
                )
            if adaptive is not None:
                raise ParameterError(
                    f"device {source!r}: {name}", "a second adaptive-flywheel inerter",
                    "at most one across the device",
                )  # fmt: skip
            adaptive = el
        else:
            if 0 in (t, bt) and el.ROLE == "inertial":
                raise ParameterError(
                    f"device {source!r}: {name}",
                    el.description,
                    "no inerter or flywheel between the body-side terminal and an internal "
                    "node (its force would depend on the body's acceleration): put it on "
                    "the wheel side of its series connection, e.g. 'c - b' for 'b - c' "
                    "(the same two-terminal law)",
                )
            rest.append((name, el, t, bt))
    system = None
    drive = ()
    if rest:
        lay = Layout()
        lay.nodes = [dict(n) for n in nodes]
        lay.edges = list(rest)
        try:
            system = build("rig", f"corner device {source!r}", lay, {"network": source})
        except NetworkError as e:
            raise ParameterError("device", source, str(e)) from None
        drive = tuple(
            (i, 1.0 if t == 0 else -1.0) for i, (_, _, t, bt) in enumerate(rest) if 0 in (t, bt)
        )
        dev = CornerDevice(source, k, c, b, adaptive, system, drive, edges, nodes)
        x1 = dev.initial_state(1.0)
        # gas springs and bump stops straight across may carry the car: the vehicle's
        # static equilibrium takes them about their static extension (statics.py)
        held = tuple(
            (i, s) for i, s in drive
            if not ({rest[i][2], rest[i][3]} == {0, 1} and hasattr(rest[i][1], "at_operating_point"))
        )  # fmt: skip
        static = dataclasses.replace(dev, drive_elements=held).tension(x1, 1.0, 0.0)
        if not math.isfinite(static) or abs(static) > 1e-9 * max(1.0, _largest_spring(rest)):
            raise ParameterError(
                "device",
                source,
                "a device whose parts with internal nodes carry no static load (a spring "
                f"path across it gives {static:.6g} N per metre of extension): put static "
                "springs in the strut's stiffness",
            )
        return dev
    return CornerDevice(source, k, c, b, adaptive, None, (), edges, nodes)


def _largest_spring(edges) -> float:
    return max((el.row()[0] for _, el, _, _ in edges if el.ROLE == "elastic"), default=0.0)
