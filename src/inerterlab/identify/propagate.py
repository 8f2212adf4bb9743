"""Carry the uncertainty of identified device parameters to ride metrics: :func:`propagate`.

A fit gives the device parameters with a covariance (:attr:`FitResult.covariance`). A
car built with the identified device then has ride metrics that are uncertain too.
Two ways to carry the parameter covariance Sigma to a metric g(theta):

``delta``
    First order: var g = grad^T Sigma grad, the gradient by central differences with
    the step of each parameter ``step`` times its standard error (so the step follows
    the size of the uncertainty, not of the value), interval value +/- 1.96 std.
``monte-carlo``
    Draws of theta from the multivariate normal N(theta_hat, Sigma) (seeded), the
    metric of each draw, interval between the 2.5 and 97.5 percentiles, std the
    sample standard deviation. Draws with a parameter <= 0 whose estimate is > 0 are
    drawn again (the device needs positive damping and stiffness).

Both report ``value`` = the metric at the estimate. They agree when the metric is close
to linear over the spread of the parameters; the Monte Carlo interval also shows a
skew where it is not.

The metrics (:func:`ride_metrics`): the simulated RMS body acceleration, Wk-weighted
body acceleration, tyre grip index and suspension deflection over an excitation
(:func:`inerterlab.simulate.simulate_metrics`), and, without simulation, H2 norms of a
linearised car from unit white road velocity and the body resonance frequency of its
frequency response (:func:`linearised_car`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from ..errors import ParameterError, check_choice, check_positive
from ..suspension.model import model_of

__all__ = [
    "propagate",
    "propagate_function",
    "ride_metrics",
    "linearised_car",
    "device_car",
    "SIMULATED_METRICS",
    "LINEAR_METRICS",
]

SIMULATED_METRICS = ("rms_body_acc", "rms_body_acc_wk", "rms_tyre_grip", "rms_deflection")
LINEAR_METRICS = (
    "h2_body_acc",
    "h2_body_acc_wk",
    "h2_tyre_grip",
    "h2_suspension_deflection",
    "body_resonance_hz",
)
UNITS = {
    "rms_body_acc": "m/s^2",
    "rms_body_acc_wk": "m/s^2",
    "rms_tyre_grip": "-",
    "rms_deflection": "m",
    "h2_body_acc": "(m/s^2) per unit white road velocity",
    "h2_body_acc_wk": "(m/s^2) per unit white road velocity",
    "h2_tyre_grip": "(-) per unit white road velocity",
    "h2_suspension_deflection": "(m) per unit white road velocity",
    "body_resonance_hz": "Hz",
}
DEVICE_FIELDS = ("stiffness", "damping", "friction")
Z975 = 1.959963984540054


# -- cars with the identified device ---------------------------------------------------
def device_car(car, params: dict):
    """``car`` (suspension ``device`` or ``device-afw``) with its device's ``stiffness``
    (k_h), ``damping`` (b_ah) and ``friction`` (F_fh) replaced by ``params``, and, for
    ``device-afw``, the flywheel's ``changing_ratio`` if given. Other keys are an error."""
    car = model_of(car)
    if car.suspension not in ("device", "device-afw"):
        raise ParameterError(
            "car", car.suspension, "a 'device' or 'device-afw' quarter car (or a car factory)"
        )
    dev = {k: float(v) for k, v in params.items() if k in DEVICE_FIELDS}
    other = set(params) - set(DEVICE_FIELDS) - {"changing_ratio"}
    if other:
        raise ParameterError("parameters", sorted(other), f"names among {DEVICE_FIELDS}")
    out = dataclasses.replace(car, device=dataclasses.replace(car.device, **dev))
    if "changing_ratio" in params:
        if car.suspension != "device-afw":
            raise ParameterError("changing_ratio", params["changing_ratio"], "a device-afw car")
        out = dataclasses.replace(
            out, flywheel=car.flywheel.with_changing_ratio(float(params["changing_ratio"]))
        )
    return out


def _road_scale(road_class: str, speed: float) -> float:
    from ..excitation import ISO8608_CLASSES, ISO8608_N0

    check_choice("road_class", road_class, tuple(ISO8608_CLASSES))
    v = check_positive("speed", speed, "m/s")
    return math.pi * ISO8608_N0 * math.sqrt(2.0 * ISO8608_CLASSES[road_class] * v)


