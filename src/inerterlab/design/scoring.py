"""Time-domain scoring of design candidates on ISO 8608 roads, and the point functions of
the design study's sweeps.

A *candidate* is a network text with its element values as the model core takes them
(:func:`inerterlab.systems.quarter_car`): an ideal layout, a synthesised realisation,
or a layout whose ideal inerter is replaced by a real device with its parasitic
stiffness, damping and friction (:func:`device_network`). Its score for an objective
is the expected value of that objective's RMS over road realisations (one seed per
road), with a 95 % interval of the expected value from Student's t over the roads;
its gain over ``k | c`` is the mean of the per-road gains (the same roads for both,
so the interval of the gain is much narrower than that of either value).

Every stage of the study is a point of a sweep (:mod:`inerterlab.studies.sweep`), so
it is stored keyed on its inputs, runs in worker processes and resumes:

``design-layout``   one layout optimised by the H2 optimiser (network_design);
``design-device-linear``  one (layout, device) optimised by H2 with the device's
                    linear stiffness and damping in the network (held);
``design-device``   one (layout, device) whose inertance (ratio or channel length) is
                    searched on tuning roads with friction and nonlinear losses in the
                    time simulation, from the linear stage's values;
``design-score``    one candidate on one road (the metrics of :data:`SCORE_METRICS`);
``design-requirement``  the friction or parasitic damping at which a device's gain
                    over ``k | c`` on the tuning roads crosses zero (:func:`crossing`).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..studies.points import ParameterSpec, PointFunction, register_point_function

__all__ = [
    "SCORE_METRICS",
    "SCORE_RTOL",
    "DEVICES",
    "OBJECTIVE_METRIC",
    "device_network",
    "device_candidate",
    "axle_params",
    "simulate_candidate",
    "objective_of",
    "expected",
    "paired_gain",
]

#: per-road metrics a score point returns; ``rms_tyre_load`` is the dynamic force of the
#: tyre spring [N] (the core's tyre grip times the static load); for a vehicle the body
#: is its bounce, the seat its seat (NaN for a quarter car), deflection and tyre load
#: those of the worst corner
SCORE_METRICS = (
    "rms_body_acc",
    "rms_body_acc_wk",
    "rms_seat_wk",
    "rms_tyre_load",
    "rms_deflection",
    "peak_deflection",
    "vdv",
    "min_tyre_force",
)
#: the real devices a design can use
DEVICES = ("hydraulic", "rectifier", "screw", "fluid")
#: objective -> (time-domain metric, unit)
OBJECTIVE_METRIC = {
    "body_acc": ("rms_body_acc", "m/s^2"),
    "body_acc_wk": ("rms_body_acc_wk", "m/s^2"),
    "seat_wk": ("rms_seat_wk", "m/s^2"),
    "tyre_load": ("rms_tyre_load", "N"),
    "weighted": ("weighted", "1"),
}
#: the three metrics of the weighted objective, as in the H2 optimiser (comfort, road
#: holding, working space), each divided by that of the reference k | c on the same road
WEIGHTED_PARTS = ("rms_body_acc", "rms_tyre_load", "rms_deflection")
_MAX_SLOTS = 16
#: value of a parameter slot the layout does not use (every element value is > 0)
_NO_SLOT = -1.0


def _inerter_name(text: str) -> str:
    from ..networks import parse_network

    net = parse_network(text)
    names = [n for n, k in zip(net.names, net.kinds, strict=True) if k == "b"]
    if len(names) != 1:
        raise ParameterError("layout", text, "a network with exactly one inerter for a device")
    return names[0]


def _replace(text: str, name: str, by: str) -> str:
    out, n = re.subn(rf"(?<![A-Za-z0-9_.]){re.escape(name)}(?![A-Za-z0-9_.])", by, text)
    if n != 1:
        raise ParameterError("layout", text, f"one element named {name}")
    return out


def device_parts(device: str) -> dict:
    """The identified parasitics of a device with a transmission (series stiffness
    [N/m], parallel damping [N s/m], Coulomb friction [N] and its smoothing velocity
    [m/s]), from :mod:`inerterlab.devices.models`."""
    from ..devices.models import HydraulicDevice, RectifierDevice, ScrewDevice

    cls = {"hydraulic": HydraulicDevice, "rectifier": RectifierDevice, "screw": ScrewDevice}
    d = cls[device]()
    return {
        "stiffness": float(d.stiffness),
        "damping": float(d.damping),
        "friction": float(d.friction),
        "friction_velocity": float(d.friction_velocity),
    }


def linear_device_network(text: str, device: str) -> tuple[str, dict]:
    """``text`` with its inerter inside the device's *linear* parasitics (for the H2
    stage): (network, fixed values). The fluid inerter's laminar loss grows with its
    inertance (one geometry), which the H2 stage cannot tie: it keeps the ideal inerter
    and the time stage handles the losses."""
    name = _inerter_name(text)
    if device == "fluid":
        return text, {}
    p = device_parts(device)
    inner = f"(k_dev | c_dev | {name})" if device == "screw" else f"(k_dev - (c_dev | {name}))"
    return _replace(text, name, inner), {"k_dev": p["stiffness"], "c_dev": p["damping"]}


def device_network(text: str, params: Mapping[str, float], device: str, **override) -> tuple:
    """(network text, element values) of layout ``text`` with its one inerter replaced
    by ``device`` of the same inertance, its parasitics at their identified (or given,
    ``override``: friction [N], damping [N s/m]) values, for the model core."""
    from ..network_truth import _network_for

    name = _inerter_name(text)
    p = {k: float(v) for k, v in params.items()}
    if name != "b":
        text = _replace(text, name, "b")
        p["b"] = p.pop(name)
    if "b" not in p:
        raise ParameterError("layout", text, "a value for its inerter")
    net, elp = _network_for(text, p, device)
    elp = json.loads(json.dumps(elp))  # plain, JSON-ready values
    if "friction" in override:
        if device == "fluid":
            raise ParameterError("requirement", "friction", "a device with friction")
        elp["fric_dev"]["force"] = float(override["friction"])
    if "damping" in override:
        if device == "fluid":
            elp["fluid"]["damping"] = float(override["damping"])
        else:
            elp["c_dev"] = float(override["damping"])
    return net, elp


def device_candidate(text: str, params: Mapping[str, float], device: str, car: Mapping,
                     **override) -> tuple:  # fmt: skip
    """:func:`device_network` for the quarter car, or for a vehicle (``car`` with a
    ``vehicle``) per axle: (network, {'front': values, 'rear': values})."""
    if "vehicle" not in car:
        return device_network(text, params, device, **override)
    from .vehicle import split_axles

    out = {}
    for axle, vals in split_axles(params).items():
        net, out[axle] = device_network(text, vals, device, **override)
    return net, out


def axle_params(params: Mapping[str, float], car: Mapping):
    """A layout's values as a candidate takes them: as they are for the quarter car,
    per axle for a vehicle."""
    if "vehicle" not in car:
        return dict(params)
    from .vehicle import split_axles

    return split_axles(params)


def candidate_text(network: str, params: Mapping[str, Any]) -> str:
    """The one text of a candidate: JSON of (network, values), keys sorted."""
    return json.dumps({"network": network, "params": params}, sort_keys=True)


#: most steps of one adaptive simulation: a device whose friction sticks for long at a
#: small inertance needs tiny steps (the smoothed friction is stiff near zero velocity)
MAX_STEPS = 400_000
#: relative tolerance of a candidate's adaptive simulation (a device's friction and
#: nonlinear losses; a linear candidate runs exact steps, where it has no effect). At
#: 1e-7 a device candidate's steps are set by the road's samples with almost no
#: rejected step, half the work of the core's default 1e-8; its metrics move by about
#: 1e-8 relative, some 1e5 times less than the 95 % interval of an expected value over
#: 20 roads (tests/test_design.py, docs/decisions.md)
SCORE_RTOL = 1e-7


def simulate_candidate(cand: Mapping, car: Mapping, road_class: str, speed: float,
                       horizon: float, seed: int, max_steps: int = MAX_STEPS,
                       rtol: float = SCORE_RTOL) -> dict:  # fmt: skip
    """:data:`SCORE_METRICS` of one candidate on one ISO 8608 road (seed); a quarter car
    integrates only its ride metrics (``metrics_only``), with relative tolerance
    ``rtol`` where it steps adaptively."""
    from .. import excitation as ex
    from ..systems import quarter_car

    if "vehicle" in car:
        from .vehicle import simulate_vehicle_candidate

        return simulate_vehicle_candidate(cand, car, road_class, speed, horizon, seed)

    sys = quarter_car(cand["network"], dict(cand["params"]), **dict(car))
    res = sys.simulate(ex.iso8608(road_class, float(speed), seed=int(seed)), horizon=horizon,
                       max_steps=int(max_steps), rtol=float(rtol), metrics_only=True)  # fmt: skip
    m = res.metrics
    load = (car["sprung_mass"] + car["unsprung_mass"]) * 9.81
    out = {
        "rms_body_acc": m["rms_body_acc"],
        "rms_body_acc_wk": m["rms_body_acc_wk"],
        "rms_seat_wk": None,
        "rms_tyre_load": m["rms_tyre_grip"] * load,
        "rms_deflection": m["rms_deflection"],
        "peak_deflection": m["peak_deflection"],
        "vdv": m["vdv"],
        "min_tyre_force": m["min_tyre_force"],
    }
    # a quarter car has no seat: None (a missing value to the sweep, not a failure)
    return {k: (v if k == "rms_seat_wk" else math.nan if v is None else float(v))
            for k, v in out.items()}  # fmt: skip


def objective_of(metrics: Mapping[str, np.ndarray], objective: str, reference=None) -> np.ndarray:
    """Per-road values of ``objective`` from per-road metrics (``weighted`` needs the
    reference ``k | c``'s metrics on the same roads)."""
    if objective == "weighted":
        if reference is None:
            raise ParameterError("objective", objective, "a reference for the weighted score")
        parts = [np.asarray(metrics[k]) / np.asarray(reference[k]) for k in WEIGHTED_PARTS]
        return np.sqrt(sum(p * p for p in parts) / len(parts))
    return np.asarray(metrics[OBJECTIVE_METRIC[objective][0]], float)


def expected(values) -> dict:
    """Mean of per-road values with the 95 % interval of the expected value (Student's
    t, n - 1 degrees of freedom) and the 95 % range of a single road."""
    from scipy.stats import t

    v = np.asarray(values, float)
    n = v.size
    mean = float(np.mean(v))
    if n < 2:
        return {"mean": mean, "half_width": math.inf, "single_road": math.inf, "roads": n}
    sd = float(np.std(v, ddof=1))
    q = float(t.ppf(0.975, n - 1))
    return {
        "mean": mean,
        "half_width": q * sd / math.sqrt(n),
        "single_road": q * sd * math.sqrt(1.0 + 1.0 / n),
        "roads": n,
    }


def paired_gain(values, base) -> dict:
    """Gain over the baseline in percent (positive: better), road by road, with the
    95 % interval of its expected value."""
    g = 100.0 * (1.0 - np.asarray(values, float) / np.asarray(base, float))
    return expected(g)


# ---------------------------------------------------------------------------------------
# point functions


def _j(text: str):
    return json.loads(text) if text else {}


def _score_point(params: Mapping[str, Any]) -> dict[str, float]:
    cand = _j(params["candidate"])
    return simulate_candidate(
        cand, _j(params["car"]), params["road_class"], params["speed"], params["horizon"],
        int(params["seed"]), rtol=float(params["rtol"]),
    )  # fmt: skip


def _mean_objective(cand, s, seeds, reference_metrics=None) -> float:
    """(mean objective over ``seeds`` with the limits' penalty, per-road metrics); an
    infinite objective when a simulation needs more than ``max_steps`` steps."""
    from ..errors import ConvergenceError

    try:
        rows = [
            simulate_candidate(
                cand,
                s["car"],
                s["road_class"],
                s["speed"],
                s["horizon"],
                seed,
                s.get("max_steps", MAX_STEPS),
                s.get("rtol", SCORE_RTOL),
            )  # fmt: skip
            for seed in seeds
        ]
    except ConvergenceError:
        return math.inf, None
    metrics = {k: np.array([r[k] for r in rows]) for k in SCORE_METRICS}
    val = float(np.mean(objective_of(metrics, s["objective"], reference_metrics)))
    pen = 0.0
    for key, metric in (("deflection", "rms_deflection"), ("tyre_load", "rms_tyre_load")):
        lim = s.get("limits", {}).get(key)
        if lim:
            pen += max(0.0, float(np.mean(metrics[metric])) / lim - 1.0)
    return val * (1.0 + 10.0 * pen), metrics


def _reference_metrics(s, seeds):
    if s["objective"] != "weighted":
        return None
    ref = _j(s["reference"])
    rows = [
        simulate_candidate(ref, s["car"], s["road_class"], s["speed"], s["horizon"], seed,
                           rtol=s.get("rtol", SCORE_RTOL))  # fmt: skip
        for seed in seeds
    ]
    return {k: np.array([r[k] for r in rows]) for k in SCORE_METRICS}


def _device_linear_point(params: Mapping[str, Any]) -> dict[str, float]:
    """One (layout, device), linear: the H2 optimum with the device's series stiffness
    and parallel damping held at their identified values (inertance and the layout's
    other elements free)."""
    from ..network_design import optimize_network

    s = _j(params["settings"])
    layout, device = params["layout"], params["device"]
    ideal = _j(params["ideal"])[layout]
    lin_text, lin_fixed = linear_device_network(layout, device)
    if "vehicle" in s["car"]:
        from .vehicle import optimize_layout

        r = optimize_layout(
            s["car"], lin_text, s["h2_objective"], bounds=dict(s["bounds_of"].get(layout, {})),
            fixed=lin_fixed, limits=s["limits"], road_class=s["road_class"], speed=s["speed"],
            initial=ideal,
        )  # fmt: skip
        out = {"objective": r["objective"] if math.isfinite(r["objective"]) else None}
        names = sorted(ideal)
        for i in range(_MAX_SLOTS):
            out[f"p{i}"] = float(r["parameters"][names[i]]) if i < len(names) else _NO_SLOT
        return out
    r = optimize_network(
        lin_text, s["h2_objective"], fixed={"k": s["stiffness"], **lin_fixed},
        bounds=dict(s["bounds_of"].get(layout, {})), constraints=s["constraints"], starts=4,
        samples=128, seed=int(s["seed"]), compare=False, simplify=False, **s["car"],
    )  # fmt: skip
    out = {"objective": r.objective if math.isfinite(r.objective) else None}
    names = sorted(ideal)
    for i in range(_MAX_SLOTS):
        out[f"p{i}"] = float(r.parameters[names[i]]) if i < len(names) else _NO_SLOT
    return out


def _device_point(params: Mapping[str, Any]) -> dict[str, float]:
    """One (layout, device, start values): the device's inertance searched in the time
    domain on the tuning roads, friction and nonlinear losses simulated."""
    from scipy.optimize import minimize_scalar

    s = _j(params["settings"])
    job = _j(params["job"])
    layout, device, p = job["layout"], job["device"], dict(job["values"])
    name = _inerter_name(layout)
    # a vehicle's inerters of both axles move by one factor (the same device, its size
    # in the ratio the linear stage found)
    names_b = [f"{a}_{name}" for a in ("front", "rear")] if "vehicle" in s["car"] else [name]
    b_of = {n: p[n] for n in names_b}
    b0 = max(b_of.values())
    hi_b = float(s["max_inertance"])
    span = float(s.get("device_span", 3.0))
    lo, hi = math.log(max(b0 / span, 1e-3)), math.log(min(b0 * span, hi_b))
    if lo >= hi:
        lo = hi - math.log(span)
    seeds = s["tune_seeds"]
    ref = _reference_metrics(s, seeds)

    def sized(u):
        q = dict(p)
        for n, b in b_of.items():
            q[n] = b * math.exp(u) / b0
        return q

    def f(u):
        net, elp = device_candidate(layout, sized(u), device, s["car"])
        v = _mean_objective({"network": net, "params": elp}, s, seeds, ref)[0]
        return v if math.isfinite(v) else 1e300

    res = minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"xatol": 0.1})
    if not res.fun < 1e300:
        raise ArithmeticError(f"every inertance of the {device} device needs more than "
                              f"{s.get('max_steps', MAX_STEPS)} steps per road")  # fmt: skip
    p = sized(float(res.x))
    out = {"objective": float(res.fun), "evaluations": float(res.nfev)}
    names = sorted(p)
    for i in range(_MAX_SLOTS):
        out[f"p{i}"] = p[names[i]] if i < len(names) else _NO_SLOT
    return out


