"""Time simulation of a vehicle with tyre lift-off and asymmetric dampers.

The linear model of :mod:`inerterlab.vehicles.model` with two departures, each a
property of a connection:

* **Tyre lift-off.** The contact force is F0 - k_t delta - c_t delta' (F0 the static
  load, delta = wheel - road the tyre extension from equilibrium); a tyre cannot pull,
  so the force is max(0, that). The linear model lets it go negative.
* **Asymmetric dampers.** A strut's damping is ``rebound`` x c while it extends and
  ``compression`` x c while it shortens (both 1: the linear strut).
* **Adaptive inerters.** A strut's adaptive-flywheel inerter (``Strut.adaptive``) adds
  (m_e(v) - m_e(0)) u u^T to the mass matrix, m_e the inertance of its law at the
  strut's extension rate v (laws ``thesis`` and ``momentum`` of
  :mod:`inerterlab.elements.adaptive_flywheel`, the same compiled code every system
  uses); the accelerations then solve the small symmetric positive definite system by
  Cholesky at every stage. ``thesis`` and ``momentum`` make the force from the
  inertance alone (no extra velocity-squared term), so the mass matrix carries it all.
* **Strut friction.** A Coulomb force of size ``friction`` against the strut's
  extension rate, regularised as F_f tanh(delta' / v_f) with ``friction_velocity``
  v_f (default 1 mm/s): below v_f the friction acts as a damper of rate F_f / v_f, so
  the equations stay an ODE an explicit method can integrate; the step must resolve
  m / (F_f / v_f) (checked).

Coordinates, outputs and their units are those of the linear model, measured from
static equilibrium; constant inerters keep the mass matrix constant. The equations are
integrated by the classical fourth-order Runge-Kutta method with a fixed step, the
road linear between its samples (so the road velocity is constant on each sample
interval and the steps never straddle a change of slope), compiled with numba.
Outputs are sampled at the road samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..elements.adaptive_flywheel import flywheel_inertance
from ..errors import ParameterError, check_nonnegative, check_positive
from .model import LinearVehicle

__all__ = ["NonlinearResult", "simulate_nonlinear"]


@dataclass(frozen=True)
class NonlinearResult:
    """Outputs (name -> array over the road samples), contact forces and lift-off."""

    time: np.ndarray
    outputs: dict
    contact_force: dict
    lift_off_fraction: dict


def _tables(
    vehicle: LinearVehicle,
    rebound: float,
    compression: float,
    lift_off: bool,
    friction: float = 0.0,
    friction_velocity: float = 1e-3,
):
    M, _, _, _, _ = vehicle.matrices(internal=True)
    Az, Zq, Zr, Fz = vehicle.internal_realisation()
    static = vehicle.static_tyre_loads()
    U = np.array([c.u for c in vehicle.connections])
    V = np.array([c.v for c in vehicle.connections])
    k = np.zeros(len(U))
    c_ext = np.zeros(len(U))
    c_cmp = np.zeros(len(U))
    preload = np.zeros(len(U))
    unilateral = np.zeros(len(U), dtype=np.int64)
    fric = np.zeros(len(U))
    for j, con in enumerate(vehicle.connections):
        _, c, kk = con.law.mck()
        k[j] = kk
        c_ext[j] = c_cmp[j] = c
        if con.name.endswith("_strut"):
            if (rebound != 1.0 or compression != 1.0) and hasattr(con.law, "network"):
                raise ParameterError(
                    "rebound/compression",
                    (rebound, compression),
                    f"1 with the network strut {con.name} ({con.law.network}): an "
                    "asymmetric damper needs a Strut, whose damper is one element",
                )
            c_ext[j], c_cmp[j] = rebound * c, compression * c
            fric[j] = friction
        if con.name.endswith("_tyre"):
            preload[j] = static[con.name[: -len("_tyre")]]
            unilateral[j] = 1 if lift_off else 0
    fv = np.array([friction_velocity])
    afw, rows, me0 = [], [], []
    for j, con in enumerate(vehicle.connections):
        adaptive = getattr(con.law, "adaptive", None)
        if adaptive is not None:
            afw.append(j)
            rows.append(adaptive.row())
            me0.append(adaptive.inertance_min)
    afw = np.array(afw, dtype=np.int64)
    rows = np.array(rows, dtype=float).reshape(len(afw), -1) if len(afw) else np.zeros((0, 16))
    me0 = np.array(me0, dtype=float)
    return (np.linalg.inv(M), U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv,
            afw, rows, me0, np.ascontiguousarray(M), Az, Zq, Zr, Fz)  # fmt: skip


@njit(cache=True)
def _forces(q, qd, r, rd, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv, out_f, gen):
    """Generalised forces into ``gen``; ``out_f`` receives each connection's tension."""
    n = q.size
    gen[:] = 0.0
    for j in range(U.shape[0]):
        d = 0.0
        dd = 0.0
        for i in range(n):
            d += U[j, i] * q[i]
            dd += U[j, i] * qd[i]
        for i in range(r.size):
            d -= V[j, i] * r[i]
            dd -= V[j, i] * rd[i]
        c = c_ext[j] if dd > 0.0 else c_cmp[j]
        f = k[j] * d + c * dd
        if fric[j] != 0.0:
            f += fric[j] * math.tanh(dd / fv[0])
        if unilateral[j] == 1 and preload[j] - f < 0.0:
            f = preload[j]  # the contact force F0 - f is held at 0
        out_f[j] = f
        for i in range(n):
            gen[i] -= U[j, i] * f
    return gen


