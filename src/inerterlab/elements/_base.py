"""What every element says about itself: role, parameters with units, states, primitive
row, linearisation about rest.

An element is a frozen dataclass. A *primitive* element has a kernel code and packs its
parameters into one row of :data:`NPAR` floats that the compiled system right-hand side
reads (:mod:`inerterlab.systems._kernel`). A *composite* element (the thesis devices,
the fluid inerter) is a small network of primitives: :meth:`ElementBase.expansion`
returns its text and the primitive objects by local name, and the system builder
substitutes it where the composite's name appears.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..errors import PHYSICAL_RANGES, ParameterError, check_choice, check_in_range, check_physical

__all__ = ["Param", "UNIT_QUANTITY", "ElementBase", "KernelLaw", "ForceLaw", "NO_GAUSSIAN_EQUIVALENT", "NPAR", "SPRING", "DAMPER", "INERTER", "FRICTION", "FLYWHEEL", "TYRE"]

#: floats per primitive element row in the compiled tables
NPAR = 18
#: kernel codes of the primitive elements
SPRING, DAMPER, INERTER, FRICTION, FLYWHEEL = 0, 1, 2, 3, 4
#: a tyre's point contact (spring and damper that cannot pull: lift-off), only between a
#: body and the road (:mod:`inerterlab.elements.tyre`)
TYRE = 5


#: the kind of physical quantity (a key of :data:`inerterlab.errors.PHYSICAL_RANGES`) of a
#: parameter declared in each unit; a parameter in another unit (a dimensionless ratio
#: with its own interval) has no physical range. The element registry's test requires
#: every numeric parameter of every registered element to have one or a unit of "".
UNIT_QUANTITY = {
    "N/m": "stiffness",
    "N s/m": "damping",
    "N s^2/m^2": "quadratic damping",
    "kg": "inertance",
    "kg m^2": "inertia",
    "kg/m^3": "density",
    "m": "length",
    "m^2": "area",
    "m/s": "velocity",
    "N": "force",
    "rad/m": "transmission ratio",
    "Pa": "pressure",
    "m^3": "volume",
    "N s/m^2": "viscosity",
    "N m s/rad": "rotary damping",
}
assert all(PHYSICAL_RANGES[q][2] == u for u, q in UNIT_QUANTITY.items())


#: why an element has no Gaussian equivalent when its kernel law gives none (states or
#: contact rules of its own)
NO_GAUSSIAN_EQUIVALENT = (
    "an element without states or contact rules of its own for the statistical "
    "linearisation (springs, dampers, friction, adaptive inerters); the Monte "
    "Carlo of the time simulation takes it"
)


class KernelLaw:
    """What the rest of the package needs to know about one kernel law (one ``code``, a
    row of :data:`NPAR` floats that the compiled right-hand side evaluates), so that no
    analysis decides by an element's code or class: registered by code in
    :data:`inerterlab.elements.KERNEL_LAWS`; every element of that code shares it.

    * how the law ties the nodes it joins, which the system builder
      (:mod:`inerterlab.systems.core`) and the static balance read: the class flags
      below;
    * its Gaussian-equivalent (statistical) linearisation from its own compiled force
      function, which :mod:`inerterlab.systems.gaussian` reads: a row that is not
      linear is linearised about a zero-mean Gaussian ``argument``
      (``"displacement"``, ``"velocity"``, or ``"acceleration"`` for an inertance); for
      an elastic or dissipative law (:class:`ForceLaw`) the equivalent is E[x F(x)] /
      sigma^2 (Stein's lemma) from its force function, the slope at rest for sigma = 0.

    A new kernel law is its element module (its force function, its branch in the
    compiled evaluation) with a subclass of this and one line in the registry."""

    #: the kernel code whose rows these are
    code: ClassVar[int] = -1
    #: what its force depends on, and its Gaussian equivalent (top minus bottom)
    argument: ClassVar[str] = ""
    #: an inertance times the relative acceleration (an inerter, a flywheel): the nodes
    #: it joins move with velocity states, and its nominal inertance
    #: (:meth:`nominal_inertance`) enters the mass matrix
    inertial: ClassVar[bool] = False
    #: a force that grows without bound with the relative velocity (a damper): a
    #: massless node it joins has its velocity from its force balance
    holds_velocity: ClassVar[bool] = False
    #: a force bounded in the relative velocity (friction): it cannot hold a massless
    #: node on its own
    bounded: ClassVar[bool] = False
    #: an elastic row whose row[0] is its stiffness at rest (the spring Laplacian of the
    #: network, the static balance)
    elastic: ClassVar[bool] = False
    #: a point contact (a tyre): it joins a wheel (a mass) to the road, carries the load
    #: at rest, and passes no impulse at a road step
    contact: ClassVar[bool] = False

    @classmethod
    def free_play(cls, row) -> bool:
        """Whether the row is a spring with free play (its force is zero inside it)."""
        return False

    @classmethod
    def nominal_inertance(cls, element) -> float:
        """The inertance [kg] the law adds to the nominal mass matrix: 0 unless it is
        :attr:`inertial`."""
        return 0.0

    @classmethod
    def gaussian_keeps(cls, row) -> bool:
        """Whether the row is linear at every motion (it keeps its law)."""
        return False

    @classmethod
    def gaussian_refusal(cls, row, description: str) -> tuple[str, str] | None:
        """(the value named, what is expected) where the row has no Gaussian equivalent,
        else None. A law that neither keeps its rows nor refuses them gives
        ``gaussian_gain(row, sigma, expect)`` and ``gaussian_row(row, gain)`` (as
        :class:`ForceLaw` does from its force function)."""
        return None


class ForceLaw(KernelLaw):
    """A kernel law whose force is a function of one argument (an elastic or a
    dissipative row): its Gaussian equivalent E[x F(x)] / sigma^2 (Stein's lemma) from
    :meth:`force_law`, the slope at rest for sigma = 0, and its equivalent row the one
    coefficient of a linear row. Subclasses give :meth:`force_law` and
    :meth:`slope_at_rest`."""

    @classmethod
    def gaussian_gain(cls, row, sigma: float, expect) -> float:
        """The equivalent (k_eq or c_eq) under a zero-mean Gaussian argument of standard
        deviation ``sigma``; ``expect(f, sigma, kinks)`` = E[f(x)]."""
        if sigma <= 0.0:
            return float(cls.slope_at_rest(row))
        law, kinks = cls.force_law(row)
        return expect(lambda x: x * law(x), sigma, kinks) / (sigma * sigma)

    @classmethod
    def gaussian_row(cls, row, gain: float) -> np.ndarray:
        """A row of this law whose linearisation about rest is ``gain``: the one
        coefficient of a linear row."""
        out = np.zeros(NPAR)
        out[0] = gain
        return out


@dataclass(frozen=True)
class Param:
    """One parameter: name, unit, valid interval (``low``, ``high``; open ends) or choices.

    A numeric parameter whose unit names a physical quantity (:data:`UNIT_QUANTITY`) must
    also lie in that quantity's physical range (:func:`inerterlab.errors.check_physical`;
    0 stays allowed where the interval is closed at 0): the one check of every element
    parameter, whichever command or function builds the element."""

    name: str
    unit: str = ""
    low: float = 0.0
    high: float = float("inf")
    low_open: bool = True
    choices: tuple | None = None
    optional: bool = False
    #: default search range (low, high) of the H2 optimiser, or None: held unless the
    #: user gives bounds
    design: tuple[float, float] | None = None

    def check(self, value: Any) -> Any:
        if self.optional and value is None:
            return None
        if self.choices is not None:
            if self.name == "flywheel" and not isinstance(value, str):
                from ..flywheels import AdaptiveFlywheel

                if isinstance(value, AdaptiveFlywheel):
                    return value
            return check_choice(self.name, value, self.choices)
        x = check_in_range(
            self.name,
            value,
            self.low,
            self.high,
            low_open=self.low_open,
            high_open=True,
            unit=self.unit,
        )
        if self.quantity is not None:
            check_physical(self.name, x, self.quantity, zero=self.low == 0 and not self.low_open)
        return x

    @property
    def quantity(self) -> str | None:
        """The kind of physical quantity whose range applies, or None."""
        return None if self.choices is not None else UNIT_QUANTITY.get(self.unit)


class ElementBase:
    """Common behaviour; subclasses are frozen keyword-only dataclasses."""

    prefix: ClassVar[str] = ""
    description: ClassVar[str] = ""
    #: what the element's force depends on: "elastic" (displacement), "dissipative"
    #: (velocity), "inertial" (acceleration), or "composite" (a network of primitives)
    ROLE: ClassVar[str] = "composite"
    #: one-parameter linear elements: Y(s) = value * s**ADMITTANCE (spring -1, damper 0,
    #: inerter 1); None for every other element (its admittance comes from
    #: :meth:`rest_network`)
    ADMITTANCE: ClassVar[int | None] = None
    PARAMETERS: ClassVar[tuple[Param, ...]] = ()
    #: parameters of a typical element (the documentation's and the registry test's
    #: example; {} where every parameter has a default)
    EXAMPLE: ClassVar[dict | None] = None
    #: kernel code, or None for a composite
    code: ClassVar[int | None] = None
    #: parameters that give another one's quantity another way, {name: the one it
    #: stands for} (a device's ``inertance`` for its ``ratio``): give either, or both
    #: consistent
    ALTERNATIVES: ClassVar[dict[str, str]] = {}

    def __post_init__(self) -> None:
        for p in self.PARAMETERS:
            v = getattr(self, p.name)
            if p.choices is None and v is not None:
                v = p.check(v)
                object.__setattr__(self, p.name, float(v))
            else:
                p.check(v)

    # -- construction -----------------------------------------------------------------
    @classmethod
    def from_value(cls, name: str, value: Any) -> ElementBase:
        """An element from what a user gave for ``name``: an element, a number (the first
        parameter) or a dict of parameters; ``None`` takes every default."""
        if isinstance(value, ElementBase):
            if not isinstance(value, cls):
                raise ParameterError(name, value, f"a {cls.description} ({cls.__name__})")
            return value
        if value is None:
            value = {}
        if not isinstance(value, dict):
            value = {cls.PARAMETERS[0].name: value}
        known = {p.name for p in cls.PARAMETERS}
        unknown = sorted(set(value) - known)
        if unknown:
            raise ParameterError(
                f"{name}.{unknown[0]}",
                value[unknown[0]],
                f"no such parameter of a {cls.description}; known: {', '.join(sorted(known))}",
            )
        try:
            return cls(**value)
        except ParameterError as e:
            label = name if len(cls.PARAMETERS) == 1 else f"{name}.{e.name}"
            raise ParameterError(label, e.value, e.valid) from None
        except TypeError as e:  # a required parameter is missing
            missing = [
                p.name
                for p in cls.PARAMETERS
                if p.name not in value
                and getattr(cls.__dataclass_fields__[p.name], "default", dataclasses.MISSING)
                is dataclasses.MISSING
                and cls.__dataclass_fields__[p.name].default_factory is dataclasses.MISSING
            ]
            if missing:
                p = next(q for q in cls.PARAMETERS if q.name == missing[0])
                raise ParameterError(
                    f"{name}.{p.name}" if len(cls.PARAMETERS) > 1 else name,
                    None,
                    f"a value [{p.unit}] (required)",
                ) from None
            raise ParameterError(name, value, str(e)) from None

    def parameters(self) -> dict:
        """The parameter values by name."""
        return {p.name: getattr(self, p.name) for p in self.PARAMETERS}

    # -- what the system builder asks ---------------------------------------------------
    def expansion(self) -> tuple[str, dict] | None:
        """Composite: (network text over local names, {local name: primitive element})."""
        return None

    def row(self) -> np.ndarray:
        """Primitive: the kernel row of :data:`NPAR` floats. A composite element has
        none: the system builder replaces it by its :meth:`expansion` first."""
        raise TypeError(
            f"{self.description} ({self.prefix}) is a composite element: it has no kernel "
            "row; place it in a network, where it is expanded into primitives"
        )

    @property
    def internal_states(self) -> tuple[str, ...]:
        """Names of the element's own states (beyond node displacements and velocities)."""
        return ()

    def initial_internal_state(self) -> tuple[float, ...]:
        return ()

    @property
    def is_linear(self) -> bool:
        """True if the force is linear in the terminal motion for every motion (then the
        :meth:`rest_network` is exact, not only a linearisation)."""
        exp = self.expansion()
        if exp is None:
            return False
        return all(el.is_linear for el in exp[1].values())

    def linear_regime(self) -> tuple[ElementBase, str, float] | None:
        """Where a nonlinear primitive's force law is linear over a whole region of its
        motion: (the linear primitive it equals there, the argument ``"velocity"`` or
        ``"displacement"`` (relative, top minus bottom), threshold a > 0), the region
        being |argument| >= a, bounded by the element's switching function. None where
        it has no such region. The integrator takes exact matrix-exponential steps while
        every nonlinear element of a system sits in its region."""
        return None

    def rest_network(self) -> tuple[str, dict[str, float]] | None:
        """The linearisation about rest: (network text of springs ``k``, dampers ``c`` and
        inerters ``b`` over local names, {local name: value}), or ``None`` where the
        element carries no force for small motions about rest (an open circuit).

        A primitive declares its own; a composite's is that of its :meth:`expansion`
        with each part replaced by the part's linearisation."""
        exp = self.expansion()
        if exp is None:
            from ..errors import NetworkError

            raise NetworkError(
                f"element {type(self).__name__} ({self.prefix}) has no linearisation about "
                "rest: its class must define rest_network() or expansion() to take part in "
                "H2, the optimiser and the spectral analyses"
            )
        from ..networks import parse_network, substitute

        text, parts = exp
        return substitute(
            parse_network(text).tree, {local: el.rest_network() for local, el in parts.items()}
        )

    def scaled(self, factor: float) -> ElementBase:
        """``factor`` identical copies in parallel, moving together, as one element (a
        vehicle corner's several devices)."""
        raise ParameterError(
            self.prefix, self.description, "an element that declares how copies add (scaled)"
        )

    def _row(self, *values: float) -> np.ndarray:
        r = np.zeros(NPAR)
        r[: len(values)] = values
        return r
