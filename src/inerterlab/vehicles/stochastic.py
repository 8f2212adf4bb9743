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
    :func:`statistical_linearisation` replaces every nonlinear element of the core
    vehicle (gas springs, bump stops, quadratic or asymmetric dampers, friction, adaptive
    inerters, a device's nonlinear parts) by its Gaussian equivalent, the expectation of
    the derivative of its own force law under the Gaussian motion of its argument
    (:mod:`inerterlab.systems.gaussian`; Roberts and Spanos, *Random Vibration and
    Statistical Linearization*, Wiley 1990, ch. 5), with the argument's variance from the
    spectral integral of the equivalent linear car on the road, iterated to a fixed
    point. Tyre lift-off is not linearised: its probability is the Gaussian tail of the
    equivalent tyre load (as in :func:`spectral_response`). A rectifying law (an
    asymmetric damper) has a mean force under the zero-mean Gaussian motion, from its own
    law (:func:`~inerterlab.systems.gaussian.mean_force`); applied to the equivalent car
    as constant loads it sets the car down or up by a mean offset
    (:func:`~inerterlab.systems.equilibrium.loaded_rest`), and each output's RMS is
    sqrt(mean^2 + sigma^2). The linearisation ignores the non-Gaussian shape of the
    response; :func:`monte_carlo` measures the error.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError, check_nonnegative, check_positive
from ..h2 import resolvent_solve
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
    return _car_text(path, kind)[0]


def _car_text(path: str, kind: str):
    """(parameters, the file's text) of :func:`_car`."""
    from ..io import CONFIG_SIZE_LIMIT, read_text_limited
    from .config import example_vehicle_path, loads_vehicle
    from .parameters import FullCar

    where = path if path else example_vehicle_path()
    text = read_text_limited(where, "vehicle file", limit=CONFIG_SIZE_LIMIT)
    params = loads_vehicle(text, str(where))
    if kind == "half" and hasattr(params, "half_car"):
        params = params.half_car()
    if isinstance(params, FullCar) != (kind == "full"):
        raise ParameterError(
            "vehicle", path or "(example)", f"a {kind}-car file or a full-car file for 'half'"
        )
    return params, text


#: the core vehicles built in this process, keyed on the vehicle file's text, the model
#: and the options that shape the system: each road of a Monte Carlo study (one process
#: runs many) swaps the road and keeps the system, its factored tables and compiled code
_SYSTEMS: dict = {}
_SYSTEMS_KEPT = 8


def _system(params: Mapping[str, Any], kind: str):
    """(parameters, core vehicle) of the road point ``params`` (built once per process
    for a vehicle file's content and the options)."""
    import hashlib

    from ..systems.vehicle import vehicle as core_vehicle

    p, text = _car_text(params["vehicle"], kind)
    opts = dict(lift_off=params["lift_off"] == "on", rebound=float(params["rebound"]),
                compression=float(params["compression"]), friction=float(params["friction"]),
                friction_velocity=float(params["friction_velocity"]))  # fmt: skip
    key = (hashlib.sha256(text.encode()).hexdigest(), kind, tuple(sorted(opts.items())))
    got = _SYSTEMS.get(key)
    if got is None:
        if len(_SYSTEMS) >= _SYSTEMS_KEPT:
            _SYSTEMS.pop(next(iter(_SYSTEMS)))
        got = (p, core_vehicle(p, **opts))
        _SYSTEMS[key] = got
    return got


def _one_road(params: Mapping[str, Any], kind: str) -> dict[str, float]:
    from .simulation import simulate_vehicle

    p, system = _system(params, kind)
    dt = float(params["dt"])
    r = _tracks(p, params, int(params["seed"]))
    res = simulate_vehicle(
        p,
        r,
        dt,
        system=system,
        rtol=float(params["rtol"]),
        warmup=float(params["warmup"]),
        fixed_step=float(params["fixed_step"]) or None,
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
    "fixed_step": ParameterSpec(
        low=0.0, high=0.1, unit="s", doc="fixed Runge-Kutta (RK4) step; 0: adaptive at rtol"
    ),
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
    "fixed_step": 0.0,
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


#: simulated time [s] of the short road :func:`_prepare` drives in the calling process
PREPARE_SPAN = 1.0


def _prepare(vehicle: str, model: str, roads: int, first_seed: int, settings: dict) -> None:
    """Before the worker processes start (forked from this one, they inherit what it
    holds): drive the car over a short road (:data:`PREPARE_SPAN`) twice, which builds
    the core vehicle with its comfort observers and factored tables once and loads the
    compiled integrator; where the whole study's integrations would take more CPU time
    than the compilation of the structure's own right-hand side pays for
    (:func:`inerterlab.systems._compiled.rhs_for`), compile that here, once, instead of
    in every worker."""
    import time

    from ..systems import _compiled
    from ..systems.vehicle import _factored

    point = {**_DEFAULTS, **settings, "vehicle": vehicle, "seed": first_seed}
    span = min(PREPARE_SPAN, float(point["length"]) / float(point["speed"]))
    short = dict(point, length=span * float(point["speed"]))
    _one_road(short, model)  # builds and loads
    t0 = time.process_time()
    _one_road(short, model)
    per_second = (time.process_time() - t0) / span
    _, system = _system(point, model)
    itab = _factored(system.info["comfort_observed"][1])[0]
    _compiled.record(itab, per_second * roads * float(point["length"]) / float(point["speed"]))
    _compiled.rhs_for(itab)


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
    ``length``, ``dt``, ``rtol``, ``fixed_step`` (0: adaptive), ``warmup``, ``lift_off`` "on"/"off", ``rebound``,
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
    from ..systems.vehicle import vehicle as core_vehicle

    # a bad file, or a car that does not rest on its struts, fails here, not in every worker
    core_vehicle(_car(vehicle, model), lift_off=False)
    if backend == "processes":
        _prepare(vehicle, model, roads, first_seed, settings)
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
    """Gaussian-equivalent linear vehicle (:func:`statistical_linearisation`).

    Attributes
    ----------
    equivalents : dict
        Nonlinear element (its name in the core vehicle, e.g. ``front_left.c``) ->
        (argument, equivalent gain): ``displacement`` -> stiffness k_eq [N/m],
        ``velocity`` -> damping c_eq [N s/m], ``acceleration`` -> inertance b_eq [kg].
    argument_rms : dict
        Element -> RMS of the argument its equivalent depends on at the fixed point
        [m for a displacement, m/s for a velocity and for an inertance's speed].
    spectral : SpectralResult
        The equivalent linear vehicle's spectral response on the road: the random part
        (its ``rms`` is the standard deviation about the mean offset).
    vehicle : LinearVehicle
        The equivalent linear vehicle (``linearised`` True where a nonlinear element was
        replaced).
    iterations : int
    converged : bool
    mean : dict
        Output -> mean offset [its unit] from the rectifying laws' mean forces (the
        deflections [m] and dynamic tyre loads [N]; 0 for the accelerations, whose mean
        is zero in a stationary response; all 0 without a rectifying law).
    mean_forces : dict
        Dissipative nonlinear element -> its mean force E[F] [N] (tension positive) at
        its ``argument_rms``, the constant load that sets the car's mean offset.
    """

    equivalents: dict
    argument_rms: dict
    spectral: Any
    vehicle: Any
    iterations: int
    converged: bool
    mean: dict = dataclasses.field(default_factory=dict)
    mean_forces: dict = dataclasses.field(default_factory=dict)

    def _gains(self, argument: str) -> dict:
        return {k: g for k, (a, g) in self.equivalents.items() if a == argument}

    @property
    def stiffness(self) -> dict:
        """Element -> k_eq [N/m] of the elastic nonlinear elements."""
        return self._gains("displacement")

    @property
    def damping(self) -> dict:
        """Element -> c_eq [N s/m] of the dissipative nonlinear elements."""
        return self._gains("velocity")

    @property
    def inertance(self) -> dict:
        """Element -> b_eq [kg] of the nonlinear inertances (adaptive inerters)."""
        return self._gains("acceleration")

    @property
    def rms(self) -> dict:
        """RMS about the static equilibrium of each output of the equivalent vehicle
        (:class:`SpectralResult` names and units): sqrt(mean^2 + sigma^2), the mean
        offset (:attr:`mean`) with the Gaussian random part, comparable with the time
        simulation's RMS."""
        return {k: math.hypot(v, self.mean.get(k, 0.0)) for k, v in self.spectral.rms.items()}

    @property
    def lift_off(self) -> dict:
        """Corner -> P(contact force < 0) [-]: the Gaussian tail of the equivalent
        vehicle's dynamic tyre load, shifted by its mean offset, on its static load."""
        from .spectral import lift_off_probability

        res = self.spectral
        return {
            c: lift_off_probability(res.static_load[c], res.rms[f"{c}_tyre_load"],
                                    self.mean.get(f"{c}_tyre_load", 0.0))
            for c in res.static_load
        }  # fmt: skip

    def to_dict(self) -> dict:
        units = {"displacement": "N/m", "velocity": "N s/m", "acceleration": "kg"}
        return {
            "model": "statistical linearisation (Gaussian equivalent)",
            "equivalents": {k: {"argument": a, "value": g, "unit": units[a]}
                            for k, (a, g) in self.equivalents.items()},  # fmt: skip
            "argument_rms": dict(self.argument_rms),
            "mean_forces": dict(self.mean_forces),
            "rms": self.rms,
            "mean": dict(self.mean),
            "sigma": dict(self.spectral.rms),
            "units": dict(self.spectral.units),
            "lift_off_probability_gaussian": self.lift_off,
            "iterations": self.iterations,
            "converged": self.converged,
        }


def _parameters_of(vehicle, model: str):
    """The HalfCar or FullCar of ``vehicle`` (a file path, '' for the packaged example,
    or parameters) as ``model`` (``half`` takes a full car's half car)."""
    from .config import example_vehicle_path, load_vehicle

    if model not in ("half", "full"):
        raise ParameterError("model", model, "'half' or 'full'")
    if isinstance(vehicle, str | type(None)) or hasattr(vehicle, "read_text"):
        params = load_vehicle(vehicle if vehicle else example_vehicle_path())
    else:
        params = vehicle
    full = hasattr(params, "half_car")
    if model == "half" and full:
        params = params.half_car()
    elif model == "full" and not full:
        raise ParameterError("vehicle", vehicle or "(example)", "a full-car file for 'full'")
    return params


def _argument_rms(sys, veh, els, ss, fac, freq) -> dict:
    """RMS [m, m/s] of each nonlinear element's argument (relative displacement, or
    relative velocity for a damper and an inertance) under the road of the input factor
    ``fac`` (:func:`~inerterlab.vehicles.spectral.input_factor`), from the state space
    ``ss`` of the core layout: the spectral integral over ``freq``."""
    from ..systems.gaussian import argument_rows
    from .spectral import _mean_square

    A, B = ss[0], ss[1]
    m = sys.info["roads"]
    Br, Bd = B[:, 0 : 3 * m : 3], B[:, 1 : 3 * m : 3]
    Cr, Dg = argument_rows(sys, els, ss)
    Rr, Sr = Dg[:, 0 : 3 * m : 3], Dg[:, 1 : 3 * m : 3]
    s = 2j * math.pi * np.asarray(freq, dtype=float)
    X = resolvent_solve(A, s, Br[None] + s[:, None, None] * Bd[None])
    # (frequencies, elements, wheels)
    H = np.einsum("ej,fjw->few", Cr, X) + Rr[None] + s[:, None, None] * Sr[None]
    psd = np.sum(np.abs(H @ fac) ** 2, axis=2).T
    return {name: math.sqrt(_mean_square(freq, psd[j])) for j, (_, name, _) in enumerate(els)}


def statistical_linearisation(
    *,
    vehicle: Any = "",
    model: str = "full",
    road_class: str = "C",
    speed: float = 20.0,
    rebound: float = 1.0,
    compression: float = 1.0,
    friction: float = 0.0,
    friction_velocity: float = 0.01,
    networks: dict | None = None,
    tol: float = 1e-10,
    max_iter: int = 200,
    points: int = 4000,
) -> LinearisationResult:
    """Gaussian-equivalent linear vehicle of the core car on an ISO 8608 road.

    The car is the core vehicle (:func:`inerterlab.systems.vehicle.vehicle`, tyres that
    always press) of ``vehicle`` (a file path, '' for the packaged example, or a HalfCar
    / FullCar) as ``model``, with ``networks`` at its corners and, where given, the
    struts' ``rebound`` / ``compression`` factors and ``friction`` [N] over
    ``friction_velocity`` [m/s] (the time simulation's options). Every nonlinear element
    is replaced by its Gaussian equivalent (:mod:`inerterlab.systems.gaussian`: the
    expectation of its own law's derivative under the Gaussian motion of its argument),
    the argument's variance from the spectral integral of the equivalent linear car
    (the road of class ``road_class`` at ``speed`` [m/s] with its coherence and the
    wheelbase delay, ``points`` frequencies over its band, as
    :func:`~inerterlab.vehicles.spectral.spectral_response`), iterated to a fixed point
    (damped: the mean of the new and the last gains) until no gain changes by more than
    ``tol`` relative. A linear car is its own equivalent (no iteration). Each
    dissipative element's mean force at its fixed point (non-zero for a rectifying law,
    an asymmetric damper) loads the equivalent car: its mean offset is the result's
    ``mean``, and ``rms`` combines it with the random part.
    """
    from ..systems.gaussian import equivalent_gains, nonlinear_elements
    from ..systems.vehicle import vehicle as core_vehicle
    from .linear import from_state_space
    from .roads import road_spectrum
    from .spectral import input_factor, spectral_response

    params = _parameters_of(vehicle, model)
    for name, val in (("rebound", rebound), ("compression", compression)):
        check_positive(name, val)
    check_nonnegative("friction", friction, "N")
    check_positive("friction_velocity", friction_velocity, "m/s")
    v = check_positive("speed", speed, "m/s")
    if not isinstance(max_iter, int) or max_iter < 1:
        raise ParameterError("max_iter", max_iter, "an integer >= 1")
    opts = {}
    if rebound != 1.0 or compression != 1.0:
        opts.update(rebound=rebound, compression=compression)
    if friction > 0.0:
        opts.update(friction=friction, friction_velocity=friction_velocity)
    sys = core_vehicle(params, networks=networks, lift_off=False, **opts)
    els = nonlinear_elements(sys)
    road = road_spectrum(road_class)
    lo, hi = road.band
    freq = np.geomspace(lo * v, hi * v, int(points))
    if not els:  # linear: its own equivalent
        veh = from_state_space(sys, sys.linear_state_space(), False)
        res = spectral_response(veh, road, v, freq=freq)
        return LinearisationResult({}, {}, res, veh, 0, True)
    fac = []  # the road's input factor, from the first equivalent car (the same for all)

    def argument_rms(eq, ss):
        veh = from_state_space(eq, ss, True)
        if not fac:
            fac.append(input_factor(veh, road, v, freq))
        return _argument_rms(eq, veh, els, ss, fac[0], freq)

    fp = equivalent_gains(sys, argument_rms, tol=tol, max_iter=max_iter)
    gains, eq, sigma = fp.gains, fp.system, fp.sigma
    veh = from_state_space(eq, fp.state_space, True)
    res = spectral_response(veh, road, v, freq=freq)
    equivalents = {name: (arg, float(gains[e])) for e, name, arg in els}
    forces, mean = _mean_offset(sys, eq, veh, els, sigma)
    return LinearisationResult(
        equivalents=equivalents, argument_rms=sigma, spectral=res, vehicle=veh,
        iterations=fp.iterations, converged=fp.converged, mean=mean, mean_forces=forces,
    )  # fmt: skip


def _mean_offset(sys, eq, veh, els, sigma: dict) -> tuple[dict, dict]:
    """(element -> mean force [N], output -> mean offset) of the equivalent car ``eq``
    (its :class:`LinearVehicle` ``veh``) of ``sys`` under the mean forces of the
    dissipative nonlinear elements ``els`` at their argument RMS ``sigma``, each from its
    own law in ``sys``: those forces as constant loads, the car's rest under them by
    Newton's method (exact for the equivalent car, linear), and each displacement-like
    output (deflections, tyre loads) read at that rest from its row of the state space;
    accelerations have mean zero in a stationary response."""
    from ..systems.equilibrium import loaded_rest
    from ..systems.gaussian import mean_force

    forces = {e: (name, mean_force(sys, e, sigma[name]))
              for e, name, arg in els if arg == "velocity"}  # fmt: skip
    mean = dict.fromkeys(veh.outputs, 0.0)
    if any(f != 0.0 for _, f in forces.values()):
        x = loaded_rest(eq, {e: f for e, (_, f) in forces.items()})
        Cy = veh._ss[3]
        for k, out in veh.outputs.items():
            if not out.unit.endswith("/s^2"):
                mean[k] = float(Cy[k] @ x)
    return {name: f for name, f in forces.values()}, mean