def _layout_point(params: Mapping[str, Any]) -> dict[str, float]:
    from ..network_design import optimize_network

    s = _j(params["settings"])
    if "vehicle" in s["car"]:
        from .vehicle import optimize_layout

        r = optimize_layout(
            s["car"], params["network"], s["h2_objective"],
            bounds=s["bounds_of"].get(params["network"], {}), limits=s["limits"],
            road_class=s["road_class"], speed=s["speed"],
        )  # fmt: skip
        out = {"objective": r["objective"] if math.isfinite(r["objective"]) else None,
               "converged": float(r["converged"]), "norm_body_acc": None,
               "norm_tyre_deflection": None, "norm_suspension_deflection": None}  # fmt: skip
        names = sorted(r["parameters"])
        for i in range(_MAX_SLOTS):
            out[f"p{i}"] = float(r["parameters"][names[i]]) if i < len(names) else _NO_SLOT
        return out
    r = optimize_network(
        params["network"], s["h2_objective"], fixed={"k": s["stiffness"]}, bounds=s["bounds_of"].get(params["network"], {}),
        constraints=s["constraints"], seed=int(s["seed"]), compare=False, simplify=False,
        **s["car"],
    )  # fmt: skip
    # simplify=False: the design reads a layout's own optimum and names the simpler layout
    # an optimum on a bound stands for itself (pipeline._simpler); the optimiser's own
    # re-optimisation of that layout would be thrown away
    out = {
        "objective": r.objective if math.isfinite(r.objective) else None,
        "converged": float(r.converged),
        **{f"norm_{k}": (v if math.isfinite(v) else None) for k, v in r.norms.items()},
    }
    names = sorted(r.parameters)
    for i in range(_MAX_SLOTS):
        out[f"p{i}"] = float(r.parameters[names[i]]) if i < len(names) else _NO_SLOT
    return out


