"""Stochastic response of nonlinear vehicles: Monte Carlo over road realisations and
statistical (Gaussian equivalent) linearisation.

Monte Carlo
    Each road realisation is one point of a sweep (:mod:`inerterlab.studies`) over the
    road ``seed``: the point functions ``half-car-road`` and ``full-car-road`` generate
    an ISO 8608 road (left/right coherence of :mod:`inerterlab.vehicles.roads`),
    evaluated exactly at the wheels (:func:`~inerterlab.vehicles.spectral.generated_road`),
    drive the vehicle of the model core over it
    (:func:`~inerterlab.vehicles.simulation.simulate_vehicle`) and return,
    after a start-up that is left out, the mean square of every output and the fraction
    of time each tyre is off the road. So a Monte Carlo study runs serially, in
    processes or on Dask, is stored chunk by chunk and resumes like any sweep.
    :func:`monte_carlo` summarises the realisations: the RMS over all of them (root of
    the mean of the per-road mean squares) with a 95 % confidence interval from the
    spread of the per-road mean squares (a t interval on the mean square, mapped through
    the square root), and per corner the mean fraction of time off the road and the
    probability that a road of that length lifts the tyre at all (Wilson interval).

Statistical linearisation
    An adaptive inerter's force m_e(v) dv/dt (laws ``thesis``, ``momentum``) becomes the
    constant inertance E[m_e(v)]: for a stationary Gaussian response v and dv/dt are
    independent, so E[m_e(v) a^2] / E[a^2] = E[m_e(v)].
    Each nonlinear strut force g(v) of the strut's extension rate v (asymmetric damper,
    regularised Coulomb friction) is replaced by the damper c_eq that minimises the
    mean square error E[(g(v) - c_eq v)^2] for a zero-mean Gaussian v of standard
    deviation sigma_v (Roberts and Spanos, *Random Vibration and Statistical
    Linearization*, Wiley 1990, ch. 5): c_eq = E[g(v) v] / sigma_v^2. For the
    asymmetric damper this is c (rebound + compression) / 2 whatever sigma_v; for
    the friction F_f tanh(v / v_f) it is F_f E[sech^2(v / v_f)] / v_f (Gaussian
    integration by parts), -> F_f sqrt(2 / pi) / sigma_v as v_f -> 0. sigma_v comes
    from the spectral response of the equivalent linear vehicle, so c_eq is a fixed
    point, found by iteration. Tyre lift-off is not linearised; its probability is the
    Gaussian tail of the linear tyre load (as in :func:`spectral_response`). The
    linearisation ignores the mean (static) offset an asymmetric damper builds up and
    the non-Gaussian shape of the response; :func:`monte_carlo` measures the error.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError, check_nonnegative, check_positive
from ..studies.points import ParameterSpec, PointFunction, register_point_function

__all__ = [
    "HALF_CAR_METRICS",
    "FULL_CAR_METRICS",
    "MonteCarloResult",
    "LinearisationResult",
    "monte_carlo",
    "statistical_linearisation",
]

_BODY = ("bounce_acc", "pitch_acc", "roll_acc", "seat_acc")
_HALF_CORNERS = ("front", "rear")
_FULL_CORNERS = ("front_left", "front_right", "rear_left", "rear_right")


def _metric_names(corners) -> tuple[str, ...]:
    names = ["ms_bounce_acc", "ms_pitch_acc", "ms_comfort_wk"]
    for c in corners:
        names += [f"ms_{c}_deflection", f"ms_{c}_tyre_load", f"{c}_lift_off_fraction"]
    return tuple(names)


#: metrics of the ``half-car-road`` point: mean squares (``ms_``, SI units squared) of
#: bounce and pitch acceleration, of the Wk-weighted seat (or bounce) acceleration, and
#: per axle of the suspension deflection and dynamic tyre load, plus the fraction of
#: time each tyre's contact force is zero or below [-] (off the road; with ``lift_off``
#: "off", the linear tyre pulling), all after the start-up.
HALF_CAR_METRICS = _metric_names(_HALF_CORNERS)
#: metrics of the ``full-car-road`` point (the half car's, per corner).
FULL_CAR_METRICS = _metric_names(_FULL_CORNERS)


def _load_vehicle(path: str, kind: str):
    from .config import example_vehicle_path, load_vehicle
    from .model import build

    params = load_vehicle(path if path else example_vehicle_path())
    if kind == "half" and hasattr(params, "half_car"):
        params = params.half_car()
    vehicle = build(params)
    if vehicle.kind != kind:
        raise ParameterError(
            "vehicle", path or "(example)", f"a {kind}-car file or a full-car file for 'half'"
        )
    return params, vehicle


def _tracks(p, params: Mapping[str, Any], seed: int) -> np.ndarray:
    """The wheel heights of road realisation ``seed`` under the car ``p``."""
    from .roads import road_spectrum
    from .spectral import generated_road

    width = 0.5 * (p.front_track + p.rear_track) if hasattr(p, "front_track") else 1.5
    return generated_road(
        p,
        road_spectrum(params["road_class"]),
        length=float(params["length"]),
        speed=float(params["speed"]),
        dt=float(params["dt"]),
        track=width,
        seed=seed,
    )


def _car(path: str, kind: str):
    """The car's parameters from ``path`` ('' the packaged example) as a ``kind`` car."""
    from .config import example_vehicle_path, load_vehicle
    from .parameters import FullCar

    params = load_vehicle(path if path else example_vehicle_path())
    if kind == "half" and hasattr(params, "half_car"):
        params = params.half_car()
    if isinstance(params, FullCar) != (kind == "full"):
        raise ParameterError(
            "vehicle", path or "(example)", f"a {kind}-car file or a full-car file for 'half'"
        )
    return params


