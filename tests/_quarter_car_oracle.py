"""An independent oracle for the tests: the named quarter cars in plain Python, integrated
by :func:`scipy.integrate.solve_ivp` (DOP853 by default). It is not part of the package:
the package simulates every car on its model core (:mod:`inerterlab.systems`).

Written apart from the core: the inertia law comes from the formulas of the
:class:`~inerterlab.flywheels.AdaptiveFlywheel` methods re-typed with :mod:`math`, the
slider force from the law in the :mod:`inerterlab.slider_dynamics` docstring, the
friction branch's velocity by root bracketing, the impulse at road jumps from numerical
quadrature and root bracketing. The ride metrics are integrated as extra states (int
a3^2, int grip^2, int z^2, the 8 Wk filter states, int a_w^2, int a_w^4) and the peaks
are located on solve_ivp's dense output with a bounded scalar search. Agreement of the
core with it to solver tolerance is therefore a real check of both.

:func:`simulate` returns the package's :class:`~inerterlab.simulate.SimulationResult`
(its ride metrics reduced by the package's own :func:`~inerterlab.systems.observers.ride_metrics`
from the integrals), so a test compares the two field by field. The benchmarks use it
as their scipy baseline (``benchmarks/bench_simulate.py`` and others).
"""

from __future__ import annotations

import math
import time

import numpy as np

from inerterlab.errors import ConvergenceError
from inerterlab.excitation import ROAD_JUMP_RTOL, road_displacement, road_scale
from inerterlab.metrics import wk_state_space
from inerterlab.simulate import (
    _DIRAC_REASON,
    SimulationResult,
    _check_inputs,
    _metrics,
    _Run,
    _sample_times,
)
from inerterlab.suspension.model import QuarterCar, model_of
from inerterlab.systems.core import listed_steps, tyre_dirac_reason
from inerterlab.systems.options import SimulationOptions

__all__ = ["ReferenceRHS", "simulate", "simulate_metrics", "state_names", "state_scales",
           "initial_state", "N_METRIC_STATES"]  # fmt: skip

#: the metric states after the physical ones: int a^2, int grip^2, int z^2, the 8 Wk
#: filter states, int aw^2, int aw^4
N_METRIC_STATES = 13

#: a typical size of each physical state, for the absolute tolerances
_SCALES = {
    "unsprung_disp": 1e-2,
    "unsprung_vel": 1e-1,
    "sprung_disp": 1e-2,
    "sprung_vel": 1e-1,
    "slider_radius": 1e-3,
    "slider_rate": 1e-2,
    "device_spring_deflection": 1e-4,
    "branch_velocity": 1e-2,
}


def state_names(model: QuarterCar) -> tuple[str, ...]:
    """Names of the oracle's physical states of ``model``, in order."""
    names = ["unsprung_disp", "unsprung_vel", "sprung_disp", "sprung_vel"]
    if model.suspension == "afw" and model.law == "slider-dynamics":
        names += ["slider_radius", "slider_rate"]
    if model.suspension == "device":
        names += ["device_spring_deflection"]
    if model.suspension == "device-afw":
        names += ["device_spring_deflection", "branch_velocity"]
        if model.law == "slider-dynamics":
            names += ["slider_radius", "slider_rate"]
    return tuple(names)


def initial_state(model: QuarterCar, unsprung: float = 0.0, sprung: float = 0.0) -> np.ndarray:
    """The physical state at rest with the given displacements [m]."""
    names = state_names(model)
    y = np.zeros(len(names))
    y[0] = unsprung
    y[2] = sprung
    if "slider_radius" in names:
        y[names.index("slider_radius")] = model.flywheel.slider_min
    return y


def state_scales(model: QuarterCar) -> np.ndarray:
    """A typical size of every state (physical, then metric), for absolute tolerances."""
    phys = [_SCALES[n] for n in state_names(model)]
    # int a^2, int grip^2, int z^2, Wk states (~ acceleration), int aw^2, int aw^4
    metric = [1e-2, 1e-4, 1e-7] + [1e-1] * 8 + [1e-2, 1e-3]
    return np.array(phys + metric)


