"""Time simulation of a vehicle with tyre lift-off and asymmetric dampers.

The linear model of :mod:`inerterlab.vehicles.model` with two departures, each a
property of a connection:

* **Tyre lift-off.** The contact force is F0 - k_t delta - c_t delta' (F0 the static
  load, delta = wheel - road the tyre extension from equilibrium); a tyre cannot pull,
  so the force is max(0, that). The linear model lets it go negative.
* **Asymmetric dampers.** A strut's damping is ``rebound`` x c while it extends and
  ``compression`` x c while it shortens (both 1: the linear strut).
* **Strut friction.** A Coulomb force of size ``friction`` against the strut's
  extension rate, regularised as F_f tanh(delta' / v_f) with ``friction_velocity``
  v_f (default 1 mm/s): below v_f the friction acts as a damper of rate F_f / v_f, so
  the equations stay an ODE an explicit method can integrate; the step must resolve
  m / (F_f / v_f) (checked).

Coordinates, outputs and their units are those of the linear model, measured from
static equilibrium; the inerters keep the mass matrix constant. The equations are
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
    M, _, _, _, _ = vehicle.matrices()
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
            c_ext[j], c_cmp[j] = rebound * c, compression * c
            fric[j] = friction
        if con.name.endswith("_tyre"):
            preload[j] = static[con.name[: -len("_tyre")]]
            unilateral[j] = 1 if lift_off else 0
    fv = np.array([friction_velocity])
    return np.linalg.inv(M), U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv


@njit(cache=True)
def _forces(q, qd, r, rd, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv, out_f):
    """Generalised forces; ``out_f`` receives each connection's tension."""
    n = q.size
    gen = np.zeros(n)
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
def _deriv(x, rr, rd, Minv, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv, f, out):
    n = Minv.shape[0]
    gen = _forces(x[:n], x[n:], rr, rd, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv, f)
    out[:n] = x[n:]
    out[n:] = Minv @ gen


@njit(cache=True)
def _run(x0, r, dt, sub, Minv, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv):
    n = Minv.shape[0]
    nt = r.shape[0]
    xs = np.empty((nt, 2 * n))
    fs = np.empty((nt, U.shape[0]))
    x = x0.copy()
    h = dt / sub
    f = np.empty(U.shape[0])
    k1 = np.empty(2 * n)
    k2 = np.empty(2 * n)
    k3 = np.empty(2 * n)
    k4 = np.empty(2 * n)
    args = (Minv, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv, f)
    for it in range(nt):
        if it + 1 < nt:
            slope = (r[it + 1] - r[it]) / dt
        else:
            slope = (r[it] - r[it - 1]) / dt
        xs[it] = x
        _forces(x[:n], x[n:], r[it], slope, U, V, k, c_ext, c_cmp, preload, unilateral, fric, fv, f)
        fs[it] = f
        if it + 1 == nt:
            break
        for s in range(sub):
            r0 = r[it] + slope * (s * h)
            _deriv(x, r0, slope, *args, k1)
            _deriv(x + 0.5 * h * k1, r0 + 0.5 * h * slope, slope, *args, k2)
            _deriv(x + 0.5 * h * k2, r0 + 0.5 * h * slope, slope, *args, k3)
            _deriv(x + h * k3, r0 + h * slope, slope, *args, k4)
            x = x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return xs, fs


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
        M = vehicle.matrices()[0]
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
    xs, fs = _run(x0, r, dt, substeps, *tables)
    n = len(vehicle.dofs)
    q, qd = xs[:, :n], xs[:, n:]
    Minv, U = tables[0], tables[1]
    gen = -(fs @ U)  # generalised forces at the samples
    qdd = gen @ Minv.T
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
