"""Sweeps and optimisation over vehicle parameters, by the spectral method.

Design parameters are per axle: ``front_stiffness``, ``front_damping``,
``front_inertance``, ``rear_...`` (the strut of each corner of that axle, [N/m],
[N s/m], [kg]), plus ``speed`` and ``road_class``. The ``vehicle-spectral`` point
function evaluates the linear vehicle (a TOML file, default the packaged example) with
those overrides on an ISO 8608 road by the spectral method and returns the RMS values
of :data:`SPECTRAL_METRICS`; any sweep (serial, processes, Dask; stored and resumable)
can use it. :func:`optimize_vehicle` minimises one RMS value over chosen parameters
within bounds, optionally with upper limits on others (a penalty-free SLSQP with
multi-start from a Sobol sample), so "the rear damping that minimises seat comfort with
the front and rear deflection below 12 mm" is one call.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError, check_seed, check_unique
from ..studies.points import ParameterSpec, PointFunction, register_point_function

__all__ = ["DESIGN_PARAMETERS", "SPECTRAL_METRICS", "H2_METRICS", "h2_metrics",
           "h2_metric_gradient", "vehicle_with",
           "spectral_metrics",
           "optimize_vehicle", "VehicleOptimum", "design_parameters", "default_parameters"]  # fmt: skip

_FIELDS = {"stiffness": "N/m", "damping": "N s/m", "inertance": "kg"}
#: design parameters: name -> unit
DESIGN_PARAMETERS = {f"{a}_{f}": u for a in ("front", "rear") for f, u in _FIELDS.items()}
#: metrics of the ``vehicle-spectral`` point (worst corner of each axle for corner values)
SPECTRAL_METRICS = (
    "comfort_wk",
    "bounce_acc",
    "pitch_acc",
    "front_deflection",
    "rear_deflection",
    "front_tyre_load",
    "rear_tyre_load",
    "front_lift_off_probability",
    "rear_lift_off_probability",
)


def _require_strut(strut, axle: str, field: str) -> None:
    network = getattr(strut, "network", None)
    if network is not None:
        raise ParameterError(
            f"{axle}_{field}",
            network,
            f"a {axle} strut of spring, damper and inerter in parallel; the {axle} axle "
            f"has the network strut {network!r}, whose element values the vehicle file sets",
        )


def _network_element(params, name: str):
    """(axle, element) if ``name`` is ``<axle>_<element>`` of a network strut of
    ``params``, else None."""
    axle, _, elem = name.partition("_")
    if axle not in ("front", "rear") or not hasattr(params, axle):
        return None
    values = getattr(getattr(params, axle).strut, "parameters", None)
    return (axle, elem) if values is not None and elem in values else None


def _classes(strut) -> list:
    from ..networks import parse_network

    return [e.cls for e in parse_network(strut.network).tree.elements()]


def design_parameters(params) -> dict:
    """Every design parameter of the vehicle ``params``: name -> unit. A Strut axle has
    ``<axle>_stiffness``, ``_damping``, ``_inertance``; a network axle one per element
    (``front_k``, ``front_c``, ``front_b`` for ``k | (c - b)``)."""
    out = {}
    for axle in ("front", "rear"):
        strut = getattr(params, axle).strut
        if getattr(strut, "network", None) is None:
            out.update({f"{axle}_{f}": u for f, u in _FIELDS.items()})
        else:
            for (n, _), cls in zip(strut.values, _classes(strut), strict=True):
                out[f"{axle}_{n}"] = cls.PARAMETERS[0].unit
    return out


def default_parameters(params) -> list:
    """The dampers of both axles: ``<axle>_damping`` of a Strut, each damper element
    ``<axle>_c...`` of a network strut."""
    out = []
    for axle in ("front", "rear"):
        strut = getattr(params, axle).strut
        if getattr(strut, "network", None) is None:
            out.append(f"{axle}_damping")
        else:
            out += [f"{axle}_{n}" for (n, _), cls in zip(strut.values, _classes(strut),
                                                         strict=True) if cls.ROLE == "dissipative"]  # fmt: skip
    return out


def vehicle_with(params, **overrides):
    """Vehicle parameters with per-axle strut values replaced (``front_damping=...``;
    for a network strut its elements by name, ``front_b=...``)."""
    changes: dict[str, dict] = {"front": {}, "rear": {}}
    net_changes: dict[str, dict] = {"front": {}, "rear": {}}
    for k, v in overrides.items():
        element = _network_element(params, k)
        if k in DESIGN_PARAMETERS:
            axle, field = k.split("_", 1)
            changes[axle][field] = float(v)
        elif element is not None:
            axle, elem = element
            net_changes[axle][elem] = float(v)
        else:
            raise ParameterError(k, v, "one of " + ", ".join(design_parameters(params)))
    out = {}
    for axle, ch in changes.items():
        if ch:
            c = getattr(params, axle)
            _require_strut(c.strut, axle, next(iter(ch)))
            out[axle] = dataclasses.replace(c, strut=dataclasses.replace(c.strut, **ch))
    for axle, ch in net_changes.items():
        if ch:
            from .parameters import NetworkStrut

            c = getattr(params, axle)
            strut = NetworkStrut(c.strut.network, {**c.strut.parameters, **ch})
            out[axle] = dataclasses.replace(c, strut=strut)
    return dataclasses.replace(params, **out) if out else params


def _axle_max(rms: dict, corners, axle: str, what: str) -> float:
    return max(rms[f"{c}_{what}"] for c in corners if c.startswith(axle))


def spectral_metrics(params, road_class: str = "C", speed: float = 20.0, points: int = 1500):
    """:data:`SPECTRAL_METRICS` of the vehicle ``params`` (HalfCar or FullCar)."""
    from .linear import linear_vehicle
    from .roads import road_spectrum
    from .spectral import spectral_response

    veh = linear_vehicle(params)
    res = spectral_response(veh, road_spectrum(road_class), speed, points=points)
    acc = "seat_acc_wk" if "seat_acc_wk" in res.rms else "bounce_acc_wk"
    out = {
        "comfort_wk": res.rms[acc],
        "bounce_acc": res.rms["bounce_acc"],
        "pitch_acc": res.rms["pitch_acc"],
    }
    for axle in ("front", "rear"):
        out[f"{axle}_deflection"] = _axle_max(res.rms, veh.corners, axle, "deflection")
        out[f"{axle}_tyre_load"] = _axle_max(res.rms, veh.corners, axle, "tyre_load")
        out[f"{axle}_lift_off_probability"] = max(
            res.lift_off[c] for c in veh.corners if c.startswith(axle)
        )
    return out


#: metrics by Lyapunov under white road velocity (ISO 8608 of waviness 2 without band
#: limits, the chosen class and speed; tracks independent, the rear wheels delayed by
#: the wheelbase): name -> (output, weighting or None); RMS in m/s^2
H2_METRICS = {
    "seat_wk": ("seat_acc", "Wk"),
    "body_acc_wk": ("bounce_acc", "Wk"),
    "body_acc": ("bounce_acc", None),
}


def h2_metrics(params, road_class: str = "C", speed: float = 20.0, names=None) -> dict:
    """RMS values [m/s^2] of :data:`H2_METRICS` (all, or ``names``) of the vehicle
    ``params`` on an ISO 8608 road of class ``road_class`` at ``speed`` [m/s] with
    waviness 2 and no band limits: the H2 norm under white road velocity
    (:func:`~inerterlab.vehicles.spectral.white_velocity_h2`, the Wk filter's states
    cascaded after the output, the wheelbase delay exact) times the road's velocity
    scale pi n0 sqrt(2 Gd(n0) V). ``seat_wk`` needs a seat in the vehicle."""
    from ..network_design import road_scale
    from .linear import linear_vehicle
    from .spectral import white_velocity_h2

    names = list(H2_METRICS if names is None else names)
    if "seat_wk" in names and getattr(params, "seat", None) is None:
        raise ParameterError(
            "objective", "seat_wk", "a vehicle with a [seat] (this file has none; use body_acc_wk)"
        )
    veh = linear_vehicle(params)
    weighted = {n: H2_METRICS[n] for n in names if H2_METRICS[n][1] is not None}
    plain = [H2_METRICS[n][0] for n in names if H2_METRICS[n][1] is None]
    h = white_velocity_h2(veh, speed=speed, weighted=weighted, outputs=plain)
    k = road_scale(road_class, speed)
    return {n: h[n if H2_METRICS[n][1] else H2_METRICS[n][0]] * k for n in names}


#: imaginary step carrying a design value's derivative through the H2 system
_STEP = 1e-20
#: a Strut's fields -> the element names of its corner network
_STRUT_ELEMENTS = {"stiffness": "k", "damping": "c", "inertance": "b"}


def _corner_element(params, name: str) -> tuple[str, str, float]:
    """(axle, element name at each of its corners, value) of the design parameter
    ``name`` (``front_damping``; ``rear_c`` of a network strut)."""
    axle, _, field = name.partition("_")
    strut = getattr(params, axle).strut if axle in ("front", "rear") else None
    if strut is None:
        raise ParameterError("names", name, "one of " + ", ".join(design_parameters(params)))
    if getattr(strut, "network", None) is not None:
        if field not in strut.parameters:
            raise ParameterError("names", name, "one of " + ", ".join(design_parameters(params)))
        return axle, field, float(strut.parameters[field])
    if field not in _STRUT_ELEMENTS:
        raise ParameterError("names", name, "one of " + ", ".join(design_parameters(params)))
    return axle, _STRUT_ELEMENTS[field], float(getattr(strut, field))


def _blocks(ss) -> list:
    """The vehicle state space (A, Br, Bd, Cy, Dr, Dd) as a flat list of arrays."""
    A, Br, Bd, Cy, Dr, Dd = ss
    return [A, Br, Bd, *(d[k] for d in (Cy, Dr, Dd) for k in sorted(d))]


def _unblocks(flat, like) -> tuple:
    keys = sorted(like[3])
    n = len(keys)
    dicts = [dict(zip(keys, flat[3 + i * n : 3 + (i + 1) * n], strict=True)) for i in range(3)]
    return (flat[0], flat[1], flat[2], *dicts)


def _moebius_slope(base: list, t1: float, at1: list, t2: float, at2: list) -> list:
    """dM/dt at t = 0 of matrices M(t) = M0 + t / (1 + sigma t) W (one sigma for all),
    from M0 = ``base`` and M at t1, t2: W itself, exact to rounding.

    Every matrix of a linear car's state space has that form in one element's value t:
    the element enters the car's equations as a rank-one term t g h^T (a spring's or a
    damper's force, an inerter's inertance), so by the Sherman-Morrison formula the
    solved matrices move along one direction W with the common factor t / (1 + sigma t)
    (sigma = 0 where the value enters no inverse: a stiffness, a damping at a body)."""
    d1 = [a - b for a, b in zip(at1, base, strict=True)]
    d2 = [a - b for a, b in zip(at2, base, strict=True)]
    big = max(range(len(d1)), key=lambda i: float(np.max(np.abs(d1[i]), initial=0.0)))
    j = int(np.argmax(np.abs(d1[big])))
    x1, x2 = float(d1[big].flat[j]), float(d2[big].flat[j])
    if x1 == 0.0:
        return [np.zeros_like(b) for b in base]
    r = x1 / x2  # = t1 (1 + sigma t2) / (t2 (1 + sigma t1))
    sigma = (t1 - r * t2) / (t1 * t2 * (r - 1.0))
    return [0.5 * (a * (1 + sigma * t1) / t1 + b * (1 + sigma * t2) / t2)
            for a, b in zip(d1, d2, strict=True)]  # fmt: skip


def _state_space_at(veh, station: str, element: str, value: float, params, axle: str):
    """The vehicle state space of ``veh`` with the element ``element`` of the corner
    ``station`` at ``value`` (added to the corner's network where the car has none)."""
    from ..systems.equilibrium import _rebuilt
    from ..systems.vehicle import StrutOptions, _strut_network, vehicle
    from .linear import from_state_space

    sys = veh.system
    name = f"{station}.{element}"
    if name in sys.element_names:
        e = sys.element_names.index(name)
        el = sys.elements[e]
        new = list(sys.elements)
        new[e] = dataclasses.replace(el, **{el.PARAMETERS[0].name: value})
        stepped = _rebuilt(sys, new)
    else:  # a Strut's field at 0: the corner rebuilt with that element
        strut = getattr(params, axle).strut
        field = next(f for f, n in _STRUT_ELEMENTS.items() if n == element)
        text, vals, _ = _strut_network(dataclasses.replace(strut, **{field: value}),
                                       StrutOptions())  # fmt: skip
        stepped = vehicle(params, networks={station: (text, vals)}, lift_off=False)
    return from_state_space(stepped, stepped.linear_state_space(), False)._ss


def state_space_derivatives(params, veh, names, log: bool = True) -> list:
    """d(A, Br, Bd, Cy, Dr, Dd)/d parameter of the linear vehicle ``veh`` (its
    :class:`~inerterlab.vehicles.linear.LinearVehicle`, :func:`linear_vehicle`) of
    ``params`` for each design parameter of ``names`` (per axle: both corners of a full
    car's axle), in its logarithm if ``log``; in the layout of the vehicle's state space.

    Exact to rounding: each corner's element value enters the state space as a rank-one
    term, so two more state spaces of the core car with that value moved fix the
    direction and the curvature of the whole (:func:`_moebius_slope`); the axle's
    derivative is the sum over its corners. Checked against central differences of the
    core's state space (tests/test_vehicle_design_gradient.py; the H2 gradients against
    differences of the norm in tests/test_design_gradient.py)."""
    base = _blocks(veh._ss)
    out = []
    for n in names:
        axle, element, value = _corner_element(params, n)
        total = [np.zeros_like(b) for b in base]
        if value != 0.0 or not log:
            stations = [st for st in veh.system.info["stations"]
                        if st == axle or st.startswith(axle + "_")]  # fmt: skip
            t = 0.5 * value if value > 0.0 else 1.0
            for st in stations:
                at1 = _blocks(_state_space_at(veh, st, element, value + t, params, axle))
                at2 = _blocks(_state_space_at(veh, st, element, value + 2 * t, params, axle))
                for i, d in enumerate(_moebius_slope(base, t, at1, 2 * t, at2)):
                    total[i] = total[i] + d
            if log:
                total = [d * value for d in total]
        out.append(_unblocks(total, veh._ss))
    return out


def h2_metric_gradient(params, objective: str, names, road_class: str = "C",
                       speed: float = 20.0, *, log: bool = True) -> tuple:  # fmt: skip
    """The RMS value of :data:`H2_METRICS` ``objective`` [m/s^2] of the vehicle ``params``
    (as :func:`h2_metrics`) and its derivatives in the logarithms of the design
    parameters ``names`` (:func:`design_parameters`: ``front_damping``, ``rear_c``...;
    one axle's value sets both its corners), or in the values themselves if not ``log``.

    Exact: the variance's gradient with respect to the state-space matrices comes from
    the adjoint Lyapunov equations (:func:`inerterlab.h2.variance_gradient`, the
    wheelbase delay and the Wk states included); the matrices' derivatives in each
    parameter from the core car's state space with that value moved
    (:func:`state_space_derivatives`), exact to rounding. (inf, None) where the norm is infinite;
    ConvergenceError where a Lyapunov equation has no finite solution."""
    from ..network_design import road_scale
    from .linear import linear_vehicle
    from .spectral import white_velocity_h2_gradient

    if objective not in H2_METRICS:
        raise ParameterError("objective", objective, "one of " + ", ".join(H2_METRICS))
    if objective == "seat_wk" and getattr(params, "seat", None) is None:
        raise ParameterError(
            "objective", "seat_wk", "a vehicle with a [seat] (this file has none; use body_acc_wk)"
        )
    veh = linear_vehicle(params)
    steps = stepped_vehicles(params, veh, names, log)
    out, weighting = H2_METRICS[objective]
    v, g = white_velocity_h2_gradient(veh, out, steps, speed=speed, weighting=weighting)
    if not math.isfinite(v):
        return math.inf, None
    k = road_scale(road_class, speed)
    return v * k, np.asarray(g) * k


def stepped_vehicles(params, veh, names, log: bool = True) -> list:
    """(vehicle, h) per design parameter of ``names``: the linear vehicle ``veh`` of
    ``params`` whose state space carries h x its derivative in that value (its logarithm
    if ``log``, :func:`state_space_derivatives`) as the imaginary part, for
    :func:`~inerterlab.vehicles.spectral.white_velocity_h2_gradient`."""
    steps = []
    for d in state_space_derivatives(params, veh, names, log):
        flat = [b + 1j * _STEP * db for b, db in zip(_blocks(veh._ss), _blocks(d), strict=True)]
        steps.append((dataclasses.replace(veh, _ss=_unblocks(flat, veh._ss)), _STEP))
    return steps


def _load(path: str):
    from .config import example_vehicle_path, load_vehicle

    return load_vehicle(path if path else example_vehicle_path())


def _example_path():
    from .config import example_vehicle_path

    return example_vehicle_path()


def _point(params: Mapping[str, Any]) -> dict[str, float]:
    base = _load(params["vehicle"])
    over = {k: params[k] for k in DESIGN_PARAMETERS if params.get(k) is not None}
    return spectral_metrics(
        vehicle_with(base, **over), params["road_class"], float(params["speed"])
    )


VEHICLE_SPECTRAL = register_point_function(
    PointFunction(
        name="vehicle-spectral",
        function=_point,
        parameters={
            "vehicle": ParameterSpec(
                kind="file", empty=_example_path, doc="vehicle TOML file ('' = example)"
            ),
            "road_class": ParameterSpec(kind="choice", choices=tuple("ABCDEFGH")),
            "speed": ParameterSpec(low=0.0, low_open=True, high=100.0, unit="m/s"),
            **{
                k: ParameterSpec(low=0.0, high=1e8, unit=u, doc=f"strut {k.replace('_', ' ')}")
                for k, u in DESIGN_PARAMETERS.items()
            },
        },
        defaults={"vehicle": "", "road_class": "C", "speed": 20.0}
        | dict.fromkeys(DESIGN_PARAMETERS),
        metrics=SPECTRAL_METRICS,
    )
)


@dataclass(frozen=True)
class VehicleOptimum:
    """Result of :func:`optimize_vehicle`."""

    objective: str
    value: float
    parameters: dict
    metrics: dict
    limits: dict
    feasible: bool
    at_bound: list
    baseline: dict

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


def optimize_vehicle(
    *,
    vehicle: str = "",
    objective: str = "comfort_wk",
    parameters=None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    limits: Mapping[str, float] | None = None,
    road_class: str = "C",
    speed: float = 20.0,
    starts: int = 8,
    seed: int = 0,
) -> VehicleOptimum:
    """Minimise ``objective`` over ``parameters``: one of :data:`SPECTRAL_METRICS` (the
    spectral method on the band-limited road) or of :data:`H2_METRICS` (``seat_wk``:
    the RMS of the Wk-weighted seat acceleration under white road velocity, exact by
    Lyapunov with the Wk filter as states, :func:`h2_metrics`).

    ``parameters`` defaults to the dampers of both axles: ``front_damping`` and
    ``rear_damping`` of a Strut axle, every damper element (``front_c``, ...) of a
    network axle (:func:`default_parameters`). ``bounds``: name -> (low, high), default 0.25-4 times the file's value (a zero value
    gets 0 to 500 kg / 1e4 N s/m / 1e5 N/m). ``limits``: metric -> upper limit. SLSQP in
    log-scaled coordinates from the ``starts`` best points of a Sobol sample.
    """
    from scipy.optimize import minimize
    from scipy.stats import qmc

    if objective not in SPECTRAL_METRICS and objective not in H2_METRICS:
        raise ParameterError(
            "objective", objective, "one of " + ", ".join([*SPECTRAL_METRICS, *H2_METRICS])
        )
    base = _load(vehicle)
    names = list(default_parameters(base) if parameters is None else parameters)
    if not names:
        raise ParameterError("parameters", names, "at least one design parameter")
    valid = design_parameters(base)
    for n in names:
        if n not in valid:
            raise ParameterError("parameters", n, "one of " + ", ".join(valid))
    for n in bounds or {}:
        if n not in names:
            raise ParameterError(
                "bound",
                n,
                "a bound on a design parameter of this run: "
                + ", ".join(names)
                + (" (add it with --parameter)" if n in valid else ""),
            )
    if isinstance(starts, bool) or not isinstance(starts, int) or not 1 <= starts <= 100:
        raise ParameterError("starts", starts, "an integer in [1, 100]")
    check_seed("seed", seed)
    check_unique("parameters", names)
    limits = dict(limits or {})
    for k, v in limits.items():
        if k not in SPECTRAL_METRICS:
            raise ParameterError("limit", k, "one of " + ", ".join(SPECTRAL_METRICS))
        if not (isinstance(v, int | float) and v > 0 and math.isfinite(v)):
            raise ParameterError(f"limit {k}", v, "a positive number")
    defaults = {"inertance": 500.0, "damping": 1e4, "stiffness": 1e5}
    lo, hi = [], []
    for n in names:
        axle, field = n.split("_", 1)
        strut = getattr(base, axle).strut
        if getattr(strut, "network", None) is not None:
            v0 = float(strut.parameters[field])  # elements are > 0
        else:
            v0 = float(getattr(strut, field))
        b = (bounds or {}).get(n)
        if b is None:
            b = (0.25 * v0, 4.0 * v0) if v0 > 0 else (0.0, defaults[field])
        l, h = float(b[0]), float(b[1])
        if not (0 <= l < h and math.isfinite(h)):
            raise ParameterError(f"bound {n}", b, "0 <= low < high")
        lo.append(l)
        hi.append(h)
    lo, hi = np.array(lo), np.array(hi)
    # map u in [0, 1] to the box; log spacing where the low bound is positive
    logs = lo > 0

    def x_of(u):
        u = np.clip(u, 0.0, 1.0)
        return np.where(logs, lo * (hi / np.where(logs, lo, 1.0)) ** u, lo + (hi - lo) * u)

    cache: dict[bytes, dict] = {}

    h2_names = [objective] if objective in H2_METRICS else []
    spectral = objective in SPECTRAL_METRICS or bool(limits)
    if h2_names:
        h2_metrics(base, road_class, speed, h2_names)  # a seat for seat_wk, before the search

    def evaluate(p):
        out = spectral_metrics(p, road_class, speed) if spectral else {}
        if h2_names:
            from ..errors import ConvergenceError

            try:
                out.update(h2_metrics(p, road_class, speed, h2_names))
            except ConvergenceError:  # an unstable vehicle inside the bounds
                out.update(dict.fromkeys(h2_names, math.inf))
        return out

    def metrics(u):
        key = np.asarray(u, dtype=float).round(12).tobytes()
        if key not in cache:
            cache[key] = evaluate(vehicle_with(base, **dict(zip(names, x_of(u), strict=True))))
        return cache[key]

    def f(u):
        return metrics(u)[objective]

    jac = None
    if h2_names:
        # exact (adjoint Lyapunov equations, complex steps of the matrices): a central
        # difference would amplify the norm's rounding of about 1e-10 relative
        span = np.where(logs, np.log(hi / np.where(logs, lo, 1.0)), hi - lo)

        def jac(u):
            from ..errors import ConvergenceError

            x = x_of(u)
            try:
                _, g = h2_metric_gradient(vehicle_with(base, **dict(zip(names, x, strict=True))),
                                          objective, names, road_class, speed, log=False)  # fmt: skip
            except ConvergenceError:
                g = None
            if g is None:
                return np.zeros(u.size)
            inside = (np.asarray(u) >= 0.0) & (np.asarray(u) <= 1.0)
            return np.where(inside, g * np.where(logs, x, 1.0) * span, 0.0)

    cons = [
        {"type": "ineq", "fun": (lambda u, k=k, v=v: 1.0 - metrics(u)[k] / v)}
        for k, v in limits.items()
    ]
    sob = qmc.Sobol(len(names), scramble=True, seed=seed)
    U = sob.random(32 if len(names) < 3 else 64)

    def penalised(u):
        m = metrics(u)
        viol = sum(max(0.0, m[k] / v - 1.0) for k, v in limits.items())
        return (viol > 0, m[objective] * (1 + viol))

    order = sorted(range(len(U)), key=lambda i: penalised(U[i]))
    best = None
    for i in order[: max(1, int(starts))]:
        r = minimize(f, U[i], jac=jac, method="SLSQP", bounds=[(0.0, 1.0)] * len(names),
                     constraints=cons, options={"maxiter": 200, "ftol": 1e-12})  # fmt: skip
        u = np.clip(r.x, 0.0, 1.0)
        m = metrics(u)
        ok = all(m[k] <= v * (1 + 1e-6) for k, v in limits.items())
        cand = (not ok, m[objective], u)
        if best is None or cand[:2] < best[:2]:
            best = cand
    u = best[2]
    x = x_of(u)
    m = metrics(u)
    at_bound = [n for n, ui in zip(names, u, strict=True) if ui < 1e-6 or ui > 1 - 1e-6]
    return VehicleOptimum(
        objective=objective,
        value=float(m[objective]),
        parameters={n: float(v) for n, v in zip(names, x, strict=True)},
        metrics={k: float(v) for k, v in m.items()},
        limits=limits,
        feasible=not best[0],
        at_bound=at_bound,
        baseline={k: float(v) for k, v in evaluate(base).items()},
    )
