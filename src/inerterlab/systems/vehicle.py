"""Half car and full car as systems of the model core.

A vehicle is a :class:`~inerterlab.systems.System` like the rig and the quarter car:
the sprung body's coordinates (bounce z, pitch theta, and roll phi for the full car;
ISO 8855 signs, :mod:`inerterlab.vehicles.parameters`) are dynamic nodes whose masses
are the body's mass and moments of inertia about its centre of gravity; each wheel and
the seat is a mass of its own. A body point at (x, y) is a combination node (docs/model.md
§11) that moves z - x theta + y phi; every element attached to it passes its force to
the coordinates by those coefficients, and an inerter there stamps its inertance into
the mass matrix as b g g^T, coupling the coordinates. Each corner's suspension is any
network of the core between the body point (top) and its wheel (bottom): the struts
of :mod:`inerterlab.vehicles.parameters` (spring, damper, inerter, adaptive-flywheel
inerter, device) or a network text with its element values, placed once from the
parsed tree. An anti-roll bar is a spring element between two combination nodes, the
strut extensions of its axle's left and right corners (body point minus wheel). The
tyre is the :class:`~inerterlab.elements.tyre.Tyre` element between the wheel and its
own road node, which lifts off (an event of the integration) where the contact force
would be negative.

Coordinates are measured from static equilibrium (gravity balanced by the static
spring forces), as in the linear vehicle model. Roads: one per wheel station, in the
order of :attr:`System.info` ``["stations"]`` (front, rear; or front_left, front_right,
rear_left, rear_right), each linear between samples ``dt`` apart (:func:`simulate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_positive
from ..networks import NetworkError
from . import _integrate
from ._network import Layout, elements_of
from .core import _NO_REGIME, System, _failure, _laid_out, _options
from .options import SimulationOptions

__all__ = [
    "half_car", "full_car", "vehicle", "simulate", "VehicleResult", "static_tyre_loads",
    "rest_state", "road_segments", "enveloped", "StrutOptions",
]


@dataclass(frozen=True)
class StrutOptions:
    """What the time-domain options change at every corner: the damper's factors
    ``rebound`` (while the strut extends) and ``compression`` (while it shortens) [-],
    and a Coulomb ``friction`` [N] across each strut, regularised over
    ``friction_velocity`` [m/s] (:class:`~inerterlab.elements.Friction`)."""

    rebound: float = 1.0
    compression: float = 1.0
    friction: float = 0.0
    friction_velocity: float = 1e-3

    @property
    def asymmetric(self) -> bool:
        return self.rebound != 1.0 or self.compression != 1.0


def _strut_network(strut, opts: StrutOptions) -> tuple[str | None, dict, object]:
    """(network text, element values, device) of a corner strut of
    :mod:`inerterlab.vehicles.parameters`: its parallel spring, damper (asymmetric with
    ``opts``' factors), inerter and adaptive inerter as a network, and its device
    (placed from its own layout)."""
    from ..elements import AsymmetricDamper, Damper, Inerter, Spring
    from ..vehicles.parameters import NetworkStrut

    if isinstance(strut, NetworkStrut):
        if opts.asymmetric:
            raise ParameterError(
                "rebound/compression", (opts.rebound, opts.compression),
                f"1 with the network strut {strut.network!r}: an asymmetric damper needs a "
                "Strut, whose damper is one element (or write an asym element in the network)",
            )  # fmt: skip
        return strut.network, strut.parameters, None
    parts, vals = [], {}
    if strut.stiffness > 0:
        parts.append("k")
        vals["k"] = Spring(stiffness=strut.stiffness)
    if strut.damping > 0 and opts.asymmetric:
        parts.append("asym")
        vals["asym"] = AsymmetricDamper(rebound=opts.rebound * strut.damping,
                                        compression=opts.compression * strut.damping)  # fmt: skip
    elif strut.damping > 0:
        parts.append("c")
        vals["c"] = Damper(damping=strut.damping)
    if strut.inertance > 0:
        parts.append("b")
        vals["b"] = Inerter(inertance=strut.inertance)
    if strut.adaptive is not None:
        parts.append("afw")
        vals["afw"] = strut.adaptive
    return (" | ".join(parts) or None), vals, strut.device


def _stations(p):
    from ..vehicles.parameters import FullCar, HalfCar

    if isinstance(p, HalfCar):
        a, b = p.cg_to_front, p.cg_to_rear
        return ["bounce", "pitch"], [("front", a, 0.0, p.front), ("rear", -b, 0.0, p.rear)]
    if isinstance(p, FullCar):
        a, b = p.cg_to_front, p.cg_to_rear
        tf, tr = 0.5 * p.front_track, 0.5 * p.rear_track
        return ["bounce", "pitch", "roll"], [
            ("front_left", a, tf, p.front),
            ("front_right", a, -tf, p.front),
            ("rear_left", -b, tr, p.rear),
            ("rear_right", -b, -tr, p.rear),
        ]
    raise ParameterError("vehicle", type(p).__name__, "a HalfCar or a FullCar")


def vehicle(parameters, *, networks: dict | None = None, lift_off: bool = True,
            rebound: float = 1.0, compression: float = 1.0, friction: float = 0.0,
            friction_velocity: float = 1e-3) -> System:  # fmt: skip
    """The core system of a :class:`~inerterlab.vehicles.parameters.HalfCar` or
    :class:`~inerterlab.vehicles.parameters.FullCar` (or a vehicle file's path).

    ``networks`` replaces the suspension of named stations (``front``, ``rear``,
    ``front_left``, ...; an axle name sets both its corners of a full car) by
    ``(network text, element values)`` or an element object, between the body point
    (top) and the wheel. ``lift_off``: the tyres lift off where the contact force would
    be negative (nonlinear), or always press (linear: the tyre a spring and damper).
    ``rebound``, ``compression`` [-]: every strut's damper becomes an
    :class:`~inerterlab.elements.AsymmetricDamper` of rates rebound x c (extending) and
    compression x c (shortening); ``friction`` [N]: a Coulomb friction across every
    corner's suspension, regularised over ``friction_velocity`` [m/s]. The static equilibrium (and the tyres' static loads) come from Newton's method on
    the whole nonlinear balance with gravity (:func:`_rest`); ``info["equilibrium"]``
    holds it."""
    from ..errors import check_nonnegative
    from ..vehicles.config import load_vehicle

    p = parameters
    if isinstance(p, str) or hasattr(p, "read_text"):
        p = load_vehicle(p)
    opts = StrutOptions(
        check_positive("rebound", rebound), check_positive("compression", compression),
        check_nonnegative("friction", friction, "N"),
        check_positive("friction_velocity", friction_velocity, "m/s"),
    )  # fmt: skip
    _, stations = _stations(p)
    names = [s[0] for s in stations]
    overrides = {}
    for key, val in (networks or {}).items():
        hits = [n for n in names if n == key or n.startswith(key + "_")]
        if not hits:
            raise ParameterError("networks", key, f"a station or axle of {', '.join(names)}")
        for h in hits:
            overrides[h] = val
    lin = _build(p, overrides, None, opts)
    eq = _rest(lin)
    loads = _loads(eq)
    lin = eq.system
    lin.info["static_tyre_loads"] = loads
    lin.info["equilibrium"] = eq
    if not lift_off:
        return lin
    return _about(_build(p, overrides, loads, opts), lin.elements, eq)


def _rest(sys: System):
    """The static equilibrium of the vehicle ``sys`` (tyres always in contact) under its
    gravity, by Newton's method on the whole nonlinear balance
    (:func:`~inerterlab.systems.equilibrium.equilibrium`): linear springs and tyres carry
    their share (the coordinates stay deviations from rest for them), gas springs and bump
    stops take their law about their static extension."""
    from .equilibrium import equilibrium

    try:
        return equilibrium(sys, sys.info["parameters"].gravity)
    except NetworkError as e:
        if "held by no spring" in str(e):
            raise ParameterError(
                "struts", "no static stiffness",
                "a suspension that carries the car at rest (a network whose springs all "
                "sit in series with a damper carries no static load)",
            ) from None  # fmt: skip
        raise


def _loads(eq) -> dict:
    """Static contact force of each wheel station [N] from the equilibrium ``eq``."""
    out = {}
    for name in eq.original.info["stations"]:
        out[name] = -eq.forces[f"{name}_tyre"]
        if not out[name] > 0:
            raise ParameterError(f"{name} static tyre load", out[name], "> 0 N (the car rests on it)")
    return out


def _about(sys: System, rested: tuple, eq) -> System:
    """``sys`` (the same layout as ``eq``'s system, tyres that lift off) with its
    load-carrying nonlinear springs at their static operating points (``rested``)."""
    from .equilibrium import _rebuilt

    new = [o if r is was else r
           for o, r, was in zip(sys.elements, rested, eq.original.elements, strict=True)]  # fmt: skip
    out = _rebuilt(sys, new)
    out.info["equilibrium"] = eq
    return out


def half_car(parameters, **options) -> System:
    """:func:`vehicle` of a :class:`~inerterlab.vehicles.parameters.HalfCar`."""
    from ..vehicles.config import load_vehicle
    from ..vehicles.parameters import HalfCar

    p = load_vehicle(parameters) if isinstance(parameters, str) else parameters
    if not isinstance(p, HalfCar):
        raise ParameterError("parameters", type(p).__name__, 'a HalfCar (model = "half")')
    return vehicle(p, **options)


def full_car(parameters, **options) -> System:
    """:func:`vehicle` of a :class:`~inerterlab.vehicles.parameters.FullCar`."""
    from ..vehicles.config import load_vehicle
    from ..vehicles.parameters import FullCar

    p = load_vehicle(parameters) if isinstance(parameters, str) else parameters
    if not isinstance(p, FullCar):
        raise ParameterError("parameters", type(p).__name__, 'a FullCar (model = "full")')
    return vehicle(p, **options)


def _build(p, overrides: dict, loads: dict | None, opts: StrutOptions) -> System:
    """The vehicle's system; tyres with these static loads (None: no lift-off)."""
    from ..elements import Damper, Spring
    from ..elements.tyre import Tyre

    body, stations = _stations(p)
    full = len(body) == 3

    def make(arrange):
        lay = Layout(arrange)
        coord = {"bounce": lay.node("bounce", "mass", p.sprung_mass),
                 "pitch": lay.node("pitch", "mass", p.pitch_inertia)}  # fmt: skip
        if full:
            coord["roll"] = lay.node("roll", "mass", p.roll_inertia)

        def point(name, x, y, extra=()):  # a body point, plus other members
            i = lay.node(name, "combination")
            mem = [(coord["bounce"], 1.0), (coord["pitch"], -x)]
            if full and y:
                mem.append((coord["roll"], y))
            lay.nodes[i]["members"] = mem + list(extra)
            return i

        wheels = {}
        for j, (name, x, y, corner) in enumerate(stations):
            top = point(f"body_{name}", x, y)
            wheel = lay.node(f"wheel_{name}", "mass", corner.unsprung_mass)
            wheels[name] = (wheel, x, y)
            road = lay.node(f"road_{name}", "road")
            lay.nodes[road]["road"] = j
            t = corner.tyre
            tyre = Tyre(stiffness=t.stiffness, damping=t.damping,
                        static_load=None if loads is None else loads[name])  # fmt: skip
            lay.edges.append((f"{name}_tyre", tyre, wheel, road))
            _place_corner(lay, name, corner.strut, overrides.get(name), top, wheel, opts)
        if full:
            for axle, rate in (("front", p.front_anti_roll), ("rear", p.rear_anti_roll)):
                if rate > 0:  # a spring between the two strut extensions of the axle
                    ends = []
                    for side in ("left", "right"):
                        w, x, y = wheels[f"{axle}_{side}"]
                        ends.append(point(f"{axle}_anti_roll_{side}", x, y, [(w, -1.0)]))
                    lay.edges.append((f"{axle}_anti_roll", Spring(stiffness=rate), *ends))
        if p.seat is not None:
            s = p.seat
            seat = lay.node("seat", "mass", s.mass)
            mount = point("seat_mount", s.x, s.y if full else 0.0)
            lay.edges.append(("seat.k", Spring(stiffness=s.stiffness), mount, seat))
            if s.damping > 0:
                lay.edges.append(("seat.c", Damper(damping=s.damping), mount, seat))
        return lay

    kind = "full_car" if full else "half_car"
    desc = kind.replace("_", " ") + (" (tyres lift off)" if loads is not None else "")
    info = {"roads": len(stations), "stations": tuple(s[0] for s in stations),
            "parameters": p, "static_tyre_loads": loads, "body": tuple(body), "weightless": tuple(body[1:])}  # fmt: skip
    sys, lay = _laid_out(kind, desc, make, info)
    sys.info["layout"] = lay
    return sys


def _place_corner(lay: Layout, name: str, strut, override, top: int, wheel: int,
                  opts: StrutOptions) -> None:  # fmt: skip
    """Place a corner's suspension between the body point ``top`` and ``wheel``."""
    from ..elements import ElementBase, Friction

    device = None
    if opts.friction > 0:
        fric = Friction(force=opts.friction, velocity=opts.friction_velocity)
        lay.edges.append((f"{name}.strut_friction", fric, top, wheel))
    if override is not None:
        if opts.asymmetric:
            raise ParameterError(
                "rebound/compression", (opts.rebound, opts.compression),
                f"1 with a network at {name}: write an asym element in the network instead",
            )  # fmt: skip
        if isinstance(override, ElementBase):
            text, vals = override.prefix, {override.prefix: override}
        else:
            try:
                text, vals = override
            except (TypeError, ValueError):
                raise ParameterError(
                    f"networks[{name!r}]", override, "(network text, element values) or an element"
                ) from None
    else:
        text, vals, device = _strut_network(strut, opts)
    if text is not None:
        try:
            tree, els = elements_of(text, vals)
        except NetworkError as e:
            raise ParameterError(f"{name} network", text, str(e)) from None
        lay.place(tree, top, wheel, els, path=f"{name}.", text=f"{name}: {text}")
    if device is not None:  # its own layout: drive -> body point, ground -> wheel
        where = {0: top, 1: wheel}
        for i, nd in enumerate(device.nodes):
            if i > 1:
                where[i] = lay.node(f"{name}.dev.{nd['name']}", origin=f"{name} device {nd['name']}")
        for ename, el, t, b in device.edges:
            lay.edges.append((f"{name}.dev.{ename}", el, where[t], where[b]))


def static_tyre_loads(parameters, networks: dict | None = None) -> dict:
    """Static contact force of each wheel station [N] (see :func:`vehicle`)."""
    return dict(vehicle(parameters, networks=networks, lift_off=True).info["static_tyre_loads"])


def rest_state(sys: System, heights) -> np.ndarray:
    """The state at rest in static equilibrium on the road ``heights`` [m] (one per
    station, coordinates measured from the equilibrium on a level road): Newton's method
    on the whole nonlinear static balance of the system about its rest
    (:func:`~inerterlab.systems.equilibrium.equilibrium` without weight, which its rest
    already carries), velocities zero, element and observer states at rest."""
    from .equilibrium import equilibrium

    h = np.asarray(heights, float)
    if not np.any(h):
        return np.array(sys.x0_template, dtype=float)
    base = sys.info.get("base", sys)
    # with the tyres in contact (the same layout and states): a tyre that may lift off
    # has no stiffness where a start from the level rest would put it off the road
    eq = base.info.get("equilibrium")
    contact = eq.system if eq is not None else base
    x = equilibrium(contact, 0.0, heights=h).state
    return np.concatenate([x, sys.x0_template[base.n_states :]])


@dataclass(frozen=True, eq=False)
class VehicleResult:
    """A time simulation of a core vehicle: ``outputs`` the vehicle's named outputs
    (:func:`simulate`), ``signals`` every node and element output of the system,
    ``contact_force`` [N] and ``lift_off_fraction`` [-] per station, the integrator's
    ``stats``."""

    system: System
    time: np.ndarray
    states: np.ndarray
    outputs: dict
    contact_force: dict
    lift_off_fraction: dict
    stats: dict
    signals: dict


#: the step budget of a vehicle run unless the options say otherwise (a vehicle on a
#: long road takes many more steps than a quarter car)
VEHICLE_MAX_STEPS = 50_000_000


def simulate(sys: System, r, dt: float, *, options: SimulationOptions | None = None, x0=None,
             **option_values) -> VehicleResult:  # fmt: skip
    """Simulate the vehicle ``sys`` over the wheel heights ``r`` (n_t, stations) [m]
    sampled every ``dt`` [s], linear between samples (adaptive Dormand-Prince 5(4),
    ``atol`` = ``rtol`` x the state scales; the tyres' lift-off and landing located as
    events). Starts at rest in static equilibrium on the first heights (or at ``x0``).
    Outputs at the samples: ``bounce_acc``, ``pitch_acc``, ``roll_acc`` [m/s^2,
    rad/s^2], ``seat_acc``, ``<station>_deflection`` [m] (strut extension),
    ``<station>_tyre_load`` [N] (increase of the contact force); every node and
    element output of the system (:attr:`System.output_names`) in ``signals``. ``options``
    (:class:`~inerterlab.systems.options.SimulationOptions`, with keywords named as its
    fields replacing its values): tolerances, step control, ``max_steps`` (default
    :data:`VEHICLE_MAX_STEPS`); the samples are the road's. ``fixed_step``: steps of at
    most that length ending on every sample, no error control, lift-off and the other
    switches still located (``fixed_step = dt``: one step per road sample); by the
    Dormand-Prince pair's order-5 solution, or with ``fixed_method="rk4"`` (what the
    vehicle commands' ``--fixed-step`` take) by classical Runge-Kutta in its own driver
    (:func:`._integrate.integrate_fixed`; their errors and costs: docs/guide/vehicles.md,
    "Fixed steps")."""
    if sys.kind not in ("half_car", "full_car"):
        raise ParameterError("sys", sys.kind, "a vehicle (systems.vehicle.half_car/full_car)")
    dt = check_positive("dt", dt, "s")
    r = np.ascontiguousarray(np.asarray(r, dtype=float))
    m = sys.info["roads"]
    if r.ndim != 2 or r.shape[1] != m or r.shape[0] < 2 or not np.all(np.isfinite(r)):
        raise ParameterError("r", f"array of shape {r.shape}", f"finite heights (n_t >= 2, {m})")
    if options is None:
        options = SimulationOptions(max_steps=VEHICLE_MAX_STEPS)
    options = _options(options, option_values)
    options.warn_ignored("a vehicle run", "method", "sample_rate")
    rtol, max_steps = options.rtol, options.max_steps
    segs = road_segments(r, dt)
    ts = dt * np.arange(r.shape[0])
    T = float(ts[-1])
    y = rest_state(sys, r[0]) if x0 is None else np.array(x0, float)
    if y.shape != (sys.n_states,) or not np.all(np.isfinite(y)):
        raise ParameterError("x0", x0, f"{sys.n_states} finite states ({', '.join(sys.state_names)})")
    atol = options.atol_factor * np.maximum(sys.state_scales, 1e-12)
    Y = np.empty((ts.size, sys.n_states))
    st = np.zeros(5, dtype=np.int64)
    nseg = len(segs)
    itab, ftab = _factored(sys)
    O = np.empty((ts.size, len(sys.output_names)))
    rk4 = options.fixed_method == "rk4"
    if rk4:  # classical Runge-Kutta, its own driver; the outputs at the samples too
        status, _ = _integrate.integrate_fixed(
            itab, ftab, segs, y, T, float(options.fixed_step), ts, Y, st, int(max_steps), O
        )
    else:
        status, _ = _integrate.integrate(
            itab, ftab, segs, y, float(r[0, 0]), T, rtol, atol, sys.imp_unit, False,
            math.inf, ts, Y, st, np.zeros(nseg), int(max_steps), math.nan, math.inf,
            np.zeros(nseg), *_NO_REGIME, 1.0, options.step_control,
        )  # fmt: skip
    if status != _integrate.OK:
        raise _failure(sys, status, max_steps)
    if not rk4:
        _integrate.outputs_many(ts, Y, segs, itab, ftab, O)
    index = {n: j for j, n in enumerate(sys.output_names)}
    outs = {n: O[:, j] for n, j in index.items()}
    res = {}
    res["bounce_acc"] = outs["bounce.a"]
    res["pitch_acc"] = outs["pitch.a"]
    if "roll.a" in outs:
        res["roll_acc"] = outs["roll.a"]
    if "seat.a" in outs:
        res["seat_acc"] = outs["seat.a"]
    contact, lift = {}, {}
    loads = sys.info["static_tyre_loads"]
    stations = sys.info["stations"]
    # the columns these read, gathered in one pass over the rows of O (a column of O
    # read alone strides through all of it, once per use)
    cols = [index[f"{p}{name}{q}"] for name in stations
            for p, q in (("body_", ".x"), ("wheel_", ".x"), ("", "_tyre.force"))]  # fmt: skip
    G = np.ascontiguousarray(O[:, cols].T)
    for i, name in enumerate(stations):  # the deflections, then the tyre loads
        res[f"{name}_deflection"] = G[3 * i] - G[3 * i + 1]
    for i, name in enumerate(stations):
        f = G[3 * i + 2]
        res[f"{name}_tyre_load"] = -f
        contact[name] = loads[name] - f
        lift[name] = np.count_nonzero(contact[name] <= 1e-9 * loads[name]) / f.size
    stats = {"steps": int(st[0]), "rejected": int(st[1]), "rhs_calls": int(st[2]),
             "events": int(st[3])}  # fmt: skip
    return VehicleResult(sys, ts, Y, res, contact, lift, stats, outs)


def _factored(sys: System) -> tuple[np.ndarray, np.ndarray]:
    """The tables of ``sys`` with its mass matrix factored beforehand
    (:func:`._kernel.dense_tables`: the body, wheels and seat have their own masses, so
    the mass matrix is constant but for the flywheels' inertances, which the right-hand
    side adds by the Woodbury identity instead of solving the whole matrix at every
    call), or its own tables where that does not apply (a device with massless internal
    nodes). Kept on the system for its parameter rows."""
    from ._kernel import dense_tables

    got = sys.info.get("factored")
    if got is None or got[0] is not sys.ftab:
        tabs = dense_tables(sys.itab, sys.ftab) or (sys.itab, sys.ftab)
        got = (sys.ftab, tabs)
        sys.info["factored"] = got
    return got[1]


def road_segments(r: np.ndarray, dt: float) -> np.ndarray:
    """Segments of kind 3 (:func:`._integrate.road_at`): per sample interval, each
    road's height at its start and its rate."""
    n, m = r.shape
    width = max(3 + 2 * m, 9)
    segs = np.zeros((n - 1, width))
    t = dt * np.arange(n)
    segs[:, 0] = t[:-1]
    segs[:, 1] = t[1:]
    segs[:, 2] = 3.0
    segs[:, 3 : 3 + 2 * m : 2] = r[:-1]
    segs[:, 4 : 4 + 2 * m : 2] = np.diff(r, axis=0) / dt
    return segs




def enveloped(r, dt: float, speed: float, contact_length: float) -> np.ndarray:
    """Wheel heights [m] seen through a tyre's contact patch: the moving average of each
    column of ``r`` (samples ``dt`` [s] apart, linear between them) over the time
    ``contact_length`` / ``speed`` the patch takes to pass a point, centred on each
    sample; the road is held level beyond its ends.

    A point contact follows every wavelength of the road; a real tyre bridges those
    shorter than its contact patch. The moving average over a patch of length L
    multiplies a wave of wavelength lambda by sin(pi L / lambda) / (pi L / lambda)
    (the average of a sine over a window): about 0.6 at lambda = 2 L, zero at
    lambda = L, so a 0.2 m patch takes most of the band above 5 cycle/m. It is the
    simplest enveloping model, a flat patch (no tandem-cam or basic-curve model).

    >>> import numpy as np
    >>> t = np.arange(10001) * 2e-4
    >>> r = np.sin(2 * np.pi * 25.0 * t)[:, None]  # 0.8 m wavelength at 20 m/s
    >>> y = enveloped(r, 2e-4, 20.0, 0.4)            # 0.4 m patch: factor 2/pi
    >>> round(float(np.abs(y[2000:8000]).max()), 3), round(2 / np.pi, 3)
    (0.637, 0.637)
    """
    dt = check_positive("dt", dt, "s")
    v = check_positive("speed", speed, "m/s")
    L = check_positive("contact_length", contact_length, "m")
    r = np.asarray(r, dtype=float)
    if r.ndim != 2 or r.shape[0] < 2 or not np.all(np.isfinite(r)):
        raise ParameterError("r", f"array of shape {r.shape}", "finite heights (n_t >= 2, n_roads)")
    n = r.shape[0]
    half = 0.5 * L / v
    t = dt * np.arange(n)
    slope = np.diff(r, axis=0) / dt
    C = np.vstack([np.zeros((1, r.shape[1])), np.cumsum(0.5 * dt * (r[:-1] + r[1:]), axis=0)])

    def integral(x):  # the integral of the road from t = 0 to x, held level outside
        xc = np.clip(x, 0.0, t[-1])
        k = np.minimum((xc / dt).astype(int), n - 2)
        u = (xc - t[k])[:, None]
        val = C[k] + r[k] * u + 0.5 * slope[k] * u * u
        return val + r[0] * np.minimum(x, 0.0)[:, None] + r[-1] * np.maximum(x - t[-1], 0.0)[:, None]

    return (integral(t + half) - integral(t - half)) / (2.0 * half)
