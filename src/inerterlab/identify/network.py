"""Identification of any network's parameters from rig data, on the model core.

:func:`identify` fits the three devices of the thesis (on the same core rig, with their
own parameters and start). :func:`identify_network` fits the named parameters of any
network text (springs, dampers, inerters, the adaptive flywheel, friction, backlash, the
fluid inerter, the devices as composite elements) with the core's rig (:func:`inerterlab.systems.rig`),
driven by each record (:func:`inerterlab.excitation.drive_series`): the same system
the time simulation, the harmonic balance and the linear analysis use. The objective,
the robust loss, the reversal window and the intervals are those of :func:`identify`
(docs/guide/identification.md).

The unmeasured initial state of a network with internal nodes is a nuisance: the
network starts with its springs in equilibrium between the drive and the ground and its
internal nodes moving with the drive in the same proportion, and the free response to
a small change of each state (one extra run per state) is fitted to the residual over
the samples of the objective and added (a projection, exact for a linear network), as
:func:`identify` does for a series device's initial spring force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..elements import element_class
from ..errors import ParameterError, check_choice, check_nonnegative
from ..networks import NetworkError
from .data import RigDataSet
from .fit import (
    INTERVALS,
    LOSSES,
    REVERSAL_WINDOW,
    RTOL,
    ParameterEstimate,
    TestValidation,
    _noise_estimate,
    _prepare,
    _reversal_times,
    _robust_fit,
    _spreads,
)

__all__ = ["NetworkFitResult", "identify_network"]

def _unit(name: str) -> str:
    """Unit of a network parameter name (``k``, ``hyd.stiffness``), or ""."""
    base, _, sub = name.partition(".")
    try:
        cls = element_class(base)
    except NetworkError:  # an unknown prefix: the rig builder refuses it, naming it
        return ""
    for p in cls.PARAMETERS:
        if p.name == (sub or cls.PARAMETERS[0].name):
            return p.unit
    return ""


@dataclass(frozen=True, kw_only=True, eq=False)
class NetworkFitResult:
    """What :func:`identify_network` found: the estimates with their 95 % intervals, the
    covariance of the free parameters (in ``free`` order), every parameter of the fitted
    network, and each test's measured and predicted force."""

    network: str
    parameters: dict
    params: dict
    free: tuple
    covariance: np.ndarray
    tests: list
    cost: float
    noise_estimate: float
    f_scale: float
    nfev: int
    loss: str
    reversal_window: float
    interval_method: str
    initial_state: str = "all"
    interval_alternatives: dict = field(default_factory=dict, repr=False)

    def __getitem__(self, name: str) -> ParameterEstimate:
        return self.parameters[name]

    def with_intervals(self, interval: str) -> NetworkFitResult:
        """The same fit with the intervals of another method (``sandwich``, ``jackknife``)."""
        import dataclasses

        check_choice("interval", interval, INTERVALS)
        params, cov = self.interval_alternatives[interval]
        return dataclasses.replace(
            self, parameters=params, covariance=cov, interval_method=interval
        )

    def rig(self):
        """The core rig of the fitted network."""
        from ..systems import rig

        return rig(self.network, self.params)

    def to_dict(self) -> dict:
        """Plain numbers for JSON."""
        return {
            "network": self.network,
            "parameters": {
                n: {
                    "value": p.value,
                    "ci95": list(p.ci95),
                    "std_error": p.std_error,
                    "unit": p.unit,
                    "interval": p.interval,
                }
                for n, p in self.parameters.items()
            },
            "covariance": self.covariance.tolist(),
            "free": list(self.free),
            "cost_rms_N": self.cost,
            "noise_estimate_N": self.noise_estimate,
            "f_scale_N": self.f_scale,
            "nfev": self.nfev,
            "loss": self.loss,
            "reversal_window_s": self.reversal_window,
            "interval": self.interval_method,
            "initial_state": self.initial_state,
            "tests": [
                {"name": t.name, "purpose": t.purpose, "rms_N": t.rms, "nrmse": t.nrmse}
                for t in self.tests
            ],
        }

    def _summary(self) -> tuple[str, list[tuple[str, str]]]:
        rows = [(f"{n} [{p.unit}]" if p.unit else n, p.value_text())
                for n, p in self.parameters.items()]  # fmt: skip
        val = [t for t in self.tests if t.purpose == "validation"]
        if val:
            rms = math.sqrt(float(np.mean([t.rms**2 for t in val])))
            rows.append((f"RMS force error, {len(val)} validation tests", f"{rms:.4g} N"))
        rows.append(("RMS residual, identification tests", f"{self.cost:.4g} N"))
        rows.append(("noise estimate", f"{self.noise_estimate:.4g} N"))
        return f"identify_network: {self.network!r}, {self.loss} loss", rows

    def __repr__(self) -> str:
        title, rows = self._summary()
        w = max(len(k) for k, _ in rows)
        return "\n".join([title, *(f"  {k:<{w}}  {v}" for k, v in rows)])