@njit(cache=True)
def _solve_spd(A, b, L, out):
    """out = A^-1 b for a small symmetric positive definite A (Cholesky; L is work)."""
    n = A.shape[0]
    for j in range(n):
        s = A[j, j]
        for m in range(j):
            s -= L[j, m] * L[j, m]
        L[j, j] = math.sqrt(s)
        for i in range(j + 1, n):
            t = A[i, j]
            for m in range(j):
                t -= L[i, m] * L[j, m]
            L[i, j] = t / L[j, j]
    for i in range(n):
        t = b[i]
        for m in range(i):
            t -= L[i, m] * out[m]
        out[i] = t / L[i, i]
    for i in range(n - 1, -1, -1):
        t = out[i]
        for m in range(i + 1, n):
            t -= L[m, i] * out[m]
        out[i] = t / L[i, i]


@njit(cache=True)
def _deriv(x, rr, rd, Minv, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv,
           afw, rows, me0, M0, Az, Zq, Zr, Fz, Mw, Lw, gen, f, out):  # fmt: skip
    n = Minv.shape[0]
    _forces(x[:n], x[n : 2 * n], rr, rd, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv,
            f, gen)  # fmt: skip
    for i in range(n):
        out[i] = x[n + i]
    # internal states of network struts: z' = Az z + Zq q - Zr r, force -Fz z on q
    nz = Az.shape[0]
    for a in range(nz):
        t = 0.0
        for b in range(nz):
            t += Az[a, b] * x[2 * n + b]
        for b in range(n):
            t += Zq[a, b] * x[b]
        for b in range(rr.size):
            t -= Zr[a, b] * rr[b]
        out[2 * n + a] = t
        for i in range(n):
            gen[i] -= Fz[i, a] * x[2 * n + a]
    if afw.size == 0:
        for a in range(n):
            t = 0.0
            for b in range(n):
                t += Minv[a, b] * gen[b]
            out[n + a] = t
        return
    # adaptive inerters: M(q') = M0 + sum_j (m_e,j(v_j) - m_e,j(0)) u_j u_j^T
    for a in range(n):
        for b in range(n):
            Mw[a, b] = M0[a, b]
    for jj in range(afw.size):
        j = afw[jj]
        v = 0.0
        for i in range(n):
            v += U[j, i] * x[n + i]
        me, _ = flywheel_inertance(rows[jj], v, 0.0, 0.0)
        d = me - me0[jj]
        for a in range(n):
            for b in range(n):
                Mw[a, b] += d * U[j, a] * U[j, b]
    _solve_spd(Mw, gen, Lw, out[n:])


