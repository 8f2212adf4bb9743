"""Half- and full-car design: the same layout at every corner, its values per axle.

A vehicle *car* is the dict ``{"vehicle": <TOML text>, "model": "half"|"full"}`` (so the
design's stores are keyed on the file's content); :func:`vehicle_of` reads it once per
process. Every corner of an axle gets the same network, the front and rear axles their
own element values (``front_c``, ``rear_b``, ...); the main spring ``k`` of each axle is
held at the file's wheel rate (its strut's static stiffness). The layout is shared
because a suspension is designed as one kind of hardware per car: 17 layouts per axle
would make 289 front/rear pairs, each a vehicle optimisation, for a choice a designer
rarely makes (docs/decisions.md).

Linear stage: the objective is the RMS of the Wk-weighted seat acceleration
(``seat_wk``), of the Wk-weighted or plain bounce acceleration (``body_acc_wk``,
``body_acc``) under white road velocity, exact by Lyapunov with the Wk filter as states
and the wheelbase delay (:func:`inerterlab.vehicles.design.h2_metrics`). It is
minimised over the per-axle values in their logarithms by L-BFGS-B (SLSQP with
limits) on its exact gradient (adjoint Lyapunov equations, the state space's
derivatives from the core car: :func:`linear_objective_gradient`), started from the
quarter-car H2 optimum of each axle's corner
(:func:`inerterlab.network_design.optimize_network`) or from the geometric middle of
the bounds (at most 100 iterations each; a layout running to a bound that stands for a
simpler one is reported as that one). Limits (RMS suspension deflection and dynamic tyre
load of the worst corner) use the spectral method on the band-limited ISO 8608 road
(both are infinite under white road velocity for a full car, see
:func:`inerterlab.vehicles.spectral.white_velocity_h2`).

Time domain: a candidate is built as the vehicle file with a network strut at every
corner (:class:`~inerterlab.vehicles.parameters.NetworkStrut`) or, with a real device,
the main spring as the strut and the rest of the layout as the corner's device
(:class:`~inerterlab.vehicles.parameters.Strut` ``device``), and driven over a generated
ISO 8608 road (its series at the wheels, linear between samples) by the model core's
vehicle, :func:`inerterlab.vehicles.simulation.simulate_vehicle` (the ``vehicle
simulate`` path; one-sided tyres).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
from collections.abc import Mapping

import numpy as np

from ..errors import ConvergenceError, ParameterError

__all__ = [
    "AXLES",
    "VEHICLE_OBJECTIVES",
    "vehicle_car",
    "vehicle_of",
    "corner_car",
    "axle_stiffness",
    "split_axles",
    "candidate_vehicle",
    "device_misfit",
    "linear_objective",
    "linear_objective_gradient",
    "optimize_layout",
    "linear_pareto_front",
    "simulate_vehicle_candidate",
]

AXLES = ("front", "rear")
#: design objectives a vehicle takes (the tyre loads and deflections of a full car are
#: infinite under white road velocity: they are limits, on the band-limited road)
VEHICLE_OBJECTIVES = ("seat_wk", "body_acc_wk", "body_acc")
#: road sample interval [s] and start-up left out [s] of a time-domain score (the car
#: of the model core, error-controlled: no step count to choose)
DT, WARMUP = 0.002, 2.0


def vehicle_car(text: str, model: str, source: str = "vehicle file") -> dict:
    """The car dict of a vehicle file's TOML ``text``; ``model`` 'file' keeps its
    model, 'half' takes a full car's pitch-plane half car."""
    from ..vehicles import loads_vehicle

    p = loads_vehicle(text, source)
    kind = "half" if type(p).__name__ == "HalfCar" else "full"
    if model == "half":
        kind = "half"
    elif model == "full" and kind != "full":
        raise ParameterError("--model", model, "half or quarter for a half-car file")
    car = {"vehicle": text, "model": kind}
    vehicle_of(car)  # built once here: an unsupported file fails before any work
    return car


@functools.lru_cache(maxsize=8)
def _vehicle(text: str, model: str):
    from ..vehicles import loads_vehicle

    p = loads_vehicle(text)
    if model == "half" and type(p).__name__ == "FullCar":
        p = p.half_car()
    return p


def vehicle_of(car: Mapping):
    """The HalfCar or FullCar of a car dict."""
    return _vehicle(car["vehicle"], car["model"])


def axle_stiffness(car: Mapping) -> dict:
    """The main spring k of each axle [N/m]: the file's strut's static stiffness."""
    p = vehicle_of(car)
    return {a: float(getattr(p, a).strut.static_stiffness()) for a in AXLES}


