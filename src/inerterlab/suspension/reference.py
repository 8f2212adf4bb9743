"""Plain-Python right-hand side of the quarter car, used by the scipy backend: the oracle.

Written independently of the model core (:mod:`inerterlab.systems`): the inertia law
comes from the :class:`~inerterlab.flywheels.AdaptiveFlywheel` methods' formulas
re-typed with :mod:`math`, the slider force from the law in the
:mod:`inerterlab.slider_dynamics` docstring, the impulse at road jumps from numerical
quadrature and root bracketing. Agreement of the two backends to solver tolerance is
therefore a real check of both.

The state vector is the model's physical states followed by the metric states:
int a3^2, int grip^2, int z^2, the 8 Wk filter states, int a_w^2, int a_w^4.
"""

from __future__ import annotations

import math

import numpy as np

from ..metrics import wk_state_space
from .model import QuarterCar

__all__ = ["ReferenceRHS"]


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
        self.nphys = model.n_states
        self.wa, self.wb, self.wc, self.wd = wk_state_space()
        self.seg = None
        if model.uses_flywheel:
            fw = model.flywheel
            self.fw = fw
            self.r = model.transmission.ratio
            self.i_const = fw.inertia_min
            if self.law == "slider-dynamics":
                from ..slider_dynamics import SliderDynamics

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