def _one_road(params: Mapping[str, Any], kind: str) -> dict[str, float]:
    from .simulation import simulate_vehicle

    p = _car(params["vehicle"], kind)
    dt = float(params["dt"])
    r = _tracks(p, params, int(params["seed"]))
    res = simulate_vehicle(
        p,
        r,
        dt,
        lift_off=params["lift_off"] == "on",
        rebound=float(params["rebound"]),
        compression=float(params["compression"]),
        friction=float(params["friction"]),
        friction_velocity=float(params["friction_velocity"]),
        rtol=float(params["rtol"]),
        warmup=float(params["warmup"]),
    )
    keep = slice(min(int(float(params["warmup"]) / dt), r.shape[0] // 2), None)
    y = res.outputs
    out = {
        "ms_bounce_acc": float(np.mean(y["bounce_acc"][keep] ** 2)),
        "ms_pitch_acc": float(np.mean(y["pitch_acc"][keep] ** 2)),
        "ms_comfort_wk": res.comfort["wk_rms"] ** 2,
    }
    for c in res.contact_force:
        out[f"ms_{c}_deflection"] = float(np.mean(y[f"{c}_deflection"][keep] ** 2))
        out[f"ms_{c}_tyre_load"] = float(np.mean(y[f"{c}_tyre_load"][keep] ** 2))
        contact = res.contact_force[c][keep]
        out[f"{c}_lift_off_fraction"] = float(np.mean(contact <= 0.0))
    return out


def _half_point(params: Mapping[str, Any]) -> dict[str, float]:
    return _one_road(params, "half")


def _full_point(params: Mapping[str, Any]) -> dict[str, float]:
    return _one_road(params, "full")


def _example_path():
    from .config import example_vehicle_path

    return example_vehicle_path()


_POS = {"low": 0.0, "low_open": True}
_PARAMETERS = {
    "vehicle": ParameterSpec(
        kind="file", empty=_example_path, doc="vehicle TOML file ('' = the packaged example)"
    ),
    "road_class": ParameterSpec(kind="choice", choices=tuple("ABCDEFGH"), doc="ISO 8608 class"),
    "speed": ParameterSpec(**_POS, high=100.0, unit="m/s", doc="vehicle speed"),
    "length": ParameterSpec(**_POS, high=1e6, unit="m", doc="road length per realisation"),
    "dt": ParameterSpec(**_POS, high=0.1, unit="s", doc="road sample interval"),
    "rtol": ParameterSpec(low=1e-12, high=1e-2, doc="relative tolerance of the integration"),
    "warmup": ParameterSpec(low=0.0, high=1e4, unit="s", doc="start-up left out"),
    "seed": ParameterSpec(kind="int", low=0.0, doc="road realisation"),
    "lift_off": ParameterSpec(kind="choice", choices=("on", "off"), doc="one-sided tyres"),
    "rebound": ParameterSpec(**_POS, high=100.0, doc="damping factor while extending"),
    "compression": ParameterSpec(**_POS, high=100.0, doc="damping factor while shortening"),
    "friction": ParameterSpec(low=0.0, high=1e5, unit="N", doc="strut Coulomb friction"),
    "friction_velocity": ParameterSpec(**_POS, high=10.0, unit="m/s", doc="regularisation"),
}
_DEFAULTS = {
    "vehicle": "",
    "road_class": "C",
    "speed": 20.0,
    "length": 1200.0,
    "dt": 0.002,
    "rtol": 1e-6,
    "warmup": 5.0,
    "seed": 0,
    "lift_off": "on",
    "rebound": 1.0,
    "compression": 1.0,
    "friction": 0.0,
    "friction_velocity": 0.01,
}

HALF_CAR_ROAD = register_point_function(
    PointFunction(
        name="half-car-road",
        function=_half_point,
        parameters=_PARAMETERS,
        defaults=_DEFAULTS,
        metrics=HALF_CAR_METRICS,
    )
)
FULL_CAR_ROAD = register_point_function(
    PointFunction(
        name="full-car-road",
        function=_full_point,
        parameters=_PARAMETERS,
        defaults=_DEFAULTS,
        metrics=FULL_CAR_METRICS,
    )
)


# --- Monte Carlo ------------------------------------------------------------------------


def _t975(dof: int) -> float:
    from scipy.stats import t

    return float(t.ppf(0.975, dof))


def _wilson(k: int, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    p = k / n
    den = 1.0 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1.0 - p) / n + z * z / (4 * n * n)) / den
    return (max(0.0, mid - half), min(1.0, mid + half))


@dataclass(frozen=True)
class MonteCarloResult:
    """Summary of a Monte Carlo study over road realisations.

    Attributes
    ----------
    rms : dict
        Output name -> (RMS, (low, high)) over all realisations with its 95 % interval;
        names as in :func:`spectral_response` (``bounce_acc`` [m/s^2], ``pitch_acc``
        [rad/s^2], ``seat_acc_wk`` or ``bounce_acc_wk`` [m/s^2], ``<corner>_deflection``
        [m], ``<corner>_tyre_load`` [N]).
    lift_off_fraction : dict
        Corner -> (mean fraction of time the contact force is zero or below, (low,
        high)) [-], after the start-up. With ``lift_off`` the time off the road; without
        it the time the linear (two-sided) tyre pulls, where a real one would lift off.
    lift_off_probability : dict or None
        Corner -> (fraction of realisations in which the tyre leaves the road at least
        once, (low, high) Wilson 95 %) [-]; None without ``lift_off`` (a linear tyre
        never leaves the road).
    realisations : int
        Number of road realisations that succeeded.
    dataset : xarray.Dataset
        The per-road metrics (dimension ``seed``), as stored by the sweep.
    lift_off : bool
        Whether the tyres were one-sided.
    """

    rms: dict
    lift_off_fraction: dict
    lift_off_probability: dict | None
    realisations: int
    dataset: Any
    lift_off: bool = True

    def to_dict(self) -> dict:
        """JSON-ready summary. Without lift-off the time fraction is named
        ``negative_contact_fraction`` and there is no ``lift_off_probability``."""

        def pair(v):
            return {"value": v[0], "ci95": list(v[1])}

        out = {
            "realisations": self.realisations,
            "rms": {k: pair(v) for k, v in self.rms.items()},
        }
        frac = {k: pair(v) for k, v in self.lift_off_fraction.items()}
        if self.lift_off:
            out["lift_off_fraction"] = frac
            out["lift_off_probability"] = {k: pair(v) for k, v in self.lift_off_probability.items()}
        else:
            out["negative_contact_fraction"] = frac
        return out

    def __repr__(self) -> str:
        parts = ", ".join(f"{k}={v[0]:.4g}" for k, v in list(self.rms.items())[:3])
        return f"MonteCarloResult(realisations={self.realisations}, {parts}, ...)"


def _rms_interval(ms: np.ndarray) -> tuple[float, tuple[float, float]]:
    n = ms.size
    mean = float(ms.mean())
    if n < 2:
        return math.sqrt(mean), (math.nan, math.nan)
    half = _t975(n - 1) * float(ms.std(ddof=1)) / math.sqrt(n)
    return math.sqrt(mean), (math.sqrt(max(mean - half, 0.0)), math.sqrt(mean + half))


def monte_carlo(
    *,
    vehicle: str = "",
    model: str = "full",
    roads: int = 100,
    first_seed: int = 0,
    store=None,
    backend: str | None = "serial",
    workers: int | None = None,
    progress=False,
    **settings,
) -> MonteCarloResult:
    """Drive the nonlinear vehicle over ``roads`` ISO 8608 road realisations.

    ``settings`` are the point function's parameters (``road_class``, ``speed``,
    ``length``, ``dt``, ``rtol``, ``warmup``, ``lift_off`` "on"/"off", ``rebound``,
    ``compression``, ``friction``, ``friction_velocity``; defaults in the point
    function). ``store`` (a Zarr folder) keeps every finished chunk, so a rerun resumes.
    """
    from ..studies import sweep

    if model not in ("half", "full"):
        raise ParameterError("model", model, "'half' or 'full'")
    if not isinstance(roads, int) or isinstance(roads, bool) or roads < 2:
        raise ParameterError("roads", roads, "an integer >= 2")
    if not isinstance(first_seed, int) or first_seed < 0:
        raise ParameterError("first_seed", first_seed, "an integer >= 0")
    seeds = list(range(first_seed, first_seed + roads))
    _car(vehicle, model)  # a bad file fails here, not in every worker
    ds = sweep(
        {
            "point": f"{model}-car-road",
            "parameters": {"seed": seeds},
            "settings": {"vehicle": vehicle, **settings},
        },
        store=store,
        backend=backend,
        workers=workers,
        progress=progress,
    )
    ok = ds.status.values == 1
    if ok.sum() < 2:
        reasons = sorted({str(r) for r in ds.reason.values[~ok]})
        raise ParameterError("roads", roads, f"at least 2 successful roads; failures: {reasons}")
    corners = _HALF_CORNERS if model == "half" else _FULL_CORNERS
    comfort = "seat_acc_wk"
    rms = {}
    for name in ("bounce_acc", "pitch_acc"):
        rms[name] = _rms_interval(ds[f"ms_{name}"].values[ok])
    rms[comfort] = _rms_interval(ds["ms_comfort_wk"].values[ok])
    frac, prob = {}, {}
    n = int(ok.sum())
    for c in corners:
        rms[f"{c}_deflection"] = _rms_interval(ds[f"ms_{c}_deflection"].values[ok])
        rms[f"{c}_tyre_load"] = _rms_interval(ds[f"ms_{c}_tyre_load"].values[ok])
        f = ds[f"{c}_lift_off_fraction"].values[ok]
        half = _t975(n - 1) * float(f.std(ddof=1)) / math.sqrt(n)
        frac[c] = (float(f.mean()), (max(0.0, float(f.mean()) - half), float(f.mean()) + half))
        k = int((f > 0).sum())
        prob[c] = (k / n, _wilson(k, n))
    lift_off = settings.get("lift_off", _DEFAULTS["lift_off"]) == "on"
    return MonteCarloResult(
        rms=rms,
        lift_off_fraction=frac,
        lift_off_probability=prob if lift_off else None,
        realisations=n,
        dataset=ds,
        lift_off=lift_off,
    )


# --- statistical linearisation ------------------------------------------------------------


@dataclass(frozen=True)
class LinearisationResult:
    """Gaussian equivalent linear vehicle.

    Attributes
    ----------
    damping : dict
        Axle (``front``, ``rear``) -> equivalent strut damping c_eq [N s/m] (both
        corners of a full car's axle see the same road statistics).
    inertance : dict
        Axle -> equivalent inertance of its adaptive inerter, E[m_e(v)] [kg] (0 without).
    velocity_rms : dict
        Axle -> RMS strut extension rate sigma_v [m/s] at the fixed point.
    spectral : SpectralResult
        The equivalent linear vehicle's spectral response (RMS values, lift-off
        probabilities from the Gaussian tail).
    mean : dict
        Output name -> mean offset (non-zero for deflections and tyre loads when the
        damper is asymmetric: E[g(v)] = c (rebound - compression) sigma_v / sqrt(2 pi)
        acts on the strut like a constant force and sets the vehicle down or up).
    iterations : int
    converged : bool
    """

    damping: dict
    inertance: dict
    velocity_rms: dict
    spectral: Any
    mean: dict
    iterations: int
    converged: bool

    @property
    def lift_off(self) -> dict:
        """Corner -> P(contact force < 0) [-] of the equivalent linear tyre: the Gaussian
        tail of its dynamic load, shifted by the load's mean offset."""
        from .spectral import lift_off_probability

        res = self.spectral
        return {
            c: lift_off_probability(
                res.static_load[c], res.rms[f"{c}_tyre_load"], self.mean.get(f"{c}_tyre_load", 0.0)
            )
            for c in res.static_load
        }

    @property
    def rms(self) -> dict:
        """RMS of each output about zero: sqrt(sigma^2 + mean^2), comparable with the
        time simulation's RMS."""
        return {
            k: math.sqrt(v * v + self.mean.get(k, 0.0) ** 2) for k, v in self.spectral.rms.items()
        }


def _friction_gain(sigma: float, friction: float, v_f: float) -> float:
    """E[F_f tanh(v/v_f) v] / sigma^2 for v ~ N(0, sigma^2) = F_f E[sech^2(v/v_f)] / v_f."""
    if friction == 0.0:
        return 0.0
    if sigma <= 0.0:
        return friction / v_f
    # trapezoid over the narrower of the Gaussian and the sech^2 bump, both smooth and
    # decaying fast, so the rule converges geometrically
    half = min(9.0 * sigma, 40.0 * v_f)
    n = int(2 * half / (min(sigma, v_f) / 20.0)) + 1
    v = np.linspace(-half, half, n)
    pdf = np.exp(-0.5 * (v / sigma) ** 2) / (sigma * math.sqrt(2.0 * math.pi))
    val = np.trapezoid(pdf / np.cosh(v / v_f) ** 2, v)
    return friction * float(val) / v_f


def _adaptive_gain(adaptive, sigma: float) -> float:
    """E[m_e(v)] [kg] for v ~ N(0, sigma^2): the Gaussian equivalent inertance of an
    adaptive inerter whose force is m_e(v) dv/dt (laws ``thesis`` and ``momentum``).

    In a stationary Gaussian response v and dv/dt are uncorrelated, hence independent,
    so E[m_e(v) a a] / E[a^2] = E[m_e(v)]."""
    from ..elements.adaptive_flywheel import flywheel_inertance

    row = adaptive.row()
    if sigma <= 0.0:
        return float(flywheel_inertance(row, 0, 0.0, 0.0, 0.0)[0])
    # m_e is smooth except for a kink at the saturation speed: a fine trapezoid
    v = np.linspace(-9.0 * sigma, 9.0 * sigma, 4001)
    me = np.array([flywheel_inertance(row, 0, float(x), 0.0, 0.0)[0] for x in v])
    pdf = np.exp(-0.5 * (v / sigma) ** 2) / (sigma * math.sqrt(2.0 * math.pi))
    return float(np.trapezoid(me * pdf, v))


def _with_damping(params, damping: dict, inertance: dict | None = None):
    """Vehicle parameters with each axle's strut damping replaced (``front``, ``rear``)
    and, where ``inertance`` gives one, the adaptive inerter replaced by a constant one.
    A network strut gets ``damping`` as a damper in parallel (its friction's equivalent)."""

    def corner(c, name):
        network = getattr(c.strut, "network", None)
        if network is not None:
            if damping[name] <= 0.0:
                return c
            from .parameters import NetworkStrut

            values = c.strut.parameters
            extra = "c_friction"
            while extra in values:
                extra += "_"
            strut = NetworkStrut(f"({network}) | {extra}", {**values, extra: damping[name]})
            return dataclasses.replace(c, strut=strut)
        strut = dataclasses.replace(c.strut, damping=damping[name])
        if inertance is not None and c.strut.adaptive is not None:
            strut = dataclasses.replace(
                strut, inertance=c.strut.inertance + inertance[name], adaptive=None
            )
        return dataclasses.replace(c, strut=strut)

    return dataclasses.replace(
        params, **{axle: corner(getattr(params, axle), axle) for axle in _HALF_CORNERS}
    )


def statistical_linearisation(
    *,
    vehicle: str = "",
    model: str = "full",
    road_class: str = "C",
    speed: float = 20.0,
    rebound: float = 1.0,
    compression: float = 1.0,
    friction: float = 0.0,
    friction_velocity: float = 0.01,
    tol: float = 1e-10,
    max_iter: int = 200,
    points: int = 4000,
) -> LinearisationResult:
    """Equivalent linear vehicle of the asymmetric dampers and strut friction.

    Fixed-point iteration on the strut damping, c_eq = c (rebound + compression) / 2
    + friction gain(sigma_v), sigma_v from the spectral response of the current
    linear vehicle (the RMS of the axle's strut extension rate; a full car's axle uses
    its left corner's, since both corners share the axle's parameters). See the module
    docstring.
    """
    from .model import build
    from .roads import road_spectrum
    from .spectral import spectral_response

    params, vehicle_lin = _load_vehicle(vehicle, model)
    for name, val in (("rebound", rebound), ("compression", compression)):
        check_positive(name, val)
    check_nonnegative("friction", friction, "N")
    v_f = check_positive("friction_velocity", friction_velocity, "m/s")
    road = road_spectrum(road_class)
    corners = _HALF_CORNERS  # axles; the left corner stands for a full car's axle
    probe = {a: (a if vehicle_lin.kind == "half" else f"{a}_left") for a in corners}
    devices = [c for c in corners if getattr(getattr(params, c).strut, "device", None)]
    if devices:
        raise ParameterError(
            f"{devices[0]}.device",
            getattr(params, devices[0]).strut.device.source,
            "no device: the statistical linearisation covers asymmetric dampers, strut "
            "friction and adaptive inerters; a device's response comes from the Monte "
            "Carlo (vehicle monte-carlo)",
        )
    networks = [c for c in corners if getattr(getattr(params, c).strut, "network", None)]
    if networks and (rebound != 1.0 or compression != 1.0):
        raise ParameterError(
            "rebound/compression",
            (rebound, compression),
            f"1 with the network strut at {networks[0]} ("
            f"{getattr(params, networks[0]).strut.network}): an asymmetric damper needs a "
            "Strut, whose damper is one element",
        )
    # a network strut's friction becomes a damper in parallel with the network
    base = {c: 0.0 if c in networks else getattr(params, c).strut.damping for c in corners}
    adaptive = {c: getattr(params, c).strut.adaptive for c in corners}
    inertance = {c: (0.0 if a is None else a.inertance_min) for c, a in adaptive.items()}
    damping = {c: base[c] * 0.5 * (rebound + compression) for c in corners}
    sigma = dict.fromkeys(corners, 0.0)
    converged = False
    it = 0
    res = None
    while it < max_iter:
        it += 1
        veh = build(_with_damping(params, damping, inertance))
        lo, hi = road.band
        freq = np.geomspace(lo * speed, hi * speed, points)
        res = spectral_response(veh, road, speed, freq=freq)
        w2 = (2.0 * math.pi * freq) ** 2
        new = {}
        for c in corners:
            psd = res.psd[f"{probe[c]}_deflection"]
            ms_rate = float(np.trapezoid(psd * w2 * freq, np.log(freq)))
            sigma[c] = math.sqrt(ms_rate)
            new[c] = base[c] * 0.5 * (rebound + compression) + _friction_gain(
                sigma[c], friction, v_f
            )
        new_b = {
            c: (0.0 if adaptive[c] is None else _adaptive_gain(adaptive[c], sigma[c]))
            for c in corners
        }
        change = max(abs(new[c] - damping[c]) / max(new[c], 1e-300) for c in corners)
        change = max(
            change,
            max(abs(new_b[c] - inertance[c]) / max(new_b[c], 1e-300) for c in corners),
        )
        # damped update: the friction gain falls like 1/sigma, and sigma falls with c
        damping = {c: 0.5 * (new[c] + damping[c]) for c in corners}
        inertance = {c: 0.5 * (new_b[c] + inertance[c]) for c in corners}
        if change < tol:
            damping, inertance = new, new_b
            converged = True
            veh = build(_with_damping(params, damping, inertance))
            res = spectral_response(veh, road, speed, freq=freq)
            break
    # mean offset from the rectified part of the asymmetric damper: a constant
    # tension f_j = c (rebound - compression) sigma_v / sqrt(2 pi) in every strut
    K = veh.static_stiffness_matrix()
    gen = np.zeros(K.shape[0])
    for con in veh.connections:
        if con.name.endswith("_strut"):
            name = con.name[: -len("_strut")]
            axle = name.split("_")[0]
            f = base[axle] * (rebound - compression) * sigma[axle] / math.sqrt(2.0 * math.pi)
            gen -= con.u * f
    q_mean = np.linalg.solve(K, gen)
    mean = {}
    for name, o in veh.outputs.items():
        if name.endswith("_tyre_load"):
            # dynamic load from the tyre's own extension (Tyre law, no road offset)
            con = next(c for c in veh.connections if c.name == name.replace("_load", ""))
            mean[name] = -float(con.law.mck()[2] * (con.u @ q_mean))
        else:
            mean[name] = float(o.P @ q_mean)
    return LinearisationResult(
        damping=damping,
        inertance=inertance,
        velocity_rms=sigma,
        spectral=res,
        mean=mean,
        iterations=it,
        converged=converged,
    )