def corner_car(params, axle: str) -> dict:
    """The quarter car of one corner of ``axle`` (HalfCar or FullCar): the body's static
    share on the axle, l_r / L at the front (l_f / L at the rear), halved per wheel of a
    full car; the corner's unsprung mass and tyre; ``stiffness`` its strut's static
    stiffness (the wheel rate)."""
    if axle not in AXLES:
        raise ParameterError("--corner", axle, "front or rear")
    wheelbase = params.cg_to_front + params.cg_to_rear
    share = (params.cg_to_rear if axle == "front" else params.cg_to_front) / wheelbase
    per_axle = 2.0 if type(params).__name__ == "FullCar" else 1.0
    c = getattr(params, axle)
    return {
        "sprung_mass": params.sprung_mass * share / per_axle,
        "unsprung_mass": c.unsprung_mass,
        "tyre_stiffness": c.tyre.stiffness,
        "tyre_damping": c.tyre.damping,
        "stiffness": float(c.strut.static_stiffness()),
    }


def split_axles(values: Mapping[str, float]) -> dict:
    """{'front_c': 1, 'rear_c': 2} -> {'front': {'c': 1}, 'rear': {'c': 2}}."""
    out = {a: {} for a in AXLES}
    for k, v in values.items():
        axle, _, name = k.partition("_")
        if axle not in out or not name:
            raise ParameterError("parameter", k, "front_<element> or rear_<element>")
        out[axle][name] = v
    return out


def _linear(network: str, values: Mapping) -> bool:
    from ..networks import NetworkError, parse_network

    if any(isinstance(v, Mapping) for v in values.values()):
        return False
    try:
        parse_network(network).require_linear()
    except NetworkError:
        return False
    return True


def _strut(network: str, values: Mapping):
    """The corner's law: a network strut for a linear network, else the main spring as
    the strut and the rest of the network as its device."""
    from ..vehicles import NetworkStrut, Strut

    if _linear(network, values):
        return NetworkStrut(network, {k: float(v) for k, v in values.items()})
    rest, n = re.subn(r"^k \| ", "", network)
    if n != 1 or "k" not in values:
        raise ParameterError("network", network, "a layout k | (...) with the main spring k")
    return Strut(stiffness=float(values["k"]), damping=0.0, device=rest,
                 device_parameters={k: v for k, v in values.items() if k != "k"})  # fmt: skip


def device_misfit(layout: str, values: Mapping[str, float], device: str) -> str:
    """'' if ``device`` in place of the inerter of ``layout`` (one corner's ``values``)
    can sit at a vehicle corner, else the reason in one line (its internal nodes would
    carry static load, or an inertial part would touch the body's side)."""
    from .scoring import device_network

    net, elp = device_network(layout, values, device)
    try:
        _strut(net, elp)
    except ParameterError as e:
        return str(e).splitlines()[0]
    return ""


def candidate_vehicle(car: Mapping, cand: Mapping):
    """The vehicle parameters of a candidate {'network', 'params': {'front': {...},
    'rear': {...}}} (element values as the model core takes them)."""
    p = vehicle_of(car)
    changes = {}
    for a in AXLES:
        c = getattr(p, a)
        changes[a] = dataclasses.replace(c, strut=_strut(cand["network"], cand["params"][a]))
    return dataclasses.replace(p, **changes)


def linear_objective(car: Mapping, network: str, values: Mapping, objective: str,
                     road_class: str, speed: float) -> float:  # fmt: skip
    """The linear objective (RMS [m/s^2] under white road velocity of the class and
    speed, :func:`inerterlab.vehicles.design.h2_metrics`) of ``network`` at every corner
    with per-axle ``values``; inf for an unstable vehicle or an infinite norm."""
    from ..vehicles.design import h2_metrics

    cand = {"network": network, "params": split_axles(values)}
    try:
        v = h2_metrics(candidate_vehicle(car, cand), road_class, speed, [objective])[objective]
    except ConvergenceError:
        return math.inf
    return float(v)


#: largest projected gradient of a converged polish [objective per unit log value]
_GTOL = 1e-5
def linear_objective_gradient(car: Mapping, network: str, values: Mapping, objective: str,
                              road_class: str, speed: float, names) -> tuple:  # fmt: skip
    """:func:`linear_objective` and its derivatives in the logarithms of the per-axle
    values ``names`` (front_/rear_ element names), exact
    (:func:`inerterlab.vehicles.design.h2_metric_gradient`). (inf, None) where the
    objective is infinite or the vehicle unstable."""
    from ..vehicles.design import h2_metric_gradient

    p = candidate_vehicle(car, {"network": network, "params": split_axles(values)})
    try:
        return h2_metric_gradient(p, objective, names, road_class, speed)
    except ConvergenceError:
        return math.inf, None


