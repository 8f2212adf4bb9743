"""Parameter sets of the linear half car and full car.

All values SI. Every class is a frozen keyword-only dataclass that checks its values
in ``__post_init__`` and names the offending parameter and its valid range.

Geometry and signs (ISO 8855 axes: x forward, y left, z up, origin at the sprung mass
centre of gravity): bounce z is positive up, pitch theta positive nose down, roll phi
positive left side up. A body point at (x, y) moves z - x theta + y phi.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import ParameterError, check_finite, check_nonnegative, check_positive

__all__ = ["CornerDevice", "corner_device", "Strut", "NetworkStrut", "split_stiffness", "Tyre", "Corner", "Seat", "HalfCar", "FullCar", "GRAVITY"]

GRAVITY = 9.81  # [m/s^2]


@dataclass(frozen=True, kw_only=True)
class Strut:
    """Suspension force law of one corner: spring, damper and inerter in parallel.

    The force pushing the body and the wheel apart is F = -(k x + c x' + b x''), with x
    the extension of the strut. :meth:`mck` gives its inertance, damping and stiffness
    at rest (a device's direct parts included) and :meth:`static_stiffness` the spring
    that carries the car.

    Parameters
    ----------
    stiffness : float
        k [N/m], >= 0.
    damping : float
        c [N s/m], >= 0.
    inertance : float
        b [kg], >= 0.
    adaptive : AdaptiveFlywheelInerter, optional
        An adaptive-flywheel inerter (:mod:`inerterlab.elements`) in parallel with the
        strut, laws ``thesis`` or ``momentum``. The time simulation (the model core's
        vehicle, :mod:`inerterlab.vehicles.simulation`) uses its speed-dependent
        inertance; the linear model (spectral method, modes) uses its rest inertance r^2 I_min, and
        :func:`~inerterlab.vehicles.stochastic.statistical_linearisation` its Gaussian
        equivalent.
    device : element or network text, optional
        A device of the model core in parallel with the strut: an element of
        :mod:`inerterlab.elements` (``HydraulicElement()``, ``RectifierElement()``,
        ``ScrewElement()``, ...) or a core network text whose element values come with
        ``device_parameters`` (:class:`CornerDevice`). The model core's vehicle places
        it as it is.
    device_parameters : dict, optional
        Element values by name for a ``device`` given as network text.
    """

    stiffness: float
    damping: float
    inertance: float = 0.0
    adaptive: Any = None
    device: Any = None
    device_parameters: Any = None

    def __post_init__(self) -> None:
        check_nonnegative("stiffness", self.stiffness, "N/m")
        check_nonnegative("damping", self.damping, "N s/m")
        check_nonnegative("inertance", self.inertance, "kg")
        if self.adaptive is not None:
            from ..elements import AdaptiveFlywheelInerter

            if not isinstance(self.adaptive, AdaptiveFlywheelInerter):
                raise ParameterError("adaptive", self.adaptive, "an AdaptiveFlywheelInerter")
            if self.adaptive.law not in ("thesis", "momentum"):
                raise ParameterError(
                    "adaptive.law", self.adaptive.law, "'thesis' or 'momentum' in a vehicle"
                )
        if self.device is not None:
            dev = corner_device(self.device, self.device_parameters)
            object.__setattr__(self, "device", dev)
            object.__setattr__(self, "device_parameters", None)
            if dev.adaptive is not None and self.adaptive is not None:
                raise ParameterError(
                    "device",
                    dev.source,
                    "a device without an adaptive inerter straight across it when the strut "
                    "has one (adaptive)",
                )
        elif self.device_parameters is not None:
            raise ParameterError("device_parameters", self.device_parameters, "None without a device")

    @property
    def adaptive_inerter(self):
        """The adaptive-flywheel inerter across the strut: ``adaptive`` or the device's."""
        if self.adaptive is not None or self.device is None:
            return self.adaptive
        return self.device.adaptive

    @property
    def linear_inertance(self) -> float:
        """b plus the adaptive inerter's rest inertance [kg] (the linear model's),
        a device's direct inerters included."""
        a = self.adaptive_inerter
        extra = 0.0 if a is None else a.inertance_min
        if self.device is not None:
            extra += self.device.inertance
        return float(self.inertance) + extra

    def _kc(self) -> tuple[float, float]:
        if self.device is None:
            return float(self.stiffness), float(self.damping)
        return (float(self.stiffness + self.device.stiffness),
                float(self.damping + self.device.damping))  # fmt: skip

    def mck(self) -> tuple[float, float, float]:
        """(b [kg], c [N s/m], k [N/m]); b includes an adaptive inerter at rest and k, c,
        b a device's direct parts (the rest is the core vehicle's alone)."""
        k, c = self._kc()
        return (self.linear_inertance, c, k)

    def static_stiffness(self) -> float:
        """k [N/m] (a device's direct springs included)."""
        return self._kc()[0]

    def scaled(self, factor: float) -> Strut:
        """The same law with every coefficient times ``factor`` (struts in parallel)."""
        if self.adaptive is not None:
            # factor identical flywheels at the same speed: one flywheel with every
            # inertia (rest, sliders) times factor and the same slider law l(w)
            fw = self.adaptive.wheel
            fw = replace(
                fw,
                rest_inertia=fw.rest_inertia * factor,
                slider_mass=fw.slider_mass * factor,
                spring_stiffness=fw.spring_stiffness * factor,
            )
            adaptive = replace(self.adaptive, flywheel=fw, changing_ratio=None)
        else:
            adaptive = None
        return Strut(
            stiffness=self.stiffness * factor,
            damping=self.damping * factor,
            inertance=self.inertance * factor,
            adaptive=adaptive,
            device=None if self.device is None else self.device.scaled(factor),
        )


def split_stiffness(network: str, num, den):
    """Z(s) = s num(s)/den(s) (the admittance's polynomials, highest power first) split
    exactly as b s^2 + c s + k + N(s)/D(s), D monic, deg N < deg D: (b, c, k, N, D).
    Any numeric type (complex values give the complex-step derivatives)."""
    zn = np.append(num, 0.0)  # s * num
    zd = np.asarray(den).copy()
    while zn.size > 1 and zd.size > 1 and zn[-1] == 0.0 and zd[-1] == 0.0:
        zn, zd = zn[:-1], zd[:-1]  # common factors s
    lead = zd[0]
    zn, zd = zn / lead, zd / lead
    if zn.size < zd.size:
        q, r = np.zeros(1), zn
    else:
        q, r = np.polydiv(zn, zd)
    q = np.concatenate([np.zeros(max(0, 3 - q.size)), q])
    if q.size > 3 or np.any(q[:-3]):
        raise ParameterError("network", network, "a dynamic stiffness of degree <= 2")
    r = np.atleast_1d(r)
    r = np.concatenate([np.zeros(max(0, zd.size - 1 - r.size)), r])[-(zd.size - 1) :]
    if zd.size == 1:
        r = np.zeros(0)
    return q[-3], q[-2], q[-1], r, zd


@dataclass(frozen=True)
class NetworkStrut:
    """Suspension law of one corner given as a linear two-terminal network.

    ``network`` is a network text of springs ``k``, dampers ``c`` and inerters ``b``
    (:mod:`inerterlab.networks`, e.g. ``"k | (c - b)"``) and ``values`` its element
    values by name (N/m, N s/m, kg). The force pushing body and wheel apart is
    -Z(s) x, x the strut's extension and Z(s) = s Y(s) its dynamic stiffness, Y the
    network's admittance.

    Z is split exactly (polynomial division, :func:`split_stiffness`) into a polynomial
    part b s^2 + c s + k (:meth:`mck`) and a strictly proper rest N(s)/D(s) whose poles
    are the network's internal modes. Z has no pole at s = 0 for any passive network, so
    the static stiffness Z(0) is finite; it may be zero (a damper in series with the only
    spring), which a static solve reports. The model core's vehicle places the network
    itself (:mod:`inerterlab.systems.vehicle`).

    Examples
    --------
    >>> law = NetworkStrut("k | (c - b)", {"k": 28e3, "c": 2200.0, "b": 150.0})
    >>> round(law.static_stiffness())
    28000
    """

    network: str
    values: Any

    def __post_init__(self) -> None:
        from ..networks import NetworkError, parse_network

        try:
            net = parse_network(self.network)
            net.require_linear()
            vec = net.parameter_vector(dict(self.values))
        except NetworkError as e:
            raise ParameterError("network", self.network, str(e)) from None
        object.__setattr__(self, "network", net.text)
        object.__setattr__(self, "values", tuple(zip(net.names, map(float, vec), strict=True)))

    @property
    def parameters(self) -> dict:
        """Element values by name."""
        return dict(self.values)

    @property
    def adaptive(self):
        """A network strut has no adaptive-flywheel inerter (None)."""
        return None

    def _split(self):
        """(b, c, k, rest numerator, rest denominator): Z = b s^2 + c s + k + N/D,
        highest power first, D monic, deg N < deg D."""
        from ..networks import admittance

        b, c, k, r, d = split_stiffness(self.network, *admittance(self.network, self.parameters))
        return float(b), float(c), float(k), r, d

    def mck(self) -> tuple[float, float, float]:
        """(b [kg], c [N s/m], k [N/m]) of the polynomial part of Z(s) (k may be < 0
        when the internal states carry part of the static stiffness)."""
        b, c, k, _, _ = self._split()
        return (b, c, k)

    def static_stiffness(self) -> float:
        """Z(0) [N/m]."""
        b, c, k, r, d = self._split()
        return k + (float(r[-1] / d[-1]) if d.size > 1 else 0.0)

    def scaled(self, factor: float) -> NetworkStrut:
        """The same network with every element value times ``factor`` (Y scales so)."""
        return NetworkStrut(self.network, {n: v * factor for n, v in self.values})


@dataclass(frozen=True, kw_only=True)
class Tyre:
    """Point-contact tyre: spring and damper in parallel, always in contact (linear).

    Parameters
    ----------
    stiffness : float
        k_t [N/m], > 0.
    damping : float
        c_t [N s/m], >= 0.
    """

    stiffness: float
    damping: float = 0.0

    def __post_init__(self) -> None:
        check_positive("tyre_stiffness", self.stiffness, "N/m")
        check_nonnegative("tyre_damping", self.damping, "N s/m")

    def mck(self) -> tuple[float, float, float]:
        return (0.0, float(self.damping), float(self.stiffness))

    def static_stiffness(self) -> float:
        """k_t [N/m]."""
        return float(self.stiffness)

    def scaled(self, factor: float) -> Tyre:
        return Tyre(stiffness=self.stiffness * factor, damping=self.damping * factor)


@dataclass(frozen=True, kw_only=True)
class Corner:
    """One wheel station: unsprung mass, suspension strut and tyre.

    In a half car a corner stands for a whole axle (both wheels lumped); in a full
    car for one wheel.
    """

    unsprung_mass: float
    strut: Strut
    tyre: Tyre

    def __post_init__(self) -> None:
        check_positive("unsprung_mass", self.unsprung_mass, "kg")
        if not isinstance(self.strut, Strut | NetworkStrut):
            raise ParameterError("strut", self.strut, "a Strut or a NetworkStrut")
        if not isinstance(self.tyre, Tyre):
            raise ParameterError("tyre", self.tyre, "a Tyre")

    def scaled(self, factor: float) -> Corner:
        """``factor`` identical corners lumped into one (masses and laws times factor)."""
        return Corner(
            unsprung_mass=self.unsprung_mass * factor,
            strut=self.strut.scaled(factor),
            tyre=self.tyre.scaled(factor),
        )


@dataclass(frozen=True, kw_only=True)
class Seat:
    """Seat and occupant as one mass on a cushion spring and damper.

    Parameters
    ----------
    x, y : float
        Position of the seat mounting on the body relative to the centre of gravity
        [m] (x forward, y left). A half car ignores ``y``.
    mass : float
        Seat plus occupant mass carried by the cushion [kg], > 0.
    stiffness, damping : float
        Cushion stiffness [N/m] > 0 and damping [N s/m] >= 0.
    """

    x: float = 0.0
    y: float = 0.0
    mass: float
    stiffness: float
    damping: float

    def __post_init__(self) -> None:
        check_finite("seat.x", self.x)
        check_finite("seat.y", self.y)
        check_positive("seat.mass", self.mass, "kg")
        check_positive("seat.stiffness", self.stiffness, "N/m")
        check_nonnegative("seat.damping", self.damping, "N s/m")


def _check_body(p) -> None:
    check_positive("sprung_mass", p.sprung_mass, "kg")
    check_positive("pitch_inertia", p.pitch_inertia, "kg m^2")
    check_positive("cg_to_front", p.cg_to_front, "m")
    check_positive("cg_to_rear", p.cg_to_rear, "m")
    check_positive("gravity", p.gravity, "m/s^2")
    for name in ("front", "rear"):
        if not isinstance(getattr(p, name), Corner):
            raise ParameterError(name, getattr(p, name), "a Corner")
    if p.seat is not None and not isinstance(p.seat, Seat):
        raise ParameterError("seat", p.seat, "a Seat or None")


@dataclass(frozen=True, kw_only=True)
class HalfCar:
    """Pitch-plane model: rigid body (bounce, pitch) on a front and a rear axle.

    Parameters
    ----------
    sprung_mass : float
        m [kg] (of the seat-less body).
    pitch_inertia : float
        I_y about the centre of gravity [kg m^2].
    cg_to_front, cg_to_rear : float
        a and b [m]; the wheelbase is a + b.
    front, rear : Corner
        Axles (both wheels lumped: twice a wheel's mass, strut and tyre).
    seat : Seat or None
        Optional seat at x = seat.x.
    gravity : float
        [m/s^2], for the static tyre loads.
    """

    sprung_mass: float
    pitch_inertia: float
    cg_to_front: float
    cg_to_rear: float
    front: Corner
    rear: Corner
    seat: Seat | None = None
    gravity: float = GRAVITY

    def __post_init__(self) -> None:
        _check_body(self)

    @property
    def wheelbase(self) -> float:
        return float(self.cg_to_front + self.cg_to_rear)

    def replace(self, **changes) -> HalfCar:
        return replace(self, **changes)


@dataclass(frozen=True, kw_only=True)
class FullCar:
    """Rigid body (bounce, pitch, roll) on four independent corners.

    Left and right corners of an axle are alike (``front`` and ``rear`` describe one
    wheel). Optional anti-roll bars add ``k_arb (x_left - x_right)^2 / 2`` to the
    potential energy, x the strut extensions: ``front_anti_roll`` is the rate felt
    at one wheel when the other is held [N/m].

    Parameters
    ----------
    sprung_mass, pitch_inertia, cg_to_front, cg_to_rear : float
        As for :class:`HalfCar`.
    roll_inertia : float
        I_x about the centre of gravity [kg m^2].
    front_track, rear_track : float
        Distance between the left and right wheel centres [m].
    front, rear : Corner
        One wheel of each axle.
    front_anti_roll, rear_anti_roll : float
        Anti-roll bar rates at the wheel [N/m], >= 0 (0: no bar).
    seat : Seat or None
    gravity : float
    """

    sprung_mass: float
    pitch_inertia: float
    roll_inertia: float
    cg_to_front: float
    cg_to_rear: float
    front_track: float
    rear_track: float
    front: Corner
    rear: Corner
    front_anti_roll: float = 0.0
    rear_anti_roll: float = 0.0
    seat: Seat | None = None
    gravity: float = GRAVITY

    def __post_init__(self) -> None:
        _check_body(self)
        check_positive("roll_inertia", self.roll_inertia, "kg m^2")
        check_positive("front_track", self.front_track, "m")
        check_positive("rear_track", self.rear_track, "m")
        check_nonnegative("front_anti_roll", self.front_anti_roll, "N/m")
        check_nonnegative("rear_anti_roll", self.rear_anti_roll, "N/m")

    @property
    def wheelbase(self) -> float:
        return float(self.cg_to_front + self.cg_to_rear)

    def replace(self, **changes) -> FullCar:
        return replace(self, **changes)

    def half_car(self) -> HalfCar:
        """The pitch-plane model of this car: each axle's two wheels lumped into one."""
        return HalfCar(
            sprung_mass=self.sprung_mass,
            pitch_inertia=self.pitch_inertia,
            cg_to_front=self.cg_to_front,
            cg_to_rear=self.cg_to_rear,
            front=self.front.scaled(2.0),
            rear=self.rear.scaled(2.0),
            seat=self.seat,
            gravity=self.gravity,
        )


@dataclass(frozen=True, eq=False)
class CornerDevice:
    """A device at a vehicle corner, in parallel with the strut (build with
    :func:`corner_device`): an element of :mod:`inerterlab.elements` or a network of
    them between the body-side terminal (node 0) and the wheel-side one (node 1).

    The model core's vehicle (:func:`inerterlab.systems.vehicle.vehicle`) places its
    ``nodes`` and ``edges`` as they are. Its springs, linear dampers and ideal inerters
    straight across the terminals are summed in ``stiffness``, ``damping`` and
    ``inertance`` (the strut's :meth:`Strut.mck` and static stiffness), and an
    adaptive-flywheel inerter straight across is ``adaptive``.
    """

    source: str
    stiffness: float
    damping: float
    inertance: float
    adaptive: Any
    edges: tuple = field(repr=False)
    nodes: tuple = field(repr=False)

    def __repr__(self) -> str:
        return f"CornerDevice({self.source!r})"

    def scaled(self, factor: float) -> CornerDevice:
        """``factor`` identical devices in parallel, moving together, as one."""
        edges = tuple((n, el.scaled(factor), t, b) for n, el, t, b in self.edges)
        return _split(f"{factor:g} x {self.source}", self.nodes, edges)


def corner_device(device, params: dict | None = None) -> CornerDevice:
    """``device`` (an element object, or a core network text with ``params``) laid out
    for a vehicle corner. ParameterError naming the network when it does not parse."""
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
    """The device of these edges, its direct linear parts and adaptive inerter read off."""
    from ..elements import kernel_law

    k = c = b = 0.0
    adaptive = None
    for _name, el, t, bt in edges:
        direct = {t, bt} == {0, 1}
        if direct and el.is_linear:  # one spring, damper or inerter by its linear law
            ((kind, value),) = el.rest_network()[1].items()
            if kind == "k":
                k += value
            elif kind == "c":
                c += value
            else:
                b += value
        elif (
            direct and kernel_law(el).inertial and el.law in ("thesis", "momentum")
            and adaptive is None
        ):  # an adaptive flywheel (the linear inerter went above)
            adaptive = el
    return CornerDevice(source, k, c, b, adaptive, edges, nodes)