class ReferenceRHS:
    """Right-hand side f(t, y) of one model on one road segment (plain Python)."""

    def __init__(self, model: QuarterCar):
        self.model = model
        q = model.parameters
        self.M, self.Mt = q.sprung_mass, q.unsprung_mass
        self.K, self.C = q.stiffness, q.damping
        self.Kt, self.Ct = q.tyre_stiffness, q.tyre_damping
        self.W = q.static_tyre_load
        self.lift = model.tyre_lift_off
        self.grip = q.tyre_stiffness / q.static_tyre_load
        self.kind = model.suspension
        self.law = model.effective_law
        self.nphys = len(state_names(model))
        self.wa, self.wb, self.wc, self.wd = wk_state_space()
        self.seg = None
        if model.uses_flywheel:
            fw = model.flywheel
            self.fw = fw
            self.r = model.transmission.ratio
            self.i_const = fw.inertia_min
            if self.law == "slider-dynamics":
                from inerterlab.slider_dynamics import SliderDynamics

                c = (model.slider or SliderDynamics()).coefficients(fw)
                self.sl = dict(
                    rest=c[0],
                    n=c[1],
                    m=c[2],
                    k=c[3],
                    lmin=c[4],
                    lmax=c[5],
                    cs=c[6],
                    kc=c[7],
                    cc=c[8],
                )
        if model.device is not None:
            d = model.device
            self.b, self.ff, self.kh, self.veps = (
                d.damping,
                d.friction,
                d.stiffness,
                d.friction_velocity,
            )

    # -- inertia laws -----------------------------------------------------------------
    def _slider_l(self, w: float) -> float:
        fw = self.fw
        w = abs(w)
        if w < fw.saturation_speed:
            return (
                fw.spring_stiffness * fw.slider_min / (fw.spring_stiffness - fw.slider_mass * w * w)
            )
        return fw.slider_max

    def _inertia(self, w: float) -> float:
        fw = self.fw
        return fw.rest_inertia + fw.inertia_coefficient * self._slider_l(w) ** fw.power

    def _momentum_inertia(self, w: float) -> float:
        fw = self.fw
        w = abs(w)
        if w >= fw.saturation_speed:
            return fw.inertia_max
        k, m, a = fw.spring_stiffness, fw.slider_mass, fw.slider_min
        l = k * a / (k - m * w * w)
        dl = 2.0 * k * a * m * w / (k - m * w * w) ** 2
        return self._inertia(w) + w * fw.inertia_coefficient * fw.power * l ** (fw.power - 1) * dl

    def inertance(self, v: float, y) -> tuple[float, float]:
        """(m_e, extra force g) of the inertia law at branch velocity v [m/s]."""
        r = self.r
        if self.law == "constant":
            return r * r * self.i_const, 0.0
        if self.law == "thesis":
            return r * r * self._inertia(r * v), 0.0
        if self.law == "momentum":
            return r * r * self._momentum_inertia(r * v), 0.0
        s = self.sl
        j0 = self.nphys - 2
        l, ld = y[j0], y[j0 + 1]
        return r * r * (s["rest"] + s["n"] * s["m"] * l * l), 2.0 * s["n"] * s[
            "m"
        ] * r * r * l * ld * v

    def _slider_acc(self, l: float, ld: float, w: float) -> float:
        s = self.sl
        f = s["m"] * l * w * w - s["k"] * (l - s["lmin"]) - s["cs"] * ld
        if l > s["lmax"]:
            f -= max(0.0, s["kc"] * (l - s["lmax"]) + s["cc"] * ld)
        elif l < s["lmin"]:
            f += max(0.0, s["kc"] * (s["lmin"] - l) - s["cc"] * ld)
        return f / s["m"]

    def _branch_velocity(self, force: float) -> float:
        """u with b u + F tanh(u/eps) = force (system A's massless branch)."""
        from scipy.optimize import brentq

        b, ff, eps = self.b, self.ff, self.veps
        g = lambda u: b * u + ff * math.tanh(u / eps) - force  # noqa: E731
        lo, hi = (force - ff) / b - 1e-12, (force + ff) / b + 1e-12
        if g(lo) == 0.0:
            return lo
        return brentq(g, lo, hi, xtol=1e-300, rtol=1e-15, maxiter=400)

    # -- road ---------------------------------------------------------------------------
    @staticmethod
    def road(seg, t: float) -> tuple[float, float]:
        if seg[2] == 0.0:
            return seg[3] + seg[4] * (t - seg[0]), seg[4]
        arg = seg[6] * t + seg[7]
        return seg[3] + seg[5] * math.sin(arg), seg[5] * seg[6] * math.cos(arg)

    # -- dynamics ----------------------------------------------------------------------
    def accelerations(self, t: float, y) -> tuple[float, float, np.ndarray]:
        """(a3, a2, derivative of the device states) at time t on the current segment."""
        x1, v1 = self.road(self.seg, t)
        X2, V2, X3, V3 = y[0], y[1], y[2], y[3]
        z, v = X3 - X2, V3 - V2
        fs = self.K * z + self.C * v
        ft = self.Kt * (X2 - x1) + self.Ct * (V2 - v1)
        if self.lift and ft > self.W:
            ft = self.W
        extra = np.zeros(self.nphys - 4)
        if self.kind == "traditional":
            return -fs / self.M, (fs - ft) / self.Mt, extra
        if self.kind in ("cfw", "afw"):
            me, g = self.inertance(v, y)
            mu = 1.0 / self.M + 1.0 / self.Mt
            arel = (ft / self.Mt - (fs + g) * mu) / (1.0 + me * mu)
            fin = me * arel + g
            if self.law == "slider-dynamics":
                l, ld = y[4], y[5]
                extra[0], extra[1] = ld, self._slider_acc(l, ld, self.r * v)
            return -(fs + fin) / self.M, (fs + fin - ft) / self.Mt, extra
        fd = self.kh * y[4]
        if self.kind == "device":
            u = self._branch_velocity(fd)
            extra[0] = v - u
        else:
            u = y[5]
            me, g = self.inertance(u, y)
            extra[0] = v - u
            extra[1] = (fd - self.b * u - self.ff * math.tanh(u / self.veps) - g) / me
            if self.law == "slider-dynamics":
                l, ld = y[6], y[7]
                extra[2], extra[3] = ld, self._slider_acc(l, ld, self.r * u)
        return -(fs + fd) / self.M, (fs + fd - ft) / self.Mt, extra

    def __call__(self, t: float, y) -> np.ndarray:
        n = self.nphys
        a3, a2, extra = self.accelerations(t, y)
        dy = np.empty_like(y)
        dy[0], dy[1], dy[2], dy[3] = y[1], a2, y[3], a3
        dy[4:n] = extra
        x1, _ = self.road(self.seg, t)
        grip = self.grip * (y[0] - x1)
        z = y[2] - y[0]
        xw = y[n + 3 : n + 11]
        aw = float(self.wc @ xw) + self.wd * a3
        dy[n] = a3 * a3
        dy[n + 1] = grip * grip
        dy[n + 2] = z * z
        dy[n + 3 : n + 11] = self.wa @ xw + self.wb * a3
        dy[n + 11] = aw * aw
        dy[n + 12] = aw**4
        return dy

    def outputs(self, t: float, y) -> tuple[float, float, float, float]:
        """(a3, a_w, deflection z, unclipped tyre force K_t (X2-X1) + C_t (V2-X1'))."""
        n = self.nphys
        a3, _, _ = self.accelerations(t, y)
        x1, v1 = self.road(self.seg, t)
        aw = float(self.wc @ y[n + 3 : n + 11]) + self.wd * a3
        return a3, aw, y[2] - y[0], self.Kt * (y[0] - x1) + self.Ct * (y[1] - v1)

    # -- road jumps -----------------------------------------------------------------
    def _inerter_impulse(self, v0: float, v1: float, y) -> float:
        """Impulse int F dt [N s] the inerter passes while its velocity jumps v0 -> v1."""
        r = self.r
        if self.law in ("constant", "slider-dynamics"):
            me, _ = self.inertance(v0, y)
            return me * (v1 - v0)
        if self.law == "momentum":
            return r * r * (self._inertia(r * v1) * v1 - self._inertia(r * v0) * v0)
        from scipy.integrate import quad

        ws = self.fw.saturation_speed / r
        pts = [p for p in (-ws, 0.0, ws) if min(v0, v1) < p < max(v0, v1)]
        val, _ = quad(
            lambda s: r * r * self._inertia(r * s),
            v0,
            v1,
            points=pts or None,
            epsabs=0.0,
            epsrel=1e-13,
            limit=200,
        )
        return val

    def apply_jump(self, y, jump: float) -> float:
        """Apply the tyre-damper impulse C_t * jump of a road step in place.

        Returns the jump of the body velocity V3 [m/s]. Where it is not zero the body
        acceleration holds a Dirac of that weight, and the Wk filter states
        (x' = A x + B a3) jump by B times it.
        """
        imp = self.Ct * jump
        if imp == 0.0 or (self.lift and imp < 0.0):
            return 0.0
        if self.kind not in ("cfw", "afw"):
            y[1] += imp / self.Mt
            return 0.0
        from scipy.optimize import brentq

        v0 = y[3] - y[1]
        mu = 1.0 / self.M + 1.0 / self.Mt
        g = lambda v1: v1 - v0 + imp / self.Mt + mu * self._inerter_impulse(v0, v1, y)  # noqa: E731
        a, b = sorted((v0, v0 - imp / self.Mt))
        v1 = brentq(g, a, b, xtol=1e-300, rtol=1e-15, maxiter=400)
        p = self._inerter_impulse(v0, v1, y)
        dv3 = -p / self.M
        y[3] += dv3
        y[1] += (imp + p) / self.Mt
        n = self.nphys
        y[n + 3 : n + 11] += self.wb * dv3
        return dv3