def _limit_values(car, network, values, road_class, speed) -> dict:
    """Worst-corner RMS deflection [m] and dynamic tyre load [N] on the band-limited
    ISO 8608 road (spectral method)."""
    from ..vehicles.design import spectral_metrics

    m = spectral_metrics(candidate_vehicle(car, {"network": network, "params": split_axles(values)}),
                         road_class, speed, points=800)  # fmt: skip
    return {
        "deflection": max(m["front_deflection"], m["rear_deflection"]),
        "tyre_load": max(m["front_tyre_load"], m["rear_tyre_load"]),
    }


def optimize_layout(car: Mapping, network: str, objective: str, *, bounds: Mapping,
                    fixed: Mapping | None = None, limits: Mapping | None = None,
                    road_class: str, speed: float, start: str = "quarter",
                    initial: Mapping | None = None) -> dict:  # fmt: skip
    """Per-axle values of ``network`` minimising the linear ``objective``.

    ``bounds``: element -> [low, high] (both axles; default the element's design
    range); ``fixed``: element -> value held on both axles (a device's parasitics); the
    main spring k is held at each axle's wheel rate. ``limits``: deflection [m RMS],
    tyre_load [N RMS] of the worst corner (spectral method). ``start``: 'quarter' (the
    quarter-car optimum of each axle's corner), 'middle' (the bounds' geometric middle)
    or 'both' (the better end; the design uses 'quarter', the tests check that the
    middle start ends at the same optimum); ``initial`` (front_/rear_ values) replaces
    them. Each start is polished by L-BFGS-B (SLSQP with limits) on the exact gradient
    (:func:`linear_objective_gradient`). Returns {'objective', 'parameters' (front_/rear_ names,
    k included), 'converged', 'limit_values'}."""
    from scipy.optimize import minimize

    from ..network_design import design_parameters, optimize_network

    fixed = dict(fixed or {})
    limits = dict(limits or {})
    dp = design_parameters(network)
    names = [n for n in dp if n != "k" and n not in fixed]
    ks = axle_stiffness(car)
    lo, hi = [], []
    for _a in AXLES:
        for n in names:
            b = bounds.get(n) or dp[n].design
            lo.append(math.log(max(float(b[0]), 1e-9)))
            hi.append(math.log(float(b[1])))
    lo, hi = np.array(lo), np.array(hi)
    var = [f"{a}_{n}" for a in AXLES for n in names]

    def values(x):
        out = {f"{a}_k": ks[a] for a in AXLES}
        out.update({f"{a}_{n}": v for a in AXLES for n, v in fixed.items()})
        out.update(dict(zip(var, np.exp(np.clip(x, lo, hi)), strict=True)))
        return out

    cache: dict = {}

    def fg(x):
        # the objective and its exact gradient in the logarithms (adjoint Lyapunov
        # equations, the core matrices' derivatives): one evaluation
        key = np.asarray(x, dtype=float).tobytes()
        if key not in cache:
            v, g = linear_objective_gradient(car, network, values(x), objective, road_class,
                                             speed, var)  # fmt: skip
            inside = (x >= lo) & (x <= hi)  # values(x) clips: flat outside the bounds
            cache.clear()
            cache[key] = (v, np.where(inside, g, 0.0)) if math.isfinite(v) else (1e6, np.zeros(x.size))
        return cache[key]

    def f(x):
        return fg(x)[0]

    starts = []
    if initial is not None:  # e.g. the ideal layout's optimum for a device's network
        start = "given"
        starts.append(np.clip(np.array([math.log(float(initial[v])) for v in var]), lo, hi))
    if start in ("quarter", "both"):
        p = vehicle_of(car)
        q_obj = "body_acc" if objective == "body_acc" else "body_acc_wk"
        x0 = []
        for a in AXLES:
            cc = corner_car(p, a)
            k = cc.pop("stiffness")
            r = optimize_network(network, q_obj, fixed={"k": k, **fixed},
                                 bounds={n: bounds[n] for n in names if n in bounds},
                                 starts=2, samples=64, evolve=False, compare=False, simplify=False,
                                 **cc)  # fmt: skip
            x0 += [math.log(r.parameters[n]) for n in names]
        starts.append(np.clip(np.array(x0), lo, hi))
    if start in ("middle", "both"):
        starts.append(0.5 * (lo + hi))
    if not names:  # nothing to search
        vals = values(np.zeros(0))
        obj = linear_objective(car, network, vals, objective, road_class, speed)
        lim = _limit_values(car, network, vals, road_class, speed) if limits else {}
        return {"objective": obj, "parameters": vals, "converged": True, "limit_values": lim}
    cons = [
        {"type": "ineq",
         "fun": (lambda x, k=k, v=v: 1.0 - _limit_values(car, network, values(x), road_class,
                                                         speed)[k] / v)}
        for k, v in limits.items()
    ]  # fmt: skip
    best = None
    for x0 in starts:
        if limits:
            r = minimize(fg, x0, jac=True, method="SLSQP", bounds=list(zip(lo, hi, strict=True)),
                         constraints=cons, options={"maxiter": 100, "ftol": 1e-10})  # fmt: skip
        else:
            r = minimize(fg, x0, jac=True, method="L-BFGS-B", bounds=list(zip(lo, hi, strict=True)),
                         options={"maxiter": 100, "ftol": 1e-10, "gtol": _GTOL})  # fmt: skip
        x = np.clip(r.x, lo, hi)
        val, g = fg(x)
        # the norm's rounding (about 1e-10 relative) can stop the line search once the
        # gradient is near 1e-5: a stationary point in the bounds is converged too
        pg = np.where(x <= lo, np.minimum(g, 0.0), np.where(x >= hi, np.maximum(g, 0.0), g))
        done = bool(r.success) or (not limits and float(np.max(np.abs(pg), initial=0.0)) <= _GTOL)
        lim = _limit_values(car, network, values(x), road_class, speed) if limits else {}
        ok = all(lim[k] <= v * (1 + 1e-4) for k, v in limits.items())
        cand = (not ok, val, x, done, lim)
        if best is None or cand[:2] < best[:2]:
            best = cand
    obj = best[1] if best[1] < 1e6 else math.inf
    return {"objective": obj, "parameters": values(best[2]), "converged": best[3],
            "limit_values": best[4], "feasible": not best[0]}  # fmt: skip


