"""Least-squares identification of device parameters from rig data: :func:`identify`.

Objective (thesis (5.2), (5.3), (5.7), (5.10), (5.13)): the RMS of measured minus
predicted force over the samples of the identification tests, minimised by
``scipy.optimize.least_squares`` with bounds, fixed parameters and an optional robust
loss (``soft_l1``, ``huber``, ``cauchy``) whose scale ``f_scale`` defaults to three
times the force-sensor noise, estimated from the data as the median absolute first
difference / (0.6745 sqrt 2). The predicted force is the model core's rig driven by
the record (:class:`inerterlab.systems.DriveRuns`), for every device (a free-wheeling
flywheel, backlash and bearing drag are elements of the rig).

Methods
-------
``joint``
    All free parameters at once over all identification tests, with the full device
    model driven by the measured motion.
``thesis``
    The thesis's procedure. Hydraulic device (ch. 5.1.3): damping and friction from
    the settled plateaus of the square-velocity identification tests with (5.1),
    F = b_ah q + F_fh sgn(q), then the stiffness alone from the sinusoidal
    identification tests with (5.7). Screw and rectifier (ch. 5.2.2, 5.3): stiffness,
    damping and friction jointly over the sinusoidal identification tests ((5.10),
    (5.13)).

Spikes and robust scale: by default the samples within ``reversal_window`` (0.24 s for
the hydraulic device and the rectifier, 0.16 s for the screw, :data:`REVERSAL_WINDOWS`)
after every reversal of the measured velocity are left out (the thesis also set the
spikes aside, ch. 5.3); the robust loss handles what is left. Its scale starts at three
times the force-sensor noise and, after a first pass, is set to three times the robust
spread (1.4826 MAD) of the residuals and the fit repeated, because noise of the measured
motion reaches the residual through the model (the screw's inertance multiplies the
acceleration differentiated from the measured velocity) and a Cauchy scale far below
the residual spread biases the estimate.

Confidence intervals (95 %): sandwich covariance of the M-estimator, cov = H^-1 M H^-1,
from the Jacobian J of the residuals at the optimum (the derivative of the residuals
themselves: the Jacobian ``least_squares`` returns for a robust loss is already scaled by
the loss), with the scores psi(r) J and H = J^T diag(psi'(r)) J (psi' = 1 for the plain
loss). Two choices of the meat M (``interval``):

``sandwich``
    M = sum over tests of J_g^T Sigma_g J_g with Sigma_g the covariance of psi(r) within
    test g under an autoregressive model: the autocorrelation of psi(r) pooled over the
    tests (lags in samples of the record), an AR(p) fitted to it by Yule-Walker with
    the order from the AIC, and each test's own variance; normal quantile. Tests are
    taken as independent and the noise within a test as stationary. A lag-window
    (Newey-West) meat is not used: the screw's residual is dominated by motion noise
    differentiated twice, whose power sits at high frequencies; a Bartlett window
    leaks it into the low frequencies the parameters live at (intervals 2-2.5 x too
    wide) and an unbiased flat-top window estimates it so noisily that the intervals
    undercover. In the coverage study at 500 Hz with each device's default reversal
    window (docs/guide/identification.md, "Calibrated intervals") it is calibrated for
    every parameter of the three devices (coverage 94-96.5 %, mean error within 0.12
    standard errors, width ratios 0.97-1.11), so it is the default.
``jackknife``
    With at least eight identification tests, the jackknife over tests (CR3) of the
    one-step estimate: the spread of theta_(-g) - theta = -(H - H_g)^-1 s_g, s_g the
    summed score of test g, scaled (G-1)/G, with Student's t quantile at the
    Satterthwaite degrees of freedom of that jackknife (Bell and McCaffrey 2002, Imbens
    and Kolesar 2016), per parameter. It assumes only that tests are independent, so a
    model mismatch that persists within a test widens it, but when one or two tests
    carry a parameter the degrees of freedom fall near 1 and the interval is several
    times wider than the scatter of the estimates (up to 9 x in the study). With fewer
    tests, a Newey-West sandwich within tests and the normal quantile.

The fit keeps both (:meth:`FitResult.with_intervals`). Optionally also a percentile
interval from a bootstrap over the identification tests (tests drawn with replacement
and refitted). Each parameter states which interval it carries
(``ParameterEstimate.interval``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import t as student_t

from ..devices import PARAMETER_UNITS, motion_from_samples
from ..errors import (
    ConvergenceError,
    DataFileError,
    ParameterError,
    check_choice,
    check_nonnegative,
    check_positive,
)
from .data import RigDataSet, RigTest
from .filters import complete_motion

__all__ = ["identify", "FitResult", "ParameterEstimate", "TestValidation", "predict_test"]

PARAMETERS = ("stiffness", "damping", "friction")
LOSSES = ("linear", "soft_l1", "huber", "cauchy")
# time [s] left out after each velocity reversal: at least the whole simulated spike
# (8 widths of 20 ms, simulate_rig); 0.1 s left its tail in and biased the damping
REVERSAL_WINDOW = 0.16
#: default reversal window [s] per device model, chosen by the coverage study at 500 Hz
#: (docs/decisions.md, "The reversal window per device"): 0.24 s calibrates the
#: hydraulic device's and the rectifier's damping, and makes the screw's worse
REVERSAL_WINDOWS = {"HydraulicDevice": 0.24, "RectifierDevice": 0.24, "ScrewDevice": 0.16}


def default_reversal_window(device) -> float:
    """The default reversal window [s] of ``device``'s model (REVERSAL_WINDOW for a model
    the coverage study has not seen)."""
    return REVERSAL_WINDOWS.get(type(device).__name__, REVERSAL_WINDOW)


# tolerance of the model integration inside the fit: at 1e-8 the objective is jagged on
# the scale of the statistical precision (the rectifier's fit then stopped up to 0.8
# standard errors away depending on where it started; docs/decisions.md)
RTOL = 1e-10
PRE_RTOL = 1e-8  # the plain least-squares start of a robust fit


@dataclass(frozen=True, kw_only=True)
class ParameterEstimate:
    """One identified parameter: value, 95 % interval(s) and unit."""

    name: str
    value: float
    ci95: tuple[float, float]
    unit: str
    fixed: bool = False
    std_error: float = 0.0
    ci95_bootstrap: tuple[float, float] | None = None
    interval: str = ""
    quantile: float = 0.0

    def __str__(self) -> str:
        """Value, unit and interval with enough digits to tell them apart."""
        return self._text(f" {self.unit}" if self.unit else "")

    def value_text(self) -> str:
        """Value and interval without the unit (for a table whose row names it)."""
        return self._text("")

    def _text(self, unit: str) -> str:
        from .._display import distinct

        v, lo, hi = distinct([self.value, *self.ci95], min_digits=6)
        return f"{v}{unit} (95 %: {lo} .. {hi})" + (" fixed" if self.fixed else "")


@dataclass(frozen=True, kw_only=True, eq=False)
class TestValidation:
    """Measured and predicted force of one test, with the times [s] of the reversals of
    the measured velocity and the sign of the velocity after each."""

    name: str
    purpose: str
    signal: str
    frequency: float
    amplitude: float
    t: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    reversals: np.ndarray = field(default_factory=lambda: np.empty(0))
    reversal_signs: np.ndarray = field(default_factory=lambda: np.empty(0))

    __test__ = False

    @property
    def residual(self) -> np.ndarray:
        return self.measured - self.predicted

    @property
    def rms(self) -> float:
        """RMS force error [N]."""
        return float(np.sqrt(np.mean(self.residual**2)))

    @property
    def nrmse(self) -> float:
        """RMS error / (max - min of the measured force) [-]."""
        span = float(np.ptp(self.measured))
        return self.rms / span if span > 0 else math.nan


@dataclass(frozen=True, kw_only=True, eq=False)
class FitResult:
    """Result of :func:`identify`.

    Attributes
    ----------
    parameters : dict of ParameterEstimate
    device : the device with the identified parameters
    method, loss : str
    tests : list of TestValidation
        Every test (identification and validation) with the fitted model's force.
    cost : float
        RMS force error over the identification samples [N].
    stages : list of str
        What each stage fitted (the thesis procedure has two for the hydraulic device).
    bootstrap : ndarray or None
        Parameter values of the bootstrap refits (rows) in ``parameters`` order.
    covariance : ndarray
        Covariance [unit_i unit_j] of the estimates in ``parameter_order``, from the
        same sandwich or jackknife the intervals use: its diagonal is ``std_error``
        squared and each ``ci95`` is value +/- ``quantile`` x sqrt(diagonal). Rows and
        columns of fixed parameters are zero. The thesis method fits the hydraulic
        device in two stages on disjoint tests (square-velocity plateaus, then sines)
        and the covariance between the stages is taken as zero; the stiffness stage
        treats the plateau estimates as known, as its interval does.
    parameter_order : tuple of str
        Row and column order of ``covariance`` (stiffness, damping, friction).
    interval_method : str
        Which intervals ``parameters`` and ``covariance`` carry (``sandwich`` or
        ``jackknife``, see :func:`identify`).
    interval_alternatives : dict
        ``(parameters, covariance)`` of every interval method, computed from the same
        fit; :meth:`with_intervals` switches between them.
    """

    parameters: dict
    device: object
    method: str
    loss: str
    tests: list
    cost: float
    noise_estimate: float
    stages: list = field(default_factory=list)
    bootstrap: np.ndarray | None = None
    nfev: int = 0
    f_scale: float = 0.0
    reversal_window: float = 0.0
    covariance: np.ndarray | None = None
    parameter_order: tuple = PARAMETERS
    interval_method: str = "sandwich"
    interval_alternatives: dict = field(default_factory=dict, repr=False)

    def with_intervals(self, interval: str) -> FitResult:
        """The same fit with the intervals and covariance of another method
        (``"sandwich"`` or ``"jackknife"``, see :func:`identify`); the estimates, the
        validation and everything else are shared, nothing is refitted."""
        check_choice("interval", interval, tuple(self.interval_alternatives) or INTERVALS)
        params, cov = self.interval_alternatives[interval]
        return dataclasses.replace(
            self, parameters=params, covariance=cov, interval_method=interval
        )

    def correlation(self) -> np.ndarray:
        """Correlation matrix of the free parameters' estimates (``parameter_order``;
        rows and columns of fixed parameters are zero)."""
        cov = np.asarray(self.covariance, dtype=float)
        s = np.sqrt(np.diag(cov))
        ok = s > 0
        out = np.zeros_like(cov)
        out[np.ix_(ok, ok)] = cov[np.ix_(ok, ok)] / np.outer(s[ok], s[ok])
        return out

    def _summary(self) -> tuple[str, list[tuple[str, str]]]:
        from .._display import fmt

        rows = []
        for name, p in self.parameters.items():
            rows.append((f"{name} [{p.unit}]", p.value_text()))
        val = self.validation()
        rows.append(
            (
                f"RMS force error, {val['tests']} {val['purpose']} tests",
                fmt(val["rms_force_error"], "N"),
            )
        )
        rows.append(("NRMSE", f"{val['nrmse']:.4%}"))
        rows.append(("noise estimate", fmt(self.noise_estimate, "N")))
        return f"identification, {self.method} method, {self.loss} loss", rows

    def __repr__(self) -> str:
        from .._display import distinct

        parts = []
        for name, p in self.parameters.items():
            v, lo, hi = distinct([p.value, *p.ci95])
            parts.append(f"{name}={v} {p.unit} [{lo}, {hi}]")
        rms = self.validation()["rms_force_error"]
        return (
            f"<FitResult {self.method}/{self.loss}: {', '.join(parts)}; validation RMS {rms:.4g} N>"
        )

    def _repr_html_(self) -> str:
        from .._display import html_table

        return html_table(*self._summary())

    def to_xarray(self):
        """Parameters (value, interval, unit) and per-test errors as an xarray Dataset."""
        import xarray as xr

        names = list(self.parameters)
        ps = list(self.parameters.values())
        vf = self.validation_frame()
        ds = xr.Dataset(
            {
                "value": ("parameter", [p.value for p in ps]),
                "ci95_low": ("parameter", [p.ci95[0] for p in ps]),
                "ci95_high": ("parameter", [p.ci95[1] for p in ps]),
                "std_error": ("parameter", [p.std_error for p in ps]),
                "fixed": ("parameter", [p.fixed for p in ps]),
                "units": ("parameter", [p.unit for p in ps]),
                "rms_force_error": ("test", vf["rms_force_error"].to_numpy(), {"units": "N"}),
                "nrmse": ("test", vf["nrmse"].to_numpy(), {"units": "1"}),
                "purpose": ("test", vf["purpose"].to_numpy().astype(str)),
            },
            coords={"parameter": names, "test": vf["test"].to_numpy().astype(str)},
        )
        ds.attrs.update(method=self.method, loss=self.loss, noise_estimate_N=self.noise_estimate)
        return ds

    def validation(self) -> dict:
        """Pooled RMS [N] and NRMSE of the validation tests (identification if none)."""
        sel = [t for t in self.tests if t.purpose == "validation"] or self.tests
        res = np.concatenate([t.residual for t in sel])
        meas = np.concatenate([t.measured for t in sel])
        rms = float(np.sqrt(np.mean(res**2)))
        return {
            "rms_force_error": rms,
            "nrmse": rms / float(np.ptp(meas)),
            "tests": len(sel),
            "purpose": sel[0].purpose,
        }

    def to_dict(self) -> dict:
        """Plain dict in the layout of ``inerterlab identify --json``."""
        params = {}
        for name, p in self.parameters.items():
            d = {
                "value": p.value,
                "ci95": list(p.ci95),
                "unit": p.unit,
                "fixed": p.fixed,
                "interval": p.interval,
            }
            if p.ci95_bootstrap is not None:
                d["ci95_bootstrap"] = list(p.ci95_bootstrap)
            params[name] = d
        return {
            "parameters": params,
            "validation": self.validation(),
            "method": self.method,
            "loss": self.loss,
            "rms_identification": self.cost,
            "noise_estimate": self.noise_estimate,
            "robust_scale": self.f_scale,
            "reversal_window": self.reversal_window,
            "interval_method": self.interval_method,
            "covariance": None
            if self.covariance is None
            else {
                "parameters": list(self.parameter_order),
                "matrix": np.asarray(self.covariance, dtype=float).tolist(),
            },
        }

    def to_pandas(self):
        """Parameter table (one row per parameter)."""
        import pandas as pd

        rows = []
        for p in self.parameters.values():
            row = {
                "parameter": p.name,
                "value": p.value,
                "ci95_low": p.ci95[0],
                "ci95_high": p.ci95[1],
                "unit": p.unit,
                "fixed": p.fixed,
            }
            if p.ci95_bootstrap is not None:
                row["bootstrap_low"], row["bootstrap_high"] = p.ci95_bootstrap
            rows.append(row)
        return pd.DataFrame(rows)

    def validation_frame(self):
        """RMS and NRMSE per test."""
        import pandas as pd

        return pd.DataFrame(
            [
                {
                    "test": t.name,
                    "purpose": t.purpose,
                    "signal": t.signal,
                    "frequency_hz": t.frequency,
                    "amplitude_m": t.amplitude,
                    "rms_force_error": t.rms,
                    "nrmse": t.nrmse,
                }
                for t in self.tests
            ]
        )

    def reversal_profile(self, *, bin_width: float = 0.01, horizon: float = 0.3):
        """Mean residual after a velocity reversal, to check the reversal window.

        For every reversal of the identification tests, the residual (measured minus
        model force) times the sign of the new velocity, averaged in bins of
        ``bin_width`` [s] of the time since the reversal up to ``horizon`` [s] (or the
        next reversal); then the mean over reversals of each bin and its standard error
        (spread of the per-reversal means / sqrt(count)). A spike shows as a mean many
        standard errors from zero; the reversal window should end where the means stop
        being significant. Samples inside the window are included (they were left out
        of the fit, not of the prediction).

        Returns
        -------
        pandas.DataFrame
            ``time_since_reversal_s`` (bin start), ``mean_residual_n``,
            ``std_error_n``, ``reversals``.
        """
        import pandas as pd

        check_positive("bin_width", bin_width, "s")
        check_positive("horizon", horizon, "s")
        nbin = max(1, int(math.ceil(horizon / bin_width - 1e-9)))
        rows = [[] for _ in range(nbin)]
        for tv in self.tests:
            if tv.purpose != "identification":
                continue
            if tv.reversals.size == 0:  # a record shorter than half a period
                continue
            res = tv.residual
            ends = np.append(tv.reversals[1:], np.inf)
            for tr, sg, end in zip(tv.reversals, tv.reversal_signs, ends, strict=True):
                lo, hi = np.searchsorted(tv.t, [tr, min(tr + horizon, end)])
                tau = tv.t[lo:hi] - tr
                k = np.minimum((tau / bin_width).astype(int), nbin - 1)
                for b in np.unique(k):
                    rows[b].append(sg * float(res[lo:hi][k == b].mean()))
        out = []
        for b, vals in enumerate(rows):
            v = np.asarray(vals)
            n = v.size
            out.append(
                {
                    "time_since_reversal_s": b * bin_width,
                    "mean_residual_n": float(v.mean()) if n else math.nan,
                    "std_error_n": float(v.std(ddof=1) / math.sqrt(n)) if n > 1 else math.nan,
                    "reversals": n,
                }
            )
        return pd.DataFrame(out)

    def plot(self, test: str | int | None = None):
        """Measured vs predicted force and the residual of one test (default: the first
        validation test)."""
        from ..plotting import _plt

        plt = _plt()
        if test is None:
            sel = [t for t in self.tests if t.purpose == "validation"] or self.tests
            tv = sel[0]
        elif isinstance(test, int):
            tv = self.tests[test]
        else:
            tv = next(t for t in self.tests if t.name == test)
        fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
        a1.plot(tv.t, tv.measured, lw=0.8, label="measured")
        a1.plot(tv.t, tv.predicted, lw=1.0, ls="--", label="model")
        a1.set_ylabel("force [N]")
        a1.legend(loc="upper right")
        a1.set_title(f"{tv.name} ({tv.purpose}): RMS {tv.rms:.4g} N, NRMSE {tv.nrmse:.3%}")
        a2.plot(tv.t, tv.residual, lw=0.8, c="C3")
        a2.set_xlabel("time [s]")
        a2.set_ylabel("residual [N]")
        fig.tight_layout()
        return fig


def _noise_estimate(tests) -> float:
    """Force-sensor noise [N]: median over tests of the MAD of second differences / sqrt(6)."""
    est = []
    for t in tests:
        d = np.diff(t.force, 2)
        est.append(np.median(np.abs(d - np.median(d))) / 0.6745 / math.sqrt(6.0))
    return float(np.median(est))


@dataclass(frozen=True)
class _Prepared:
    test: RigTest
    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    force: np.ndarray
    motion: object
    mask: np.ndarray  # samples used in the objective
    runs: object = None  # the record as a drive of the model core's rig (DriveRuns)


def _reversal_times(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Times [s] of the last sample before each change of sign of the velocity.

    Samples with v = 0 exactly are skipped, so a reversal that falls on a sample (the
    noise-free square velocity crosses zero on the grid) is still found.
    """
    nz = np.nonzero(v != 0.0)[0]
    s = np.sign(v[nz])
    return t[nz[:-1][s[1:] != s[:-1]]]