def _run(model, excitation, horizon, rtol, atol_factor, method, sample_rate, max_steps,
         time_limit, want_series) -> _Run:  # fmt: skip
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar

    f = ReferenceRHS(model)
    x_prev = excitation.initial_road(horizon)
    du, ds = excitation.initial_displacements
    phys = initial_state(model, unsprung=x_prev + du, sprung=x_prev + ds)
    y = np.concatenate([phys, np.zeros(N_METRIC_STATES)])
    segs = excitation.segments(horizon)
    atol = atol_factor * state_scales(model)
    peaks = np.full(7, -np.inf)
    ts = _sample_times(horizon, sample_rate) if want_series else np.empty(0)
    out_y = np.empty((ts.size, y.size))
    out_a3 = np.empty(ts.size)
    isamp = 0
    nsteps = nfev = 0
    jumps = []
    tol = ROAD_JUMP_RTOL * road_scale(segs)
    budget = {"calls": 0, "t": 0.0}
    max_calls = 16 * max_steps
    deadline = None if time_limit is None else time.monotonic() + time_limit

    class _OverBudget(Exception):
        pass

    def rhs(t, yy):
        # step and time limits: solve_ivp itself has neither
        budget["calls"] += 1
        budget["t"] = t
        if budget["calls"] > max_calls:
            raise _OverBudget(
                f"more than max_steps={max_steps} steps ({max_calls} right-hand-side evaluations)"
            )
        if deadline is not None and budget["calls"] % 256 == 0 and time.monotonic() > deadline:
            raise _OverBudget(f"the time limit of {time_limit:g} s was reached")
        return f(t, yy)

    def q_of(t, yy):
        a3, aw, z, ft = f.outputs(t, yy)
        return np.array([a3, -a3, aw, -aw, z, -z, ft])

    for seg in segs:
        t0, t1 = float(seg[0]), float(min(seg[1], horizon))
        f.seg = seg
        xs, _ = f.road(seg, t0)
        if abs(xs - x_prev) > tol:
            dv3 = f.apply_jump(y, xs - x_prev)
            if dv3 != 0.0 and t0 < horizon:
                jumps.append((t0, float(dv3)))
        x_prev, _ = f.road(seg, t1)
        if t1 <= t0:
            continue
        try:
            sol = solve_ivp(rhs, (t0, t1), y, method=method, rtol=rtol, atol=atol,
                            dense_output=True)  # fmt: skip
        except _OverBudget as exc:
            raise ConvergenceError(
                f"scipy {method} stopped at t = {budget['t']:.6g} s of {horizon:g} s: {exc}"
            ) from None
        if sol.status != 0:
            raise ConvergenceError(f"scipy {method} failed: {sol.message}")
        nsteps += sol.t.size - 1
        nfev += sol.nfev
        # peaks: values at step ends and midpoints, then local maxima refined on the
        # dense output
        tt = np.concatenate([sol.t, 0.5 * (sol.t[1:] + sol.t[:-1])])
        tt = tt[np.argsort(tt)]
        yy = sol.sol(tt)
        yy[:, 0] = sol.y[:, 0]
        yy[:, -1] = sol.y[:, -1]
        qs = np.array([q_of(t, yy[:, i]) for i, t in enumerate(tt)])
        for j in range(7):
            col = qs[:, j]
            top = col.max()
            peaks[j] = max(peaks[j], top)
            if col.size < 3:
                continue
            interior = np.where((col[1:-1] >= col[:-2]) & (col[1:-1] >= col[2:]))[0] + 1
            span = max(abs(top), 1e-300)
            for i in interior:
                if col[i] < top - 1e-2 * span:
                    continue
                res = minimize_scalar(
                    lambda t, j=j, s=sol.sol: -q_of(t, s(t))[j],
                    bounds=(tt[i - 1], tt[i + 1]),
                    method="bounded",
                    options={"xatol": 1e-13 * max(1.0, t1)},
                )
                peaks[j] = max(peaks[j], -res.fun)
        if want_series:
            last = t1 >= horizon
            while isamp < ts.size and (ts[isamp] < t1 or (last and ts[isamp] <= t1)):
                if ts[isamp] >= t0:
                    ys = sol.sol(ts[isamp]) if ts[isamp] > t0 else sol.y[:, 0]
                    out_y[isamp] = ys
                    out_a3[isamp] = f.outputs(ts[isamp], ys)[0]
                isamp += 1
        y = sol.y[:, -1].copy()
        if t1 >= horizon:
            break
    st = {"steps": nsteps, "rejected": None, "rhs_calls": nfev, "segments": len(segs)}
    samples = None
    n = len(phys)
    if want_series:
        _, _, wc, wd = wk_state_space()
        x1, v1 = road_displacement(segs, ts)
        samples = dict(
            time=ts, states=out_y[:, :n].copy(), state_names=state_names(model), body_acc=out_a3,
            body_acc_wk=out_y[:, n + 3 : n + 11] @ wc + wd * out_a3, road=x1, road_velocity=v1,
        )  # fmt: skip
    I = y[n:]
    values = {
        "ride.i_acc": I[0], "ride.i_grip": I[1], "ride.i_defl": I[2], "ride.i_wk": I[11],
        "ride.i_wk4": I[12],
    }  # fmt: skip
    names = ("acc", "neg_acc", "wk", "neg_wk", "defl", "neg_defl", "tyre")
    values.update({f"ride.peak_{k}": float(v) for k, v in zip(names, peaks, strict=True)})
    return _Run(values=values, samples=samples, stats=st, jumps=tuple(jumps))