def linearised_car(car, *, road_class: str = "C", speed: float = 20.0, start: dict | None = None):
    """The linear state space of a quarter car on an ISO 8608 road, its nonlinear
    elements linearised statistically: a
    :class:`~inerterlab.suspension.linear.LinearQuarterCar` driven by the road velocity.

    A linear car (``traditional``, ``cfw``) is its own state space. Otherwise every
    nonlinear element of the car's core system (a device's friction, an adaptive
    flywheel) is replaced by its Gaussian equivalent from its own law
    (:mod:`inerterlab.systems.gaussian`: a friction's c_eq = E[v F(v)] / sigma_v^2, a
    flywheel's b_eq = E[m_e(v)]), its argument's RMS taken in the equivalent car itself
    on the road of ``road_class`` at ``speed`` [m/s] (ISO 8608, waviness 2: white road
    velocity of the class's level, no band limits; a Lyapunov equation), iterated to a
    fixed point (:func:`~inerterlab.systems.gaussian.equivalent_gains`). ``info`` of
    the result: ``equivalents`` (element name -> (argument, gain [N s/m, kg or N/m])),
    ``argument_rms`` (element name -> m/s or m) and ``iterations``. ``start``: the
    ``equivalents`` of a car of the same structure nearby to start the iteration from
    (the result is the same fixed point, to its tolerance of 1e-10). ConvergenceError
    where the gains do not settle; ParameterError naming an element that has no
    Gaussian equivalent (a tyre that lifts off).
    """
    from ..errors import ConvergenceError
    from ..h2 import gramian
    from ..suspension.linear import road_relative, road_velocity_form
    from ..systems.gaussian import argument_rows, equivalent_gains, nonlinear_elements
    from ..systems.quarter_car import system_of

    scale = _road_scale(road_class, speed)
    sys = system_of(model_of(car))
    els = nonlinear_elements(sys)

    def argument_rms(eq, ss):
        A, B, Ti = road_relative(eq, ss)
        Cr, Dr = argument_rows(eq, els, ss)
        if np.max(np.abs(Dr)) > 1e-12 * (1.0 + float(np.max(np.abs(Cr)))):
            raise ParameterError("car", "an element driven straight by the road",
                                 "nonlinear elements inside the suspension")  # fmt: skip
        P = gramian(A, B, what="equivalent linearisation")
        Cr = Cr @ Ti
        return {name: scale * math.sqrt(max(float(Cr[j] @ P @ Cr[j]), 0.0))
                for j, (_, name, _) in enumerate(els)}  # fmt: skip

    if start is not None:
        index = {name: e for e, name, _ in els}
        unknown = sorted(set(start) - set(index))
        if unknown or len(start) != len(index):
            raise ParameterError("start", unknown or sorted(start),
                                 f"the equivalents of the elements {sorted(index)}")  # fmt: skip
        start = {index[name]: float(v[1] if isinstance(v, tuple) else v)
                 for name, v in start.items()}  # fmt: skip
    fp = equivalent_gains(sys, argument_rms, start=start)
    if not fp.converged:
        raise ConvergenceError(
            f"statistical linearisation of the {model_of(car).suspension!r} car: the "
            f"equivalents did not settle in {fp.iterations} iterations"
        )
    info = {
        "equivalents": {name: (arg, float(fp.gains[e])) for e, name, arg in els},
        "argument_rms": dict(fp.sigma),
        "iterations": fp.iterations,
    }
    return road_velocity_form(fp.system, fp.state_space, info)


def _body_resonance(lin) -> float:
    """Frequency [Hz] of the peak of |X3 / X1| (body over road displacement) in
    0.2-5 Hz, or NaN if the peak is at an edge: the gain on a 0.02 Hz grid (one
    :func:`inerterlab.h2.resolvent_solve` for all of it), refined by a bounded scalar
    search between the grid neighbours of its largest value."""
    from scipy.optimize import minimize_scalar

    from ..h2 import resolvent_solve

    n = lin.A.shape[0]
    # X3 - X1: the tyre's deflection and the suspension's (no feed-through: both are
    # displacements)
    c = lin.C["tyre_deflection"] + lin.C["suspension_deflection"]
    B = np.asarray(lin.B, dtype=float)

    def gain(f):
        s = 2j * math.pi * np.atleast_1d(np.asarray(f, dtype=float))
        X = resolvent_solve(lin.A, s, np.broadcast_to(B, (s.size, n)))
        return np.abs(1.0 + s * (X @ c))

    grid = np.arange(0.2, 5.0001, 0.02)
    g = gain(grid)
    i = int(np.argmax(g))
    if i == 0 or i == grid.size - 1:
        return math.nan
    res = minimize_scalar(
        lambda f: -float(gain(f)[0]),
        bounds=(grid[i - 1], grid[i + 1]),
        method="bounded",
        options={"xatol": 1e-7},
    )
    return float(res.x)