def _deflection_gradient(p, names, road_class: str, speed: float) -> tuple:
    """The RMS suspension deflection of the corners, sqrt of the mean of their squared
    RMS deflections [m] under white road velocity of the class and speed (linear; the
    left and right corners of an axle alike, so the mean of the axles' squares), and
    its derivatives in the logarithms of ``names`` (exact, as
    :func:`inerterlab.vehicles.design.h2_metric_gradient`: adjoint Lyapunov equations,
    the core car's matrices' derivatives). (inf, None) where a norm is infinite.

    A full car is measured on its pitch-plane half car (each axle's wheels lumped): its
    own corner deflections have infinite norms under independent tracks, since a step
    under one track warps a body whose front and rear tracks differ, or that has an
    anti-roll bar, into a lasting deflection."""
    from ..network_design import road_scale
    from ..vehicles.design import stepped_vehicles
    from ..vehicles.linear import linear_vehicle
    from ..vehicles.spectral import white_velocity_h2_gradient

    if type(p).__name__ == "FullCar":
        p = p.half_car()
    veh = linear_vehicle(p)
    steps = stepped_vehicles(p, veh, names)
    outs = sorted(o for o in veh.state_space()[3] if o.endswith("_deflection"))
    vals, grads = [], []
    for o in outs:
        v, g = white_velocity_h2_gradient(veh, o, steps, speed=speed)
        if not math.isfinite(v):
            return math.inf, None
        vals.append(v)
        grads.append(np.asarray(g))
    ms = sum(v * v for v in vals) / len(vals)
    d = math.sqrt(ms)
    g = sum(v * gi for v, gi in zip(vals, grads, strict=True)) / (len(vals) * d) if d > 0 else 0.0
    k = road_scale(road_class, speed)
    return d * k, np.asarray(g) * k