def _not_finite_here(model, excitation, run, horizon: float) -> dict:
    """The oracle's own decision of which metrics are not finite (the package's words):
    the body's where its velocity was seen to jump at a road step, the least tyre force
    where a tyre damper that cannot lift off meets a road step down."""
    out = {}
    if run.jumps:
        why = _DIRAC_REASON.format(jumps=listed_steps(run.jumps, "m/s"))
        out.update(rms_body_acc=why, peak_body_acc=why)
    if model.parameters.tyre_damping > 0 and not model.tyre_lift_off:
        down = [(t, j) for t, j in excitation.prepared(horizon).steps if j < 0 and t < horizon]
        if down:
            out["min_tyre_force"] = tyre_dirac_reason(down)
    return out


def simulate(model, excitation, horizon: float = 10.0, *, rtol: float = 1e-8,
             atol: float | None = None, method: str = "DOP853", sample_rate: float = 1000.0,
             output: str = "series", max_steps: int = 10_000_000,
             time_limit: float | None = None) -> SimulationResult:  # fmt: skip
    """``model`` (a named quarter car) on ``excitation`` up to ``horizon`` [s] by
    ``solve_ivp(method=...)`` on :class:`ReferenceRHS`; the tyre-damper impulse C_t x jump
    applied where the road jumps. ``atol`` is a multiple of each state's typical size
    (:func:`state_scales`; None: ``rtol``). The result is the package's
    :class:`~inerterlab.simulate.SimulationResult`; its states are :func:`state_names`."""
    model = model_of(model)
    options = SimulationOptions(rtol=rtol, atol=atol, sample_rate=sample_rate,
                                max_steps=max_steps)  # fmt: skip
    T = _check_inputs(model, excitation, horizon, options, output)
    want = output == "series"
    run = _run(model, excitation, T, rtol, options.atol_factor, method, sample_rate, max_steps,
               time_limit, want)  # fmt: skip
    nf = _not_finite_here(model, excitation, run, T)
    return SimulationResult(
        model=model, excitation=excitation, horizon=T, options=options,
        values=_metrics(model, excitation, run, T, nf), stats=run.stats,
        body_velocity_jumps=run.jumps, not_finite=nf, **(run.samples if want else {}),
    )  # fmt: skip


def simulate_metrics(model, excitation, horizon: float = 10.0, **kwargs) -> dict:
    """The ride metrics of :func:`simulate` (no time series)."""
    return simulate(model, excitation, horizon, output="metrics", **kwargs).metrics()