def ride_metrics(
    car,
    excitation=None,
    horizon: float = 10.0,
    *,
    linear: bool = True,
    road_class: str = "C",
    speed: float = 20.0,
    start: dict | None = None,
) -> dict:
    """Ride metrics of one car: the :data:`SIMULATED_METRICS` over ``excitation`` (if
    given; ``None`` where not finite) and, with ``linear``, the :data:`LINEAR_METRICS`
    of :func:`linearised_car` (``start``: its equivalents' starting point)."""
    car = model_of(car)
    out = {}
    if excitation is not None:
        from ..simulate import simulate_metrics

        m = simulate_metrics(car, excitation, horizon)
        for k in SIMULATED_METRICS:
            out[k] = m.get(k)
    if linear:
        from ..metrics import h2_norms_state_space

        lin = linearised_car(car, road_class=road_class, speed=speed, start=start)
        norms = h2_norms_state_space(lin, label=car.suspension).norms
        out["h2_body_acc"] = norms["body_acc"]
        out["h2_body_acc_wk"] = norms["body_acc_wk"]
        out["h2_tyre_grip"] = norms["tyre_grip"]
        out["h2_suspension_deflection"] = norms["suspension_deflection"]
        out["body_resonance_hz"] = _body_resonance(lin)
    return out


# -- the propagation itself ------------------------------------------------------------
def _source(source, widen: bool = True):
    from .fit import FitResult

    if isinstance(source, FitResult):
        names = tuple(source.parameter_order)
        mean = np.array([source.parameters[n].value for n in names], dtype=float)
        cov = np.asarray(source.covariance, dtype=float)
        if widen:
            # each parameter's t quantile (few effective tests) carried over: the
            # standard deviations scaled by q / 1.96, correlations kept, so that
            # +/- 1.96 sqrt(diagonal) is the printed interval
            q = np.array([source.parameters[n].quantile for n in names])
            d = np.where(q > 0, q / Z975, 1.0)
            cov = cov * np.outer(d, d)
    else:
        try:
            mean, cov, names = source
        except (TypeError, ValueError):
            raise ParameterError(
                "source", type(source).__name__, "a FitResult or a (mean, covariance, names) tuple"
            ) from None
        mean = np.atleast_1d(np.asarray(mean, dtype=float))
        cov = np.atleast_2d(np.asarray(cov, dtype=float))
        names = tuple(names)
    p = mean.size
    if cov.shape != (p, p) or len(names) != p:
        raise ParameterError(
            "covariance", cov.shape, f"a {p} x {p} matrix and {p} names for {p} parameters"
        )
    if not (np.all(np.isfinite(mean)) and np.all(np.isfinite(cov))):
        raise ParameterError("covariance", "not finite", "finite mean and covariance")
    if not np.allclose(cov, cov.T, rtol=1e-8, atol=0.0):
        raise ParameterError("covariance", "not symmetric", "a symmetric matrix")
    if np.linalg.eigvalsh(cov).min() < -1e-9 * max(float(np.abs(cov).max()), 1e-300):
        raise ParameterError("covariance", "not positive semi-definite", "a covariance matrix")
    return mean, 0.5 * (cov + cov.T), names


def _as_float(v) -> float:
    return math.nan if v is None else float(v)


def propagate_function(
    f: Callable[[np.ndarray], dict],
    mean,
    cov,
    *,
    method: str = "delta",
    n: int = 200,
    seed: int = 0,
    step: float = 0.5,
) -> dict:
    """Propagate N(mean, cov) through ``f`` (parameter vector -> {metric: float}).

    Returns ``{metric: {"value", "ci95", "std"}}`` (plus ``"mean"`` and ``"draws"`` for
    Monte Carlo); a metric that is not finite at the estimate or at any evaluation has
    value, interval and std ``None``. Parameters with zero variance are not perturbed.
    See the module docstring for the two methods.
    """
    check_choice("method", method, ("delta", "monte-carlo"))
    mean = np.asarray(mean, dtype=float)
    cov = np.asarray(cov, dtype=float)
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    free = np.nonzero(se > 0)[0]
    f0 = {k: _as_float(v) for k, v in f(mean.copy()).items()}
    keys = list(f0)
    out = {}
    if method == "delta":
        check_positive("step", step)
        grads = np.zeros((len(keys), free.size))
        for j, k in enumerate(free):
            h = step * se[k]
            up, dn = mean.copy(), mean.copy()
            up[k] += h
            dn[k] -= h
            fp, fm = f(up), f(dn)
            grads[:, j] = [(_as_float(fp[m]) - _as_float(fm[m])) / (2.0 * h) for m in keys]
        S = cov[np.ix_(free, free)]
        for i, m in enumerate(keys):
            g = grads[i]
            if not (math.isfinite(f0[m]) and np.all(np.isfinite(g))):
                out[m] = {"value": None, "ci95": None, "std": None}
                continue
            s = math.sqrt(max(float(g @ S @ g), 0.0))
            out[m] = {"value": f0[m], "ci95": (f0[m] - Z975 * s, f0[m] + Z975 * s), "std": s}
        return out
    n = int(n)
    if n < 2:
        raise ParameterError("n", n, "at least 2 Monte Carlo draws")
    rng = np.random.default_rng(seed)
    S = cov[np.ix_(free, free)]
    positive = mean[free] > 0
    rows = np.empty((0, free.size))
    for _ in range(100):
        d = rng.multivariate_normal(mean[free], S, size=n, method="eigh")
        d = d[np.all((d > 0) | ~positive, axis=1)]
        rows = np.vstack([rows, d])[:n]
        if rows.shape[0] == n:
            break
    else:
        raise ParameterError("covariance", "too wide", "draws with positive parameters")
    vals = np.empty((n, len(keys)))
    for i, row in enumerate(rows):
        th = mean.copy()
        th[free] = row
        r = f(th)
        vals[i] = [_as_float(r[m]) for m in keys]
    for i, m in enumerate(keys):
        v = vals[:, i]
        if not (math.isfinite(f0[m]) and np.all(np.isfinite(v))):
            out[m] = {"value": None, "ci95": None, "std": None}
            continue
        lo, hi = np.percentile(v, [2.5, 97.5])
        out[m] = {
            "value": f0[m],
            "ci95": (float(lo), float(hi)),
            "std": float(v.std(ddof=1)),
            "mean": float(v.mean()),
            "draws": n,
        }
    return out