#: relative singular-value cutoff of the initial-state projection
PROJECTION_RCOND = 1e-9


class _Runner:
    """Rig runs of one network on the prepared tests, with the initial-state projection."""

    def __init__(self, network, params, free, preps, initial_state="all"):
        from ..excitation import drive_series
        from ..systems import DriveRuns

        self.initial_state = initial_state
        self.network = network
        self.params = dict(params)
        self.free = list(free)
        self.preps = preps
        self.starts: dict = {}
        self.drives = {
            id(p): DriveRuns(drive_series(p.t, p.x, p.v, label=p.test.name)) for p in preps
        }

    def system(self, theta):
        from ..systems import rig

        return rig(self.network, {**self.params, **dict(zip(self.free, theta, strict=True))})

    def start(self, sys, p):
        """State at the first sample (where the runs start): springs in equilibrium
        between the drive and the ground; internal nodes moving with the drive in the
        same proportion (the spring map applied to the velocities)."""
        from ..systems.core import _initial

        x0 = _initial(sys, {}, float(p.x[0]))
        if sys.n_states:
            v_map = _initial(sys, {}, float(p.v[0]))
            for i, name in enumerate(sys.state_names):
                if name.endswith(".v"):
                    node = name[:-2]
                    x0[i] = v_map[sys.state_names.index(f"{node}.x")]
        return x0

    def predict(self, sys, p, rtol):
        """Force at the samples of ``p``, with the initial state projected out.

        The first call for a test refines its start: two projections, each restarting
        from the corrected state, so that the free responses are then taken where the
        record starts (a series damper and friction carry hundreds of newtons at the
        first sample, far beyond a linear correction of an unloaded start). The refined
        start is kept for the whole fit, so the objective stays a function of the
        parameters alone."""
        x0 = self.starts.get(id(p))
        if x0 is None:
            x0 = self.start(sys, p)
            for _ in range(2):
                _, x0 = self._project(sys, p, rtol, x0)
            self.starts[id(p)] = x0
        return self._project(sys, p, rtol, x0)[0]

    def _project(self, sys, p, rtol, x0):
        """(prediction, corrected initial state) from the start ``x0``."""
        runs = self.drives[id(p)]

        def run(x, m):
            return runs.force(sys, x, m, rtol=rtol)

        n = p.t.size
        base = run(x0, n)
        if sys.n_states == 0:
            return base, x0
        scales = np.maximum(np.asarray(sys.state_scales, dtype=float), 1e-12)
        probe = list(range(sys.n_states))
        if self.initial_state == "displacements":
            probe = [i for i, nm in enumerate(sys.state_names) if nm.endswith(".x")]
        if not probe:
            return base, x0
        H = np.zeros((n, len(probe)))
        for col, i in enumerate(probe):
            d = 1e-4 * scales[i]
            xi = x0.copy()
            xi[i] += d
            # the free response of a damped network dies out: run the probe over the
            # first eighth of the record, and over all of it if it has not
            for m in (max(2, n // 8), n):
                h = (run(xi, m) - base[:m]) / d
                H[:m, col] = h
                tail = np.abs(h[m - max(1, m // 10) :]).max()
                if m == n or tail <= 1e-6 * np.abs(h).max():
                    break
        m = p.mask
        # columns scaled to unit norm; directions the record hardly sees (a state whose
        # free response dies within a sample or two) are left at zero, not fitted to
        # round-off with a huge correction
        norm = np.linalg.norm(H[m], axis=0)
        norm[norm == 0.0] = 1.0
        coef, *_ = np.linalg.lstsq(H[m] / norm, (p.force - base)[m], rcond=PROJECTION_RCOND)
        coef = coef / norm
        x1 = x0.copy()
        x1[probe] += coef
        return base + H @ coef, x1

    def residuals(self, rtol):
        def fun(theta):
            sys = self.system(theta)
            return np.concatenate(
                [(self.predict(sys, p, rtol) - p.force)[p.mask] for p in self.preps]
            )

        return fun, None


def identify_network(
    dataset: RigDataSet,
    network: str,
    params: dict | None = None,
    *,
    free,
    loss: str = "cauchy",
    f_scale: float | None = None,
    lower: dict | None = None,
    upper: dict | None = None,
    reversal_window: float = REVERSAL_WINDOW,
    derivative_window: float = 0.02,
    detrend: str = "constant",
    rtol: float = RTOL,
    max_nfev: int = 100,
    interval: str = "sandwich",
    initial_state: str = "all",
) -> NetworkFitResult:
    """Fit the ``free`` parameters of ``network`` to the identification tests of ``dataset``.

    Parameters
    ----------
    dataset : RigDataSet
        Tests with purpose ``identification`` are fitted, ``validation`` ones predicted.
    network : str
        Network text between the rig's drive and its ground, e.g. ``"k | c | b"``,
        ``"k - (c | b)"``, ``"hyd"`` (docs/guide/core.md).
    params : dict
        Values of the network's parameters, by the names :func:`inerterlab.systems.rig`
        takes (``"k"``, ``"hyd.stiffness"``); the free ones are the starting values.
    free : sequence of str
        Names in ``params`` to fit; each must be a number.
    loss, f_scale, reversal_window, derivative_window, detrend, rtol, max_nfev, interval
        As for :func:`inerterlab.identify.identify`; the reversal window defaults to
        0.16 s, the whole spike of the rig model.
    lower, upper : dict, optional
        Bounds per free parameter (default [0, inf)).
    initial_state : {"all", "displacements"}
        Which internal states' free responses are projected out of each test's
        residual: every one (default; exact for a linear network whatever its start),
        or the internal displacements only, the internal nodes starting with the drive's
        motion (the assumption of :func:`identify` for a series device: its branch
        moves with the drive, its spring force is unknown; narrower intervals where the
        assumption holds).

    Returns
    -------
    NetworkFitResult
    """
    from ..errors import DataFileError

    check_choice("loss", loss, LOSSES)
    check_choice("interval", interval, INTERVALS)
    check_choice("initial_state", initial_state, ("all", "displacements"))
    check_nonnegative("reversal_window", reversal_window, "s")
    if not isinstance(dataset, RigDataSet) or not dataset.tests:
        raise ParameterError("dataset", dataset, "a RigDataSet with at least one test")
    params = dict(params or {})
    free = tuple(free)
    if not free:
        raise ParameterError("free", free, "at least one parameter name to fit")
    for n in free:
        if n not in params:
            raise ParameterError(
                "free", n, f"a name given in params ({', '.join(params) or 'none given'})"
            )
        v = params[n]
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise ParameterError(n, v, "a finite number (the starting value of a free parameter)")
    from ..systems import rig

    rig(network, params)  # refuses a bad network or value here, naming it
    ident = dataset.select("identification")
    if not ident:
        raise DataFileError(dataset.source or "dataset", "no test has purpose 'identification'")
    lower, upper = dict(lower or {}), dict(upper or {})
    preps = {
        id(t): _prepare(
            t, window=derivative_window, detrend=detrend, reversal_window=reversal_window
        )
        for t in dataset.tests
    }
    ip = [preps[id(t)] for t in ident]
    sigma = _noise_estimate(ident)
    adapt = f_scale is None
    if f_scale is None:
        f_scale = max(3.0 * sigma, 1e-9 * max(float(np.abs(t.force).max()) for t in ident))
    x0 = np.array([float(params[n]) for n in free])
    lb = np.array([float(lower.get(n, 0.0)) for n in free])
    ub = np.array([float(upper.get(n, np.inf)) for n in free])
    x0 = np.clip(x0, lb + 1e-12 * np.maximum(1.0, np.abs(lb)), ub)
    runner = _Runner(network, params, free, ip, initial_state)
    sol, J, f_scale, nfev = _robust_fit(
        runner.residuals, x0, lb, ub, loss=loss, f_scale=f_scale, rtol=rtol,
        max_nfev=max_nfev, adapt_scale=adapt,
    )  # fmt: skip
    sizes = [int(p.mask.sum()) for p in ip]
    spreads = _spreads(J, sol.fun, loss, f_scale, sizes, [p.mask for p in ip])
    fitted = {**params, **dict(zip(free, (float(v) for v in sol.x), strict=True))}
    by_method = {}
    for m in INTERVALS:
        sp = spreads[m]
        est = {}
        for k, n in enumerate(free):
            val, s, q = fitted[n], float(sp.se[k]), float(sp.quantile[k])
            est[n] = ParameterEstimate(
                name=n, value=val, ci95=(val - q * s, val + q * s), unit=_unit(n),
                std_error=s, interval=sp.interval[k], quantile=q,
            )  # fmt: skip
        by_method[m] = (est, np.array(sp.cov, dtype=float))
    all_runner = _Runner(
        network, fitted, (), [preps[id(t)] for t in dataset.tests], initial_state
    )
    sys = all_runner.system(())
    tests = []
    for t in dataset.tests:
        p = preps[id(t)]
        pred = all_runner.predict(sys, p, rtol)
        rev = _reversal_times(p.t, p.v)
        tests.append(
            TestValidation(
                name=t.name, purpose=t.purpose, signal=t.signal, frequency=t.frequency,
                amplitude=t.amplitude, t=t.t, measured=t.force, predicted=pred,
                reversals=rev, reversal_signs=-np.sign(np.interp(rev, p.t, p.v)),
            )  # fmt: skip
        )
    res_id = np.concatenate([tv.residual for tv in tests if tv.purpose == "identification"])
    est, cov = by_method[interval]
    return NetworkFitResult(
        network=network, parameters=est, params=fitted, free=free, covariance=cov,
        tests=tests, cost=float(np.sqrt(np.mean(res_id**2))), noise_estimate=sigma,
        f_scale=float(f_scale), nfev=int(nfev), loss=loss,
        reversal_window=float(reversal_window), interval_method=interval,
        initial_state=initial_state, interval_alternatives=by_method,
    )  # fmt: skip