def _prepare(test: RigTest, *, window: float, detrend: str, reversal_window: float) -> _Prepared:
    x, v = complete_motion(test, window=window, detrend=detrend)
    mask = np.ones(test.t.size, dtype=bool)
    if reversal_window > 0:
        for tr in _reversal_times(test.t, v):
            mask &= ~((test.t >= tr) & (test.t < tr + reversal_window))
    from ..excitation import drive_series
    from ..systems import DriveRuns

    motion = motion_from_samples(test.t, x, v)
    runs = DriveRuns(drive_series(test.t, x, v, label=test.name))
    return _Prepared(test, test.t, x, v, test.force, motion, mask, runs)


def _core_state(device, sys, prep: _Prepared, initial_force: float | None) -> np.ndarray:
    """The rig's state at the first sample: the device moving steadily with the record
    (:func:`inerterlab.devices.force.initial_state`), its series spring carrying
    ``initial_force`` where given."""
    from ..devices.force import initial_state

    x0, v0 = float(prep.x[0]), float(prep.v[0])
    return initial_state(device, sys, x0, v0, 0.0, initial_force if device.series else None)


def _model_force(device, prep: _Prepared, *, rtol: float, m: int | None = None,
                 initial_force: float | None = None) -> np.ndarray:  # fmt: skip
    """Force [N] of the device model at the first ``m`` samples of ``prep``, on the model
    core's rig (:func:`inerterlab.devices.force.device_rig`)."""
    from ..devices.force import device_rig

    n = prep.t.size if m is None else m
    sys = device_rig(device)
    return prep.runs.force(sys, _core_state(device, sys, prep, initial_force), n, rtol=rtol)