def _requirement_point(params: Mapping[str, Any]) -> dict[str, float]:
    """The friction [N] or parasitic damping [N s/m] at which the expected gain over
    k | c on the tuning roads of the layout's ideal design, built with the device (its
    stiffness as identified, the other loss off), is zero: :func:`crossing` in its
    logarithm, to the accuracy of ``bisections`` halvings of the range."""
    s = _j(params["settings"])
    job = _j(params["job"])
    layout, p, device, what = job["layout"], job["values"], job["device"], job["parameter"]
    seeds = s["tune_seeds"]
    ref = _reference_metrics(s, seeds)
    base = _mean_objective(_j(s["baseline"]), s, seeds, ref)[0]

    # the other loss off (1e-3 N or N s/m, the smallest physical values, stand for none)
    other = (
        {}
        if device == "fluid"
        else {"friction": {"damping": 1e-3}, "damping": {"friction": 1e-3}}[what]
    )

    def gain(x):
        # a road the integration cannot finish in max_steps (long sticking) counts as
        # no gain: the crossing found is then a lower bound of the true one
        net, elp = device_candidate(layout, p, device, s["car"], **{what: x, **other})
        return 1.0 - _mean_objective({"network": net, "params": elp}, s, seeds, ref)[0] / base

    lo, hi = s.get("requirement_range", {}).get(what) or (
        (1.0, 2000.0) if what == "friction" else (10.0, 30_000.0)
    )
    threshold, bracket, g_lo, g_hi = crossing(gain, lo, hi, int(s.get("bisections", 8)))
    return {
        "threshold": threshold,
        "bracket": bracket,
        "gain_low": 100 * g_lo,
        # a loss too large to simulate (-inf: a road beyond max_steps) is missing
        "gain_high": 100 * g_hi if math.isfinite(g_hi) else None,
    }


