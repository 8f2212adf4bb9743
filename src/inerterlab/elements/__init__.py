"""Element laws of two-terminal networks, one module each, and their registry.

:data:`ELEMENTS` is the one registry of element names: it maps a name prefix (as written
in a network text, ``k2``, ``afw_front``) to the element class, which declares its role,
its parameters with units (and the optimiser's default search ranges), its law and its
linearisation about rest. The network grammar (:mod:`inerterlab.networks`) reads names
through :func:`element_class` only. A primitive element (spring, damper, asymmetric damper, inerter, friction, adaptive
flywheel, backlash, gas spring, bump stop, bearing drag, one-way clutch, the ball
screw's contact rule) has a compiled force law the system right-hand side calls; a composite element
(hydraulic, screw and rectifier devices, fluid inerter) is a small network of primitives.
Adding an element is one module and one line below (docs/decisions.md, "Model core").
"""

from __future__ import annotations

import functools
import re

from ..errors import NetworkError
from ._base import UNIT_QUANTITY, ElementBase, KernelLaw, Param
from .adaptive_flywheel import AdaptiveFlywheelInerter, FlywheelLaw, inertia_law
from .asymmetric_damper import AsymmetricDamper
from .backlash import Backlash
from .bearing_drag import BearingDrag
from .bump_stop import BumpStop
from .damper import Damper, DamperLaw
from .fluid_inerter import FluidInerter
from .friction import Friction, FrictionLaw
from .gas_spring import GasSpring
from .hydraulic import HydraulicElement
from .inerter import Inerter, InerterLaw
from .one_way_clutch import OneWayClutch
from .rectifier import RectifierElement
from .screw import ScrewElement
from .screw_backlash import ScrewContact
from .spring import Spring, SpringLaw
from .tyre import TyreLaw

__all__ = [
    "ELEMENTS",
    "KERNEL_LAWS",
    "KernelLaw",
    "kernel_law",
    "ElementBase",
    "Param",
    "UNIT_QUANTITY",
    "element_class",
    "register",
    "make_element",
    "inertia_law",
    "Spring",
    "Damper",
    "AsymmetricDamper",
    "Inerter",
    "Friction",
    "AdaptiveFlywheelInerter",
    "HydraulicElement",
    "ScrewElement",
    "RectifierElement",
    "FluidInerter",
    "Backlash",
    "GasSpring",
    "BumpStop",
    "BearingDrag",
    "OneWayClutch",
    "ScrewContact",
]

#: every kernel law by code (:class:`KernelLaw`: how it ties the nodes it joins, its
#: Gaussian equivalent): the system builder, the static balance and the statistical
#: linearisation read it, never an element's code or class
KERNEL_LAWS: dict[int, type[KernelLaw]] = {
    law.code: law for law in (SpringLaw, DamperLaw, FrictionLaw, InerterLaw, FlywheelLaw, TyreLaw)
}


def kernel_law(element: ElementBase) -> type[KernelLaw]:
    """The kernel law of a primitive element (:data:`KERNEL_LAWS` by its code)."""
    law = KERNEL_LAWS.get(element.code)
    if law is None:
        from ..errors import ParameterError

        raise ParameterError(
            "code", element.code,
            f"the code of a kernel law in inerterlab.elements.KERNEL_LAWS ({element.description}: "
            "a primitive packs its row for one of them; a composite gives its expansion())",
        )  # fmt: skip
    return law


ELEMENTS: dict[str, type[ElementBase]] = {
    "k": Spring,
    "c": Damper,
    "b": Inerter,
    "fric": Friction,
    "afw": AdaptiveFlywheelInerter,
    "hyd": HydraulicElement,
    "screw": ScrewElement,
    "rect": RectifierElement,
    "fluid": FluidInerter,
    "gap": Backlash,
    "gas": GasSpring,
    "bump": BumpStop,
    "drag": BearingDrag,
    "owc": OneWayClutch,
    "sgap": ScrewContact,
    "asym": AsymmetricDamper,
}


def register(cls: type[ElementBase]) -> type[ElementBase]:
    """Add an element class under its ``prefix`` (usable as a decorator): then the network
    grammar, the core systems and every analysis know it. A prefix is letters and not
    taken already; where one prefix starts another, a name goes to the longest match."""
    from ..errors import ParameterError

    p = getattr(cls, "prefix", "")
    if not (isinstance(p, str) and p.isalpha() and p.isascii()):
        raise ParameterError("prefix", p, "letters a-z naming the element in network texts")
    if p in ELEMENTS and ELEMENTS[p] is not cls:
        raise ParameterError("prefix", p, f"a prefix not taken (taken by {ELEMENTS[p].__name__})")
    ELEMENTS[p] = cls
    element_class.cache_clear()
    return cls

_SUFFIX = r"(?:\d*|_[A-Za-z0-9_]+)"


@functools.lru_cache(maxsize=4096)
def element_class(name: str) -> type[ElementBase]:
    """The element class a network name belongs to (longest matching prefix)."""
    for prefix in sorted(ELEMENTS, key=len, reverse=True):
        if re.fullmatch(re.escape(prefix) + _SUFFIX, name):
            return ELEMENTS[prefix]
    shown = name if len(name) <= 40 else name[:37] + "..."
    raise NetworkError(
        f"unknown element name {shown!r}: expected a prefix "
        f"{', '.join(sorted(ELEMENTS))} and an optional suffix (digits or _word), "
        "e.g. k2, c_front, afw"
    )


def make_element(name: str, value=None) -> ElementBase:
    """The element ``name`` with ``value``: a number, a dict of parameters or an element."""
    return element_class(name).from_value(name, value)