def linear_pareto_front(car: Mapping, network: str, objective: str, values: Mapping, *,
                        bounds: Mapping, road_class: str, speed: float,
                        weights=(1.0, 0.85, 0.7, 0.5, 0.3), maxiter: int = 60) -> list:  # fmt: skip
    """The front of the linear ``objective`` (RMS [m/s^2], :func:`linear_objective`)
    against the RMS suspension deflection of the axles (:func:`_deflection_gradient`
    [m]) of ``network`` at every corner, per-axle values free (k held as ``values``
    gives it): for each weight w the minimum of w J / J0 + (1 - w) D / D0 (J0, D0 at
    ``values``, the start), by L-BFGS-B on the exact gradients from the previous
    weight's optimum. ``bounds``: element -> [low, high] (default the element's design
    range). Unconstrained: the design's limits are not applied. Returns one dict per
    weight: {'weight', 'objective', 'deflection', 'parameters'}."""
    from scipy.optimize import minimize

    from ..network_design import design_parameters

    dp = design_parameters(network)
    names = [n for n in dp if n != "k"]
    var = [f"{a}_{n}" for a in AXLES for n in names]
    lo = np.array([math.log(max(float((bounds.get(n) or dp[n].design)[0]), 1e-9))
                   for _a in AXLES for n in names])  # fmt: skip
    hi = np.array([math.log(float((bounds.get(n) or dp[n].design)[1])) for _a in AXLES for n in names])
    base = {k: float(v) for k, v in values.items()}

    def vals(x):
        return {**base, **dict(zip(var, np.exp(np.clip(x, lo, hi)), strict=True))}

    def both(x):
        v = vals(x)
        p = candidate_vehicle(car, {"network": network, "params": split_axles(v)})
        j, gj = linear_objective_gradient(car, network, v, objective, road_class, speed, var)
        d, gd = _deflection_gradient(p, var, road_class, speed)
        return j, gj, d, gd

    x = np.clip(np.array([math.log(base[v]) for v in var]), lo, hi)
    j0, _, d0, _ = both(x)
    if not (math.isfinite(j0) and math.isfinite(d0)):
        raise ParameterError("values", network, "a start with finite H2 norms")
    out = []
    for w in weights:
        def fg(y, w=w):
            j, gj, d, gd = both(y)
            if not (math.isfinite(j) and math.isfinite(d)):
                return 1e6, np.zeros(y.size)
            inside = (y >= lo) & (y <= hi)
            g = w * np.asarray(gj) / j0 + (1.0 - w) * np.asarray(gd) / d0
            return w * j / j0 + (1.0 - w) * d / d0, np.where(inside, g, 0.0)

        if var:
            r = minimize(fg, x, jac=True, method="L-BFGS-B", bounds=list(zip(lo, hi, strict=True)),
                         options={"maxiter": maxiter, "ftol": 1e-12, "gtol": 1e-7})  # fmt: skip
            x = np.clip(r.x, lo, hi)
        j, _, d, _ = both(x)
        out.append({"weight": float(w), "objective": j, "deflection": d, "parameters": vals(x)})
    return out


def simulate_vehicle_candidate(cand: Mapping, car: Mapping, road_class: str, speed: float,
                               horizon: float, seed: int) -> dict:  # fmt: skip
    """The design's per-road metrics of one vehicle candidate on one generated ISO 8608
    road (seed): ``horizon`` seconds after a start-up of :data:`WARMUP` s, one-sided
    tyres. Accelerations of the body's bounce and the seat (Wk weighted from rest over
    the whole run), deflection and tyre load of the worst corner."""
    from .. import iso2631
    from ..vehicles import generated_road, road_spectrum
    from ..vehicles.simulation import simulate_vehicle

    p = candidate_vehicle(car, cand)
    width = 0.5 * (p.front_track + p.rear_track) if hasattr(p, "front_track") else 1.5
    length = float(speed) * (float(horizon) + WARMUP) + p.wheelbase + 4 * float(speed) * DT
    r = generated_road(p, road_spectrum(road_class), length=length, speed=float(speed), dt=DT,
                       track=width, seed=int(seed))  # fmt: skip
    res = simulate_vehicle(p, r, DT, lift_off=True)
    y = res.outputs
    keep = slice(int(round(WARMUP / DT)), None)

    def rms(x):  # after the warm-up (trapezoidal rule, iso2631.rms)
        return iso2631.rms(np.asarray(x)[keep])

    bw = iso2631.weight(y["bounce_acc"], 1.0 / DT, "Wk")
    seat = "seat_acc" in y
    sw = iso2631.weight(y["seat_acc"], 1.0 / DT, "Wk") if seat else None
    cw = sw if seat else bw
    corners = tuple(res.contact_force)
    defl = [y[f"{c}_deflection"] for c in corners]
    loads = [y[f"{c}_tyre_load"] for c in corners]
    return {
        "rms_body_acc": rms(y["bounce_acc"]),
        "rms_body_acc_wk": rms(bw),
        "rms_seat_wk": rms(sw) if seat else None,
        "rms_tyre_load": max(rms(x) for x in loads),
        "rms_deflection": max(rms(x) for x in defl),
        "peak_deflection": max(float(np.max(np.abs(np.asarray(x)[keep]))) for x in defl),
        "vdv": float(iso2631.vibration_dose_value(np.asarray(cw)[keep], 1.0 / DT)),
        "min_tyre_force": min(float(np.min(res.contact_force[c][keep])) for c in corners),
    }