def crossing(gain, lo: float, hi: float, halvings: int) -> tuple[float, float, float, float]:
    """Where ``gain`` (positive below, not positive above) crosses zero in [lo, hi]:
    (value, bracket, gain(lo), gain(hi)); bracket -1 when no value keeps a gain
    (gain(lo) <= 0, value lo), +1 when every value does (gain(hi) > 0, value hi), else 0.

    The ITP method (interpolate, truncate, project; Oliveira and Takahashi, ACM Trans.
    Math. Softw. 47(1), 2020) on the logarithm, to the accuracy of ``halvings``
    bisections of the range: it ends with the crossing bracketed in a width of at most
    log(hi / lo) / 2^halvings and returns the middle, as bisection does, in at most one
    evaluation more than bisection and in fewer where the gain is smooth (its steps are
    the regula falsi's, truncated and projected into bisection's worst-case bound). A
    non-finite gain counts as a loss."""
    g_lo, g_hi = gain(lo), gain(hi)
    if g_lo <= 0.0:
        return lo, -1.0, g_lo, g_hi
    if g_hi > 0.0:
        return hi, 1.0, g_lo, g_hi
    a, b = math.log(lo), math.log(hi)
    ya, yb = g_lo, (g_hi if math.isfinite(g_hi) else -1.0)  # a loss: only its sign matters
    eps = 0.5 * (b - a) / 2**halvings
    n_max = halvings + 1  # bisection's count plus n0 = 1
    k1 = 0.2 / (b - a)
    for j in range(n_max):
        if b - a <= 2.0 * eps * (1.0 + 1e-12):
            break
        mid = 0.5 * (a + b)
        r = eps * 2.0 ** (n_max - j) - 0.5 * (b - a)
        delta = k1 * (b - a) ** 2
        xf = (yb * a - ya * b) / (yb - ya)
        sigma = math.copysign(1.0, mid - xf)
        xt = xf + sigma * delta if delta <= abs(mid - xf) else mid
        x = xt if abs(xt - mid) <= r else mid - sigma * r
        y = gain(math.exp(x))
        if y > 0.0:
            a, ya = x, y
        else:
            b, yb = x, (y if math.isfinite(y) else -1.0)
    return math.exp(0.5 * (a + b)), 0.0, g_lo, g_hi