def _initial_force_guess(prep: _Prepared) -> float:
    n0 = min(9, prep.t.size)
    tt = prep.t[:n0] - prep.t[0]
    return float(np.polyval(np.polyfit(tt, prep.force[:n0], min(2, n0 - 1)), 0.0))


def _is_affine(device) -> bool:
    """True when the force is affine in (stiffness, damping, friction): the parallel
    screw without backlash, F = k x + c v + f tanh(v / v_eps) + inertial force (3.38)."""
    return (not device.series) and device.backlash == 0.0


def _affine_terms(device, prep: _Prepared):
    """(Phi, F_inertial) of an affine device: F = Phi @ (k, c, f) + F_inertial at the samples.

    Phi's columns are x, v and tanh(v / v_eps) at the samples, which the sampled motion
    passes through exactly; the inertial force (any law) depends on the motion only and
    is read off one model run.
    """
    phi = np.column_stack([prep.x, prep.v, np.tanh(prep.v / device.friction_velocity)])
    theta = np.array([getattr(device, n) for n in PARAMETERS], dtype=float)
    base = _model_force(device, prep, rtol=1e-8)
    return phi, base - phi @ theta


def _transient_horizon(device) -> float:
    """Time [s] after which a spring-branch transient has decayed by e^-12: twelve
    decay times 2 m_e,max / b of the series branch (friction only adds damping)."""
    m = device.transmission.ratio**2 * device.flywheel.inertia_max
    return 12.0 * 2.0 * m / max(device.damping, 1e-9 * m)