def propagate(
    source,
    car,
    excitation=None,
    horizon: float = 10.0,
    *,
    method: str = "delta",
    n: int = 200,
    seed: int = 0,
    step: float = 0.5,
    linear: bool = True,
    road_class: str = "C",
    speed: float = 20.0,
    widen: bool = True,
) -> dict:
    """Uncertainty of the ride metrics of a car that uses an identified device.

    Parameters
    ----------
    source : FitResult or (mean, covariance, names)
        The estimates and their covariance (``FitResult.covariance`` in
        ``FitResult.parameter_order``).
    car : QuarterCar or callable
        A ``device`` or ``device-afw`` quarter car whose device's stiffness (k_h),
        damping (b_ah) and friction (F_fh) are replaced by the parameters
        (:func:`device_car`; a ``changing_ratio`` parameter sets the flywheel's), or a
        factory ``car(params: dict) -> QuarterCar`` for anything else.
    excitation, horizon
        Road and length [s] of the simulation (:func:`inerterlab.simulate.simulate_metrics`);
        ``None``: linear metrics only. Use a drop, sine or ISO 8608 road: across a
        rectangular bump some RMS values are not finite.
    method : {"delta", "monte-carlo"}
    n, seed : Monte Carlo draws and seed.
    step : float
        Delta method: central-difference step in standard errors.
    linear : bool
        Also the H2 norms and body resonance of the linearised car
        (:func:`linearised_car`, on an ISO 8608 road of ``road_class`` at ``speed``).
    widen : bool
        For a FitResult: scale each parameter's standard deviation by its interval's
        quantile / 1.96 (correlations kept), so that a parameter whose interval is a
        Student-t with few degrees of freedom (a parameter carried by one or two tests)
        passes that width on instead of the normal one. ``False`` uses the covariance
        as estimated.

    Returns
    -------
    dict
        ``{metric: {"value", "ci95", "std", "unit"}}``, metrics of
        :data:`SIMULATED_METRICS` (with an excitation) and :data:`LINEAR_METRICS`.

    Examples
    --------
    >>> import numpy as np
    >>> from inerterlab import quarter_car
    >>> out = propagate(([8100.0, 190.0], np.diag([50.0**2, 4.0**2]), ["damping", "friction"]),
    ...                 quarter_car("device"))
    >>> r = out["body_resonance_hz"]
    >>> r["ci95"][0] < r["value"] < r["ci95"][1]
    True
    """
    mean, cov, names = _source(source, widen)
    from ..systems import System

    factory = (
        car if callable(car) and not isinstance(car, System) and not hasattr(car, "suspension")
        else None
    )
    if factory is None:
        car = model_of(car)

    def make(theta):
        params = dict(zip(names, (float(x) for x in theta), strict=True))
        return factory(params) if factory is not None else device_car(car, params)

    # every draw's statistical linearisation starts from the estimate's fixed point (the
    # same fixed point to 1e-10; a third of the passes from the slope at rest)
    start = (linearised_car(make(mean), road_class=road_class, speed=speed).info["equivalents"]
             if linear else None)  # fmt: skip

    def f(theta):
        return ride_metrics(make(theta), excitation, horizon, linear=linear,
                            road_class=road_class, speed=speed, start=start)  # fmt: skip

    out = propagate_function(f, mean, cov, method=method, n=n, seed=seed, step=step)
    for k, v in out.items():
        v["unit"] = UNITS.get(k, "")
    return out