def _inputs() -> dict:
    from ..network_truth import FLUID

    return {
        "devices": {d: device_parts(d) for d in DEVICES if d != "fluid"},
        "fluid": dict(FLUID),
        "metrics": list(SCORE_METRICS),
    }


_TEXT = ParameterSpec(kind="text")
_ROAD = {
    "car": ParameterSpec(kind="text", doc="JSON of the car's masses and tyre"),
    "road_class": ParameterSpec(kind="choice", choices=tuple("ABCDEFGH")),
    "speed": ParameterSpec(low=0.0, low_open=True, high=100.0, unit="m/s"),
    "horizon": ParameterSpec(low=1.0, high=600.0, unit="s"),
    "rtol": ParameterSpec(low=1e-10, high=1e-6, doc="relative tolerance (adaptive steps)"),
}

SCORE = register_point_function(
    PointFunction(
        name="design-score",
        function=_score_point,
        inputs=_inputs,
        parameters={"candidate": _TEXT, "seed": ParameterSpec(kind="int", low=0.0), **_ROAD},
        defaults={
            "candidate": "",
            "seed": 1,
            "car": "",
            "road_class": "C",
            "speed": 25.0,
            "horizon": 10.0,
            "rtol": SCORE_RTOL,
        },  # fmt: skip
        metrics=SCORE_METRICS,
    )
)
LAYOUT = register_point_function(
    PointFunction(
        name="design-layout",
        function=_layout_point,
        inputs=_inputs,
        parameters={"network": _TEXT, "settings": _TEXT},
        defaults={"network": "k | c", "settings": ""},
        metrics=(
            "objective",
            "converged",
            "norm_body_acc",
            "norm_tyre_deflection",
            "norm_suspension_deflection",
            *(f"p{i}" for i in range(_MAX_SLOTS)),
        ),  # fmt: skip
    )
)
DEVICE = register_point_function(
    PointFunction(
        name="design-device",
        function=_device_point,
        inputs=_inputs,
        parameters={"job": _TEXT, "settings": _TEXT},
        defaults={"job": "", "settings": ""},
        metrics=("objective", "evaluations", *(f"p{i}" for i in range(_MAX_SLOTS))),
    )
)
DEVICE_LINEAR = register_point_function(
    PointFunction(
        name="design-device-linear",
        function=_device_linear_point,
        inputs=_inputs,
        parameters={
            "layout": _TEXT,
            "device": ParameterSpec(kind="choice", choices=DEVICES),
            "ideal": _TEXT,
            "settings": _TEXT,
        },  # fmt: skip
        defaults={"layout": "k | (c - b)", "device": "hydraulic", "ideal": "", "settings": ""},
        metrics=("objective", *(f"p{i}" for i in range(_MAX_SLOTS))),
    )
)
REQUIREMENT = register_point_function(
    PointFunction(
        name="design-requirement",
        function=_requirement_point,
        inputs=_inputs,
        parameters={"job": _TEXT, "settings": _TEXT},
        defaults={"job": "", "settings": ""},
        metrics=("threshold", "bracket", "gain_low", "gain_high"),
    )
)