def predict_test(device, prep: _Prepared, *, rtol: float = RTOL) -> np.ndarray:
    """Model force [N] at the samples of a prepared test.

    The initial state of a series device (the force its spring carries at the first
    sample) is not measured. It is estimated from the record itself: the model is run
    from the measured force at t0 (quadratic fit through the first 9 samples) and from
    that force plus a probe; the difference is the free transient h(t) of the spring
    branch, and the multiple of h that best fits the measured force over the samples
    used in the objective is added (a projection of the nuisance parameter, which keeps
    a wrong start from ringing through the fit). The probe run covers only the time in
    which the transient decays (:func:`_transient_horizon`), or the whole record if it
    has not died out by then.
    """
    f0 = _initial_force_guess(prep)
    base = _model_force(device, prep, rtol=rtol, initial_force=f0)
    if not device.series:
        return base
    probe = max(1.0, 1e-3 * float(np.abs(prep.force).max()))
    n = int(np.searchsorted(prep.t, prep.t[0] + _transient_horizon(device))) + 1
    h = np.zeros_like(base)
    for m in (min(n, prep.t.size), prep.t.size):
        moved = _model_force(device, prep, rtol=rtol, m=m, initial_force=f0 + probe)
        h[:m] = (moved - base[:m]) / probe
        tail = np.abs(h[m - max(1, m // 10) : m]).max()
        if m == prep.t.size or tail <= 1e-6 * np.abs(h[:m]).max():
            break
    m = prep.mask
    hh = float(h[m] @ h[m])
    if hh <= 0:
        return base
    delta = float(h[m] @ (prep.force[m] - base[m])) / hh
    return base + delta * h


#: residual vectors a fit keeps for points it may ask for again
_SEEN = 8


def _residuals(device, names, preps, rtol, affine=None):
    """Residual function (model - measured over the masked samples) and its Jacobian
    (exact for an affine device, else None: finite differences)."""
    if affine is not None:
        cols = [PARAMETERS.index(n) for n in names]
        phi = np.concatenate([affine[id(p)][0][p.mask] for p in preps])
        rest = np.concatenate([(affine[id(p)][1] - p.force)[p.mask] for p in preps])
        theta = np.array([getattr(device, n) for n in PARAMETERS], dtype=float)
        keep = [j for j in range(len(PARAMETERS)) if j not in cols]
        rest = rest + phi[:, keep] @ theta[keep]
        jac_free = np.ascontiguousarray(phi[:, cols])

        def fun_affine(th):
            return jac_free @ th + rest

        return fun_affine, lambda th: jac_free

    # the solver, the robust restarts and the intervals ask again for points already
    # computed (about one call in ten on a campaign): the last few are kept
    seen: dict = {}

    def fun(theta):
        key = np.asarray(theta, dtype=float).tobytes()
        r = seen.get(key)
        if r is None:
            dev = dataclasses.replace(device, **dict(zip(names, theta, strict=True)))
            r = np.concatenate(
                [(predict_test(dev, p, rtol=rtol) - p.force)[p.mask] for p in preps]
            )
            if len(seen) >= _SEEN:
                seen.pop(next(iter(seen)))
            seen[key] = r
        return r.copy()

    return fun, None


def _robust_weights(r, loss, f_scale):
    """w = psi(r) / r of the loss: the score of a sample is w r J."""
    z = (r / f_scale) ** 2
    if loss == "linear":
        return np.ones_like(r)
    if loss == "soft_l1":
        return 1.0 / np.sqrt(1.0 + z)
    if loss == "huber":
        return np.where(z <= 1.0, 1.0, 1.0 / np.sqrt(np.maximum(z, 1e-300)))
    return 1.0 / (1.0 + z)  # cauchy


def _robust_slopes(r, loss, f_scale):
    """psi'(r) of the loss, the weight of a sample in the Hessian of the M-estimator
    (Huber 1967): cauchy (1 - z) / (1 + z)^2, soft_l1 (1 + z)^-3/2, huber 1 inside the
    scale and 0 beyond, z = (r / f_scale)^2."""
    z = (r / f_scale) ** 2
    if loss == "linear":
        return np.ones_like(r)
    if loss == "soft_l1":
        return (1.0 + z) ** -1.5
    if loss == "huber":
        return np.where(z <= 1.0, 1.0, 0.0)
    return (1.0 - z) / (1.0 + z) ** 2  # cauchy


def _bandwidth(u: np.ndarray) -> int:
    """First lag at which the autocorrelation of ``u`` falls below 0.1 (at most n/4)."""
    n = u.size
    if n < 8:
        return 0
    u = u - u.mean()
    f = np.fft.rfft(u, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n]
    if acf[0] <= 0:
        return 0
    acf /= acf[0]
    below = np.nonzero(acf[1 : n // 4] < 0.1)[0]
    return int(below[0]) if below.size else n // 4


MIN_CLUSTERS = 8  # tests needed for the cluster-robust interval
INTERVALS = ("sandwich", "jackknife")  # interval methods of identify()


@dataclass(frozen=True)
class _Spread:
    """Standard errors, the 97.5 % quantiles that turn them into 95 % intervals, and the
    name of the estimator, one per parameter."""

    se: np.ndarray
    quantile: np.ndarray
    interval: tuple
    cov: np.ndarray


def _satterthwaite_dof(B, Hg, Ng, H, N) -> np.ndarray:
    """Degrees of freedom of the jackknife variance of each parameter (Bell and
    McCaffrey 2002; Imbens and Kolesar 2016): v = (tr S)^2 / tr(S^2), S the G x G
    covariance of the centred leave-one-test-out deltas under a working model of
    independent scores of equal variance.

    With u the sample scores psi(r) and the one-step fit, the fitted scores are
    (I - D J H^-1 J^T) u (D = diag psi'), so delta_g = B_g J_g^T [(I - D J H^-1 J^T) u]_g
    with B_g = (H - H_g)^-1, and Cov(delta . e_k) follows from the per-test matrices
    H_g = J_g^T D_g J_g and N_g = J_g^T J_g alone. When one or two tests carry a
    parameter, v falls towards 1, which is what the spread of the jackknife then is.
    """
    G = len(B)
    Hi = np.linalg.pinv(H)
    P = np.eye(G) - 1.0 / G
    dof = np.empty(H.shape[0])
    for k in range(H.shape[0]):
        b = [Bg[:, k] for Bg in B]
        X = np.array([h @ bk for h, bk in zip(Hg, b, strict=True)])
        Y = np.array([n @ bk for n, bk in zip(Ng, b, strict=True)])
        C = np.diag([bk @ n @ bk for n, bk in zip(Ng, b, strict=True)])
        C = C - X @ Hi @ Y.T - Y @ Hi @ X.T + X @ Hi @ N @ Hi @ X.T
        S = P @ C @ P
        tr2 = float(np.trace(S @ S))
        dof[k] = float(np.trace(S)) ** 2 / tr2 if tr2 > 0 else G - 1.0
    return np.clip(dof, 1.0, G - 1.0)


def _sandwich(J, r, loss, f_scale, sizes=None, interval="sandwich", masks=None) -> _Spread:
    """Robust sandwich covariance of the M-estimator from the raw Jacobian ``J`` of the
    residuals ``r``: scores psi(r) J, Hessian H = J^T diag(psi'(r)) J.

    ``J`` must be the derivative of the residuals themselves, not the Jacobian that
    ``scipy.optimize.least_squares`` returns for a robust loss (that one is already
    scaled by sqrt(psi')).

    ``interval="sandwich"``: H^-1 M H^-1 with M the
    Newey-West (Bartlett) sum of the scores over lags within each test (``sizes``:
    samples per test), the bandwidth where the residual autocorrelation dies out, and
    the normal quantile; without ``sizes``, the plain sandwich.
    ``interval="jackknife"``: with at least ``MIN_CLUSTERS`` tests the jackknife over
    tests (CR3) of the one-step estimate, see the module docstring, with a Student-t
    quantile whose degrees of freedom follow from the information each test carries
    (:func:`_satterthwaite_dof`); with fewer tests the Newey-West sandwich above.
    """
    check_choice("interval", interval, INTERVALS)
    w = _robust_weights(r, loss, f_scale)
    d = _robust_slopes(r, loss, f_scale)
    H = J.T @ (d[:, None] * J)
    G = (w * r)[:, None] * J
    try:
        Hi = np.linalg.inv(H)
    except np.linalg.LinAlgError:
        Hi = np.linalg.pinv(H)
    p = J.shape[1]
    bounds = np.cumsum([0, *sizes]) if sizes is not None else None
    groups = 0 if sizes is None else sum(1 for n in sizes if n > 0)
    if interval == "jackknife" and groups >= MIN_CLUSTERS:
        # CR3: the jackknife over tests of the one-step estimate, theta_(-g) - theta =
        # -(H - H_g)^-1 s_g. Unlike the plain cluster sum it stays honest when a few
        # tests carry most of the information about a parameter (the rectifier's
        # stiffness sits in its few 2 Hz tests), because leaving such a test out moves
        # the estimate by as much as that test's share of the information; the
        # Satterthwaite degrees of freedom then widen the quantile
        dJ = d[:, None] * J
        deltas, Bs, Hs, Ns = [], [], [], []
        for i, j in zip(bounds[:-1], bounds[1:], strict=True):
            if j > i:
                Hg = J[i:j].T @ dJ[i:j]
                B = np.linalg.pinv(H - Hg)
                deltas.append(B @ G[i:j].sum(axis=0))
                Bs.append(B)
                Hs.append(Hg)
                Ns.append(J[i:j].T @ J[i:j])
        D = np.array(deltas)
        D -= D.mean(axis=0)
        cov = D.T @ D * (groups - 1.0) / groups
        dof = _satterthwaite_dof(Bs, Hs, Ns, H, J.T @ J)
        q = student_t.ppf(0.975, dof)
        how = tuple(
            f"jackknife (CR3) sandwich over {groups} tests, t({v:.1f}) (Satterthwaite)" for v in dof
        )
        return _Spread(np.sqrt(np.maximum(np.diag(cov), 0.0)), np.asarray(q), how, cov)
    if interval == "sandwich" and sizes is not None:
        M, order = _ar_meat(J, w * r, bounds, masks)
        how = f"sandwich, AR({order}) noise within tests"
    else:
        M = G.T @ G
        if sizes is not None:
            for i, j in zip(bounds[:-1], bounds[1:], strict=True):
                g = G[i:j]
                L = _bandwidth((w * r)[i:j])
                for lag in range(1, L + 1):
                    c = g[lag:].T @ g[:-lag]
                    M += (1.0 - lag / (L + 1.0)) * (c + c.T)
            how = "Newey-West sandwich within tests"
        else:
            how = "sandwich"
    cov = Hi @ M @ Hi
    q = np.full(p, 1.959963984540054)
    return _Spread(np.sqrt(np.maximum(np.diag(cov), 0.0)), q, (how,) * p, cov)


def _correlate(a, b):
    """sum_i a[i] b[i + k] for k = 0..n-1 (a 1-D, b 1-D or the same length), by FFT."""
    n = a.shape[0]
    return np.fft.irfft(np.conj(np.fft.rfft(a, 2 * n)) * np.fft.rfft(b, 2 * n), 2 * n)[:n]


def _pooled_autocorrelation(u, bounds, masks, kmax):
    """Autocorrelation of ``u`` at lags 0..kmax pooled over the tests (lags counted in
    samples of the record: a pair straddling left-out samples has its true lag), the
    variance of ``u`` per test, and the sample positions of each test."""
    num = np.zeros(kmax + 1)
    cnt = np.zeros(kmax + 1)
    pos_all, var = [], []
    for g, (i, j) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
        pos = np.nonzero(masks[g])[0] if masks is not None else np.arange(j - i)
        pos_all.append(pos)
        if j <= i:
            var.append(0.0)
            continue
        n = int(pos[-1]) + 1
        uf = np.zeros(n)
        on = np.zeros(n)
        uf[pos] = u[i:j]
        on[pos] = 1.0
        var.append(float(u[i:j] @ u[i:j]) / (j - i))
        m = min(kmax, n - 1) + 1
        num[:m] += _correlate(uf, uf)[:m]
        cnt[:m] += _correlate(on, on)[:m]
    gam = np.where(cnt > 0, num / np.maximum(cnt, 1.0), 0.0)
    rho = gam / gam[0] if gam[0] > 0 else np.eye(1, kmax + 1)[0]
    return rho, int(cnt[0]), np.array(var), pos_all


def _ar_autocorrelation(rho, n, length, pmax):
    """Autocorrelation at lags 0..length-1 of the autoregressive model fitted to the
    sample autocorrelation ``rho`` (Yule-Walker by the Durbin-Levinson recursion, order
    by the AIC up to ``pmax``; the model matches ``rho`` up to its order and continues
    it by its recursion beyond). Returns it and the order."""
    pmax = max(0, min(pmax, rho.size - 1))
    phi = np.zeros(0)
    best = (0.0, 0, phi)  # AIC of order 0 relative: n log(1) = 0
    v = 1.0
    for k in range(1, pmax + 1):
        a = (rho[k] - phi @ rho[k - 1 : 0 : -1]) / v if phi.size else rho[k] / v
        if not abs(a) < 1.0:
            break
        phi = np.append(phi - a * phi[::-1], a)
        v *= 1.0 - a * a
        aic = n * math.log(v) + 2.0 * k
        if aic < best[0]:
            best = (aic, k, phi.copy())
    _, p, phi = best
    out = np.zeros(length)
    out[: min(length, p + 1)] = rho[: min(length, p + 1)]
    for k in range(p + 1, length):
        out[k] = phi @ out[k - 1 : k - p - 1 : -1] if p else 0.0
    return out, p


def _ar_meat(J, u, bounds, masks=None, pmax=40):
    """Meat of the sandwich under an autoregressive model of the scores' noise:
    M = sum over tests g of J_g^T Sigma_g J_g, Sigma_g[i, j] = s_g^2 rho(|t_i - t_j|)
    with s_g^2 the variance of psi(r) in test g and rho the autocorrelation of the
    AR model fitted to psi(r) pooled over the tests (:func:`_ar_autocorrelation`),
    lags counted in samples of the record.

    A lag-window (Newey-West, flat-top) estimate of the long-run variance leaks the
    power of a residual at high frequencies into the low frequencies the parameters
    live at; when that power dominates (motion noise differentiated twice through the
    screw's inertance: residual spread ~40 N against 5 N force noise) the Bartlett
    weights overstated the variance 5-fold and a flat-top window, unbiased, gave a
    variance estimate so noisy that 95 % intervals covered ~80 %. The autoregressive
    model estimates the spectrum at low frequencies from the pooled autocorrelations
    with few parameters (Berk 1974; den Haan and Levin 1997). Sigma_g is positive
    definite (a Yule-Walker model is stationary), so M is positive semi-definite.
    """
    p = J.shape[1]
    sizes = np.diff(bounds)
    nmax = 1
    for g in range(len(sizes)):
        if sizes[g] > 0:
            last = np.nonzero(masks[g])[0][-1] if masks is not None else sizes[g] - 1
            nmax = max(nmax, int(last) + 1)
    kmax = max(1, min(nmax - 1, 4 * pmax))
    rho, n, var, pos_all = _pooled_autocorrelation(u, bounds, masks, kmax)
    acf, order = _ar_autocorrelation(rho, n, nmax, min(pmax, max(1, n // 50)))
    M = np.zeros((p, p))
    for g, (i, j) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
        if j <= i:
            continue
        pos = pos_all[g]
        n_g = int(pos[-1]) + 1
        Jf = np.zeros((n_g, p))
        Jf[pos] = J[i:j]
        F = np.fft.rfft(Jf, 2 * n_g, axis=0)
        w = acf[:n_g].copy()
        w[0] *= 0.5  # lag 0 once: it is counted from both sides below
        Mg = np.empty((p, p))
        for a in range(p):
            for b in range(a, p):
                c = np.fft.irfft(np.conj(F[:, a]) * F[:, b], 2 * n_g)
                # sum over lags k of acf(|k|) sum_i J_a[i] J_b[i + k], k = -(n-1)..n-1
                Mg[a, b] = Mg[b, a] = w @ c[:n_g] + w @ np.r_[c[0], c[:n_g:-1]]
        M += var[g] * Mg
    return 0.5 * (M + M.T), order


def _spreads(J, r, loss, f_scale, sizes, masks=None) -> dict:
    """The spread of every interval method (cheap next to the fit), by method name."""
    return {m: _sandwich(J, r, loss, f_scale, sizes, interval=m, masks=masks) for m in INTERVALS}


def _raw_jacobian(fun, x, f0, lb, ub, jac=None) -> np.ndarray:
    """Jacobian of the residuals at ``x``: exact when ``jac`` is given, else forward
    differences with the step of the fit (1e-3 relative), stepping inwards at a bound."""
    if jac is not None:
        return np.asarray(jac(x), dtype=float)
    cols = []
    for k in range(x.size):
        h = 1e-3 * max(1.0, abs(x[k]))
        if x[k] + h > ub[k]:
            h = -h
        e = x.copy()
        e[k] = min(max(x[k] + h, lb[k]), ub[k])
        cols.append((fun(e) - f0) / (e[k] - x[k]))
    return np.column_stack(cols)


def _residual_scale(r) -> float:
    """Robust standard deviation of residuals [N]: 1.4826 x median absolute deviation."""
    return float(1.482602218505602 * np.median(np.abs(r - np.median(r))))


def _solve(fun, x0, lb, ub, loss, f_scale, max_nfev, jac=None, tol=1e-8, radius=1.0):
    # x_scale sets the first trust region: a relative step of about ``radius``
    scale = np.maximum(np.abs(x0), 1e-6) / radius
    try:
        sol = least_squares(
            fun,
            x0,
            jac="2-point" if jac is None else jac,
            bounds=(lb, ub),
            loss=loss,
            f_scale=f_scale,
            x_scale=scale,
            diff_step=1e-3,
            max_nfev=max_nfev,
            method="trf",
            ftol=tol,
            xtol=tol,
            gtol=tol,
        )
    except ValueError as e:
        raise ConvergenceError(f"identify: least squares failed ({e})") from None
    if sol.status == 0:
        raise ConvergenceError(
            f"identify: the fit did not converge within max_nfev={max_nfev} model evaluations "
            f"(last cost {float(sol.cost):.6g}); raise max_nfev, start closer, or fix a parameter"
        )
    return sol


def _robust_fit(residuals, x0, lb, ub, *, loss, f_scale, rtol, max_nfev, adapt_scale=True):
    """Least squares of the residuals, robust after a plain start, with the robust scale
    adapted to the residuals. ``residuals(rtol)`` gives (fun, jac or None) with the
    model at that tolerance. Returns (solution, raw Jacobian at it, f_scale, nfev)."""
    fun, jac = residuals(rtol)
    nfev = 0
    if loss != "linear" and jac is None:
        # a robust loss far from the optimum sees every residual as an outlier: its
        # cost is nearly flat there and the trust region creeps (20 Jacobians from a
        # 20 % error). Plain least squares converges in a few Gauss-Newton steps; it
        # only supplies the start, loosely converged, and the robust fit below then
        # solves the same problem as before to the same tolerance.
        # Only a start, so its model may be loose (PRE_RTOL): the tolerance matters
        # where the robust fit compares costs that differ by a fraction of the noise.
        loose, _ = residuals(max(rtol, PRE_RTOL))
        pre = _solve(loose, x0, lb, ub, "linear", f_scale, max_nfev, jac, tol=1e-4)
        x0 = pre.x
        nfev += pre.nfev
        # started that close, a first trust region of 1 % saves the evaluations a full
        # step would spend being rejected
        sol = _solve(fun, x0, lb, ub, loss, f_scale, max_nfev, jac, radius=0.01)
    else:
        sol = _solve(fun, x0, lb, ub, loss, f_scale, max_nfev, jac)
    nfev += sol.nfev
    if adapt_scale and loss != "linear":
        # the robust scale must match the residuals, not just the force sensor: noise
        # of the measured motion reaches the residual through the model (the screw's
        # inertance multiplies a twice-differentiated displacement), and a Cauchy scale
        # far below the residual spread biases the fit
        scale = 3.0 * _residual_scale(sol.fun)
        if scale > 0 and abs(scale / f_scale - 1.0) > 0.25:
            f_scale = scale
            sol = _solve(fun, sol.x, lb, ub, loss, f_scale, max_nfev, jac)
            nfev += sol.nfev
    # the Jacobian least_squares returns is scaled by the robust loss; the sandwich
    # needs the derivative of the residuals themselves
    J = _raw_jacobian(fun, sol.x, sol.fun, lb, ub, jac)
    return sol, J, f_scale, nfev


def _fit_stage(
    device,
    names,
    preps,
    *,
    loss,
    f_scale,
    lower,
    upper,
    rtol,
    max_nfev,
    affine=None,
    adapt_scale=True,
):
    x0 = np.array([getattr(device, n) for n in names], dtype=float)
    lb = np.array([lower.get(n, 0.0) for n in names])
    ub = np.array([upper.get(n, np.inf) for n in names])
    x0 = np.clip(x0, lb + 1e-12 * np.maximum(1.0, np.abs(lb)), ub)
    if affine is not None:
        for p in preps:
            if id(p) not in affine:
                affine[id(p)] = _affine_terms(device, p)
    sol, J, f_scale, nfev = _robust_fit(
        lambda tol: _residuals(device, names, preps, tol, affine),
        x0, lb, ub, loss=loss, f_scale=f_scale, rtol=rtol, max_nfev=max_nfev,
        adapt_scale=adapt_scale,
    )  # fmt: skip
    sizes = [int(p.mask.sum()) for p in preps]
    spread = _spreads(J, sol.fun, loss, f_scale, sizes, [p.mask for p in preps])
    dev = dataclasses.replace(device, **dict(zip(names, sol.x, strict=True)))
    return dev, sol, spread, f_scale, nfev


def _plateau_stage(device, preps, *, loss, f_scale, settle_time):
    """(5.1): F = b q + F_f sgn(q) on settled velocity plateaus of square-velocity tests."""
    vs, fs, sizes, masks = [], [], [], []
    for p in preps:
        half = 0.5 / p.test.frequency
        # time since the last reversal of the measured velocity
        rev = _reversal_times(p.t, p.v)
        last = np.full(p.t.size, -np.inf)
        if rev.size:
            pos = np.searchsorted(rev, p.t, side="right") - 1
            ok = pos >= 0
            last[ok] = rev[pos[ok]]
        settled = (p.t - last >= settle_time) & (p.t - last < half + 1e-9)
        settled &= np.isfinite(last) & p.mask
        vs.append(p.v[settled])
        fs.append(p.force[settled])
        sizes.append(int(settled.sum()))
        masks.append(settled)
    v = np.concatenate(vs)
    F = np.concatenate(fs)
    if v.size < 10:
        raise DataFileError(
            "square-velocity tests",
            f"fewer than 10 settled plateau samples (settle time {settle_time:.3g} s); "
            "use method='joint' or longer square-velocity tests",
        )
    eps = device.friction_velocity

    def fun(th):
        return th[0] * v + th[1] * np.tanh(v / eps) - F

    x0 = np.array([device.damping, device.friction], dtype=float)
    sol = _solve(fun, np.maximum(x0, 1e-6), [0.0, 0.0], [np.inf, np.inf], loss, f_scale, 200)
    J = np.column_stack([v, np.tanh(v / eps)])  # exact: the model is linear in (b, F_f)
    spread = _spreads(J, sol.fun, loss, f_scale, sizes, masks)
    return dataclasses.replace(device, damping=sol.x[0], friction=sol.x[1]), sol, spread, v.size


def _estimates(dev, spreads, interval, *, fixed, free, boot):
    """(parameters, covariance) of a fit with the intervals of one method."""
    params = {}
    for j, n in enumerate(PARAMETERS):
        val = float(getattr(dev, n))
        bci = None
        if boot is not None and n in free:
            bci = (float(np.percentile(boot[:, j], 2.5)), float(np.percentile(boot[:, j], 97.5)))
        if n in spreads:
            spread, k = spreads[n]
            spread = spread[interval]
            s, q, how = float(spread.se[k]), float(spread.quantile[k]), spread.interval[k]
            half = q * s
        else:
            s, q, half, how = 0.0, 0.0, 0.0, "fixed"
        params[n] = ParameterEstimate(
            name=n,
            value=val,
            ci95=(val - half, val + half),
            unit=PARAMETER_UNITS[n],
            fixed=n in fixed,
            std_error=s,
            ci95_bootstrap=bci,
            interval=how,
            quantile=q,
        )
    cov = np.zeros((len(PARAMETERS), len(PARAMETERS)))
    for a, na in enumerate(PARAMETERS):
        for b, nb in enumerate(PARAMETERS):
            if na in spreads and nb in spreads and spreads[na][0] is spreads[nb][0]:
                sp = spreads[na][0][interval]
                cov[a, b] = sp.cov[spreads[na][1], spreads[nb][1]]
    return params, cov


def identify(
    dataset: RigDataSet,
    device,
    *,
    method: str = "joint",
    loss: str = "cauchy",
    f_scale: float | None = None,
    fixed: tuple[str, ...] = (),
    lower: dict | None = None,
    upper: dict | None = None,
    bootstrap: int = 0,
    seed: int = 0,
    settle_time: float | None = None,
    reversal_window: float | None = None,
    derivative_window: float = 0.02,
    detrend: str = "constant",
    rtol: float = RTOL,
    max_nfev: int = 100,
    interval: str = "sandwich",
) -> FitResult:
    """Identify stiffness, damping and friction of ``device`` from rig data.

    Parameters
    ----------
    dataset : RigDataSet
        Tests with purpose ``identification`` are fitted, ``validation`` ones predicted.
    device : HydraulicDevice, ScrewDevice or RectifierDevice
        Model structure (flywheel, transmission, law) and the starting values.
    method : {"joint", "thesis"}
        See the module docstring.
    loss : {"linear", "soft_l1", "huber", "cauchy"}
        ``linear`` is plain least squares; the others are robust to spikes.
    f_scale : float, optional
        Residual scale [N] of the robust loss (default: 3 x the robust spread of the
        residuals, see the module docstring); a given value is used as is.
    fixed : tuple of str
        Parameters kept at the device's values.
    lower, upper : dict, optional
        Bounds per parameter (default [0, inf)).
    bootstrap : int
        Number of bootstrap refits over the identification tests (0 = none).
    settle_time : float, optional
        Thesis method, hydraulic: plateau samples are used from this time [s] after a
        reversal (default: five decay times 2 m_e,max / b_ah of the starting model).
    reversal_window : float
        Leave out of the objective the samples within this time [s] after each
        reversal of the measured velocity, where the rig's spikes sit (default: the
        device model's, :data:`REVERSAL_WINDOWS`: 0.24 s for the hydraulic device and
        the rectifier, 0.16 s for the screw; 0.16 s is the whole spike of
        :func:`simulate_rig`; the thesis also set the spikes aside, ch. 5.3). Check it
        on real data with :meth:`FitResult.reversal_profile`. 0 keeps every sample and
        leaves the spikes to the robust loss, which cannot separate them when they are not
        much larger than the residual spread. A test shorter than the window per half
        period contributes nothing.
    derivative_window, detrend
        Filters for records with only displacement or only velocity
        (:mod:`inerterlab.identify.filters`).
    rtol : float
        Tolerance of the model integration (default 1e-10). The fit compares costs
        that differ by a fraction of the noise: a looser model makes the objective
        jagged on that scale and the fit stops wherever its start leaves it (at 1e-8
        the rectifier's estimates moved by up to 0.8 standard errors between two starts
        6 % apart; docs/decisions.md, "The fit's model tolerance").
    interval : {"sandwich", "jackknife"}
        How the 95 % intervals and ``covariance`` are computed (module docstring):
        ``sandwich`` (default) the M-estimator sandwich with an autoregressive noise
        model within tests and the normal quantile, calibrated for every parameter of
        the three devices in the coverage study (docs/guide/identification.md,
        "Calibrated intervals"); ``jackknife`` over tests with Satterthwaite degrees
        of freedom, conservative, for when a mismatch that persists within a test is
        suspected. Both are kept on the
        result: :meth:`FitResult.with_intervals`.

    Returns
    -------
    FitResult
    """
    check_choice("method", method, ("joint", "thesis"))
    check_choice("loss", loss, LOSSES)
    check_choice("interval", interval, INTERVALS)
    for n in fixed:
        check_choice("fixed", n, PARAMETERS)
    if not isinstance(dataset, RigDataSet) or not dataset.tests:
        raise ParameterError("dataset", dataset, "a RigDataSet with at least one test")
    lower, upper = dict(lower or {}), dict(upper or {})
    ident = dataset.select("identification")
    if not ident:
        raise DataFileError(dataset.source or "dataset", "no test has purpose 'identification'")
    if reversal_window is None:
        reversal_window = default_reversal_window(device)
    check_nonnegative("reversal_window", reversal_window, "s")
    preps = {
        id(t): _prepare(
            t, window=derivative_window, detrend=detrend, reversal_window=reversal_window
        )
        for t in dataset.tests
    }
    ip = [preps[id(t)] for t in ident]
    affine = {} if _is_affine(device) else None
    sigma = _noise_estimate(ident)
    adapt = f_scale is None
    if f_scale is None:
        f_scale = max(3.0 * sigma, 1e-9 * max(float(np.abs(t.force).max()) for t in ident))
    free = [n for n in PARAMETERS if n not in fixed]
    spreads = {}
    stages = []
    nfev = 0
    dev = device
    stage = dict(lower=lower, upper=upper, rtol=rtol, max_nfev=max_nfev, affine=affine)
    if method == "joint" or device.kind != "hydraulic":
        sig = ("sine",) if method == "thesis" else None
        use = [p for p in ip if sig is None or p.test.signal in sig] or ip
        if free:
            dev, sol, spread, f_scale, n_ev = _fit_stage(
                dev, free, use, loss=loss, f_scale=f_scale, adapt_scale=adapt, **stage
            )
            spreads.update({n: (spread, j) for j, n in enumerate(free)})
            nfev += n_ev
        stages.append(f"{', '.join(free) or 'nothing'} jointly over {len(use)} tests")
        cost_preps = use
    else:
        squares = [p for p in ip if p.test.signal in ("square", "triangle")]
        sines = [p for p in ip if p.test.signal == "sine"]
        if not squares or not sines:
            raise DataFileError(
                dataset.source or "dataset",
                "the thesis method needs square-velocity (square/triangle) and sinusoidal "
                "identification tests; use method='joint'",
            )
        fw, r = dev.flywheel, dev.transmission.ratio
        if settle_time is None:
            settle_time = 5.0 * 2.0 * r * r * fw.inertia_max / max(dev.damping, 1.0)
        first = [n for n in ("damping", "friction") if n not in fixed]
        if first:
            dev2, sol, spread, n_used = _plateau_stage(
                dev, squares, loss=loss, f_scale=f_scale, settle_time=settle_time
            )
            dev = dataclasses.replace(dev, **{n: getattr(dev2, n) for n in first})
            spreads.update(
                {n: (spread, j) for j, n in enumerate(("damping", "friction")) if n in first}
            )
            stages.append(f"damping, friction from {n_used} settled plateau samples (5.1)")
        if "stiffness" not in fixed:
            dev, sol, spread, f_scale, n_ev = _fit_stage(
                dev, ["stiffness"], sines, loss=loss, f_scale=f_scale, adapt_scale=adapt, **stage
            )
            spreads["stiffness"] = (spread, 0)
            nfev += n_ev
            stages.append(f"stiffness from {len(sines)} sinusoidal tests (5.7)")
        cost_preps = sines
    boot = None
    if bootstrap and free:
        rng = np.random.default_rng(seed)
        rows = []
        for _ in range(int(bootstrap)):
            pick = rng.integers(0, len(cost_preps), len(cost_preps))
            sample = [cost_preps[i] for i in pick]
            d_b, *_ = _fit_stage(
                dev, free, sample, loss=loss, f_scale=f_scale, adapt_scale=False, **stage
            )
            rows.append([getattr(d_b, n) for n in PARAMETERS])
        boot = np.array(rows)
    by_method = {
        m: _estimates(dev, spreads, m, fixed=fixed, free=free, boot=boot) for m in INTERVALS
    }
    params, cov = by_method[interval]
    tests = []
    for t in dataset.tests:
        p = preps[id(t)]
        pred = predict_test(dev, p, rtol=rtol)
        rev = _reversal_times(p.t, p.v)
        tests.append(
            TestValidation(
                name=t.name,
                purpose=t.purpose,
                signal=t.signal,
                frequency=t.frequency,
                amplitude=t.amplitude,
                t=t.t,
                measured=t.force,
                predicted=pred,
                reversals=rev,
                reversal_signs=-np.sign(np.interp(rev, p.t, p.v)),  # the new direction
            )
        )
    res_id = np.concatenate([tv.residual for tv in tests if tv.purpose == "identification"])
    return FitResult(
        parameters=params,
        device=dev,
        method=method,
        loss=loss,
        tests=tests,
        cost=float(np.sqrt(np.mean(res_id**2))),
        noise_estimate=sigma,
        stages=stages,
        bootstrap=boot,
        nfev=nfev,
        f_scale=float(f_scale),
        reversal_window=float(reversal_window),
        covariance=cov,
        parameter_order=PARAMETERS,
        interval_method=interval,
        interval_alternatives=by_method,
    )