@njit(cache=True)
def _run(x0, r, dt, sub, Minv, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv,
         afw, rows, me0, M0, Az, Zq, Zr, Fz):  # fmt: skip
    n = Minv.shape[0]
    nt = r.shape[0]
    nx = x0.size
    xs = np.empty((nt, nx))
    fs = np.empty((nt, U.shape[0]))
    acc = np.empty((nt, n))
    x = x0.copy()
    h = dt / sub
    f = np.empty(U.shape[0])
    k1 = np.empty(nx)
    k2 = np.empty(nx)
    k3 = np.empty(nx)
    k4 = np.empty(nx)
    xt = np.empty(nx)
    Mw = np.empty((n, n))
    Lw = np.zeros((n, n))
    gen = np.empty(n)
    args = (
        Minv,
        U,
        V,
        k,
        c_ext,
        c_cmp,
        preload,
        unilateral,
        fric,
        fv,
        afw,
        rows,
        me0,
        M0,
        Az,
        Zq,
        Zr,
        Fz,
        Mw,
        Lw,
        gen,
        f,
    )
    for it in range(nt):
        if it + 1 < nt:
            slope = (r[it + 1] - r[it]) / dt
        else:
            slope = (r[it] - r[it - 1]) / dt
        xs[it] = x
        _deriv(x, r[it], slope, *args, k1)
        fs[it] = f
        acc[it] = k1[n : 2 * n]
        if it + 1 == nt:
            break
        for s in range(sub):
            r0 = r[it] + slope * (s * h)
            if s > 0:
                _deriv(x, r0, slope, *args, k1)
            for i in range(nx):
                xt[i] = x[i] + 0.5 * h * k1[i]
            _deriv(xt, r0 + 0.5 * h * slope, slope, *args, k2)
            for i in range(nx):
                xt[i] = x[i] + 0.5 * h * k2[i]
            _deriv(xt, r0 + 0.5 * h * slope, slope, *args, k3)
            for i in range(nx):
                xt[i] = x[i] + h * k3[i]
            _deriv(xt, r0 + h * slope, slope, *args, k4)
            for i in range(nx):
                x[i] = x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    return xs, fs, acc


def simulate_nonlinear(
    vehicle: LinearVehicle,
    r,
    dt: float,
    *,
    tyre_lift_off: bool = True,
    rebound: float = 1.0,
    compression: float = 1.0,
    substeps: int = 1,
    friction: float = 0.0,
    friction_velocity: float = 1e-3,
) -> NonlinearResult:
    """Simulate ``vehicle`` over wheel heights ``r`` (n_t, n_inputs) sampled every ``dt``.

    ``substeps`` Runge-Kutta steps per road sample. ``friction`` [N] is the Coulomb
    friction of every strut, regularised over ``friction_velocity`` [m/s]. Starts at rest in static equilibrium
    on the first road heights (computed with the linear model, where every tyre presses).
    """
    dt = check_positive("dt", dt, "s")
    r = np.ascontiguousarray(np.asarray(r, dtype=float))
    if r.ndim != 2 or r.shape[1] != len(vehicle.inputs) or r.shape[0] < 2:
        raise ParameterError("r", f"array of shape {r.shape}", f"(n_t >= 2, {len(vehicle.inputs)})")
    for name, val in (("rebound", rebound), ("compression", compression)):
        check_positive(name, val)
    if not isinstance(substeps, int) or substeps < 1:
        raise ParameterError("substeps", substeps, "an integer >= 1")
    check_nonnegative("friction", friction, "N")
    v_f = check_positive("friction_velocity", friction_velocity, "m/s")
    tables = _tables(
        vehicle, float(rebound), float(compression), bool(tyre_lift_off), float(friction), v_f
    )
    if friction > 0.0:
        # below v_f the friction is a damper of rate F_f / v_f: RK4 is stable for
        # h c / m < 2.78; the lightest mass of the model sets the limit
        M = vehicle.matrices(internal=True)[0]
        m_min = float(np.min(np.diag(M)[np.diag(M) > 0]))
        h_max = 2.0 * m_min * v_f / friction
        if dt / substeps > h_max:
            raise ParameterError(
                "substeps",
                substeps,
                f"at least {math.ceil(dt / h_max)}: the regularised friction "
                f"(rate {friction / v_f:.3g} N s/m) needs steps below {h_max:.3g} s; "
                "or raise friction_velocity",
            )
    A, Br, _, _, _, _ = vehicle.state_space()
    x0 = -np.linalg.solve(A, Br @ r[0])
    xs, fs, qdd = _run(x0, r, dt, substeps, *tables)
    n = len(vehicle.dofs)
    q, qd = xs[:, :n], xs[:, n : 2 * n]
    rdot = np.vstack([np.diff(r, axis=0) / dt, (r[-1:] - r[-2:-1]) / dt])
    outputs = {}
    for name, o in vehicle.outputs.items():
        if name.endswith("_tyre_load"):
            continue
        outputs[name] = q @ o.P + qd @ o.V + qdd @ o.G + r @ o.R + rdot @ o.S
    contact, lift = {}, {}
    for j, con in enumerate(vehicle.connections):
        if con.name.endswith("_tyre"):
            corner = con.name[: -len("_tyre")]
            total = tables[6][j] - fs[:, j]
            contact[corner] = total
            outputs[f"{corner}_tyre_load"] = total - tables[6][j]
            lift[corner] = float(np.mean(total <= 1e-9 * tables[6][j]))
    return NonlinearResult(
        time=dt * np.arange(r.shape[0]),
        outputs=outputs,
        contact_force=contact,
        lift_off_fraction=lift,
    )
