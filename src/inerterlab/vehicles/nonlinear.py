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
  uses); the accelerations follow by the Woodbury identity from the inverse of the
  mass matrix with every flywheel saturated, so only the flywheels below saturation
  enter a small system (at most 4 x 4 for four adaptive corners) at a stage. ``thesis`` and ``momentum`` make the force from the
  inertance alone (no extra velocity-squared term), so the mass matrix carries it all.
* **Devices.** A strut's device (``Strut.device``, :mod:`inerterlab.vehicles.devices`):
  its parts straight across the strut are in the matrices above; the rest is a core rig
  driven by the strut's extension, whose states join the vehicle's and whose force adds
  to the strut's. Its fastest rate at rest must be resolved by the step (checked).
* **Strut friction.** A Coulomb force of size ``friction`` against the strut's
  extension rate, regularised as F_f tanh(delta' / v_f) with ``friction_velocity``
  v_f (default 1 mm/s): below v_f the friction acts as a damper of rate F_f / v_f, so
  the equations stay an ODE an explicit method can integrate; the step must resolve
  m / (F_f / v_f) (checked).

Coordinates, outputs and their units are those of the linear model, measured from
static equilibrium; constant inerters keep the mass matrix constant. The equations are
integrated by the classical fourth-order Runge-Kutta method with a fixed step,
compiled with numba. A road of samples is linear between them (so the road velocity is
constant on each sample interval and the steps never straddle a change of slope); a
generated road (:class:`~inerterlab.vehicles.spectral.StageRoad`) is read exactly, its
height and rate at every stage time. Outputs are sampled at the road samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..elements._base import NPAR
from ..elements.adaptive_flywheel import flywheel_inertance
from ..errors import ParameterError, check_nonnegative, check_positive
from ..systems._kernel import I_NN, evaluate
from .model import LinearVehicle

__all__ = ["NonlinearResult", "simulate_nonlinear"]


@dataclass(frozen=True)
class NonlinearResult:
    """Outputs (name -> array over the road samples), contact forces and, per corner,
    the fraction of all samples (the start-up included) with the tyre off the road."""

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
        adaptive = getattr(con.law, "adaptive_inerter", None)
        if adaptive is not None:
            afw.append(j)
            rows.append(adaptive.row())
            me0.append(adaptive.inertance_min)
    afw = np.array(afw, dtype=np.uint64)
    rows = np.array(rows, dtype=float).reshape(len(afw), -1) if len(afw) else np.zeros((0, NPAR))
    rows = rows.ravel()
    me0 = np.array(me0, dtype=float)
    Ua = U[afw]
    # the base mass matrix holds every adaptive inerter at its saturated inertance
    # (computed by the kernel's own law, so a saturated flywheel's departure from it
    # is exactly zero and drops out of the Woodbury system)
    mb = _base_inertance(rows, me0)
    M = M + (Ua.T * (mb - me0)) @ Ua
    Minv = np.linalg.inv(M)
    W = np.ascontiguousarray(Minv @ Ua.T)
    S = np.ascontiguousarray(Ua @ Minv @ Ua.T)
    dev = _device_tables(vehicle, 2 * M.shape[0] + Az.shape[0])
    devof = dev[0]
    # the linear part of every connection (damping rate c_ext) as one matrix on
    # (q, q', r, r'); the connections that depart from it are evaluated one by one
    # and corrected through M^-1 u: tyres (whose forces are returned), asymmetric or
    # rubbing struts, devices
    G = Minv @ np.hstack([-(U.T * k) @ U, -(U.T * c_ext) @ U, (U.T * k) @ V, (U.T * c_ext) @ V])
    tyre = np.array([con.name.endswith("_tyre") for con in vehicle.connections], dtype=bool)
    departs = tyre | (c_ext != c_cmp) | (fric != 0.0) | (devof >= 0)
    nl = np.flatnonzero(departs).astype(np.uint64)
    MU = np.ascontiguousarray((Minv @ U[nl].T).T) if nl.size else np.zeros((0, M.shape[0]))
    MFz = np.ascontiguousarray(Minv @ Fz)
    args = (np.ascontiguousarray(G), nl, MU, *_csr(U), *_csr(V), k, c_ext, c_cmp, preload,
            unilateral, fric, fv, afw, rows, me0, mb, W, S, Az, Zq, Zr, MFz, *dev)  # fmt: skip
    return args, nl, preload


def _device_tables(vehicle: LinearVehicle, offset: int):
    """The rig parts of the corners' devices, packed for the kernel: per connection the
    device index or -1; the devices' integer and float tables concatenated with their
    offsets; each device's first state in x (from ``offset``, the end of the vehicle's
    own states; the last entry is the end); the elements at its driven terminal (CSR
    rows of indices and signs); and the largest node count, element count and
    work size of :func:`~inerterlab.systems._kernel.evaluate`."""
    from ..systems import _kernel

    devof = np.full(len(vehicle.connections), -1, dtype=np.int64)
    itabs, ftabs = [], []
    ioff, foff, xoff, dptr, delem, dsign = [0], [0], [offset], [0], [], []
    size = np.zeros(3, dtype=np.int64)
    index = {id(con): j for j, con in enumerate(vehicle.connections)}
    for con, dev in vehicle.nonlinear_devices():
        devof[index[id(con)]] = len(itabs)
        itab, ftab = dev.system.tables
        itabs.append(itab)
        ftabs.append(ftab)
        ioff.append(ioff[-1] + itab.size)
        foff.append(foff[-1] + ftab.size)
        xoff.append(xoff[-1] + dev.n_states)
        for e, sign in dev.drive_elements:
            delem.append(e)
            dsign.append(sign)
        dptr.append(len(delem))
        size[0] = max(size[0], int(itab[_kernel.I_NN]))
        size[1] = max(size[1], int(itab[_kernel.I_NE]))
        size[2] = max(size[2], _kernel.work_size(itab))
    cat_i = np.concatenate(itabs) if itabs else np.zeros(0, dtype=np.int64)
    cat_f = np.concatenate(ftabs) if ftabs else np.zeros(0)
    return (devof, cat_i.astype(np.int64), cat_f, np.array(ioff, dtype=np.int64),
            np.array(foff, dtype=np.int64), np.array(xoff, dtype=np.int64),
            np.array(dptr, dtype=np.int64), np.array(delem, dtype=np.int64),
            np.array(dsign, dtype=float), size)  # fmt: skip


@njit(cache=True)
def _base_inertance(rows, me0):
    """Inertance [kg] of each adaptive inerter above its flywheel's saturation speed
    (its rest inertance where the flywheel never saturates), by the kernel's law."""
    na = me0.size
    out = me0.copy()
    for jj in range(na):
        o = jj * NPAR
        w_sat = rows[o + 8]
        r = abs(rows[o + 1])
        if math.isfinite(w_sat) and r > 0.0:
            out[jj], _ = flywheel_inertance(rows, o, 2.0 * w_sat / r + 1.0, 0.0, 0.0)
    return out


def _csr(U):
    """(row pointers, column indices, values) of the nonzeros of ``U``, rows in order."""
    ptr, idx, val = [0], [], []
    for row in U:
        nz = np.flatnonzero(row)
        idx.extend(nz.tolist())
        val.extend(row[nz].tolist())
        ptr.append(len(idx))
    return (np.array(ptr, dtype=np.uint64), np.array(idx, dtype=np.uint64),
            np.array(val, dtype=float))  # fmt: skip


@njit(cache=True, error_model="numpy", fastmath={"reassoc", "contract"})
def _linear_part(G, gs, xt, rs, out, n, m):
    """out[:n] = q', out[n:2n] = G (q, q', r) + gs: the accelerations of every
    connection's linear part (gs the road-rate part). A leaf (it calls no compiled
    function), so its fastmath flags cannot reach another kernel's callees
    (tests/test_numba_flags.py): the sums may be vectorised, round-off only."""
    n2 = 2 * n
    for a in range(n):
        out[a] = xt[n + a]
        t = gs[a]
        for b in range(n2):
            t += G[a, b] * xt[b]
        for i in range(m):
            t += G[a, n2 + i] * rs[i]
        out[n + a] = t


@njit(cache=True)
def _run(x0, r, dt, sub, rf, vf, G, nl, MU, uptr, uidx, uval, vptr, vidx, vval, k, c_ext, c_cmp,
         preload, unilateral, fric, fv, afw, rows, me0, mb, W, S, Az, Zq, Zr, MFz, devof, ditab,
         dftab, ioff, foff, xoff, dptr, delem, dsign, dsize, optr, oidx, oval):  # fmt: skip
    """RK4 over the road samples; the road linear between them, or, when ``rf`` has
    rows, read at every stage from ``rf`` (heights) and ``vf`` (rates) given every half
    step (a road known exactly between its samples, :class:`~.spectral.StageRoad`); returns (tensions of the connections ``nl``, outputs)
    at every sample, the outputs y = CY x + CA q'' + CR r + CS r' (r' the sample's
    slope), given as sparse rows (optr, oidx, oval) over z = (x, q'', r, r').

    One function with the right-hand side written once inside the stage loop: a call
    per stage passing some thirty arrays cost three times the arithmetic (measured,
    docs/decisions.md). The accelerations at the base mass matrix Mb (every adaptive
    inerter at its saturated inertance m_b) are
    y = G (q, q', r, r') - Mb^-1 Fz z + sum_j Mb^-1 u_j (f_lin,j - f_j): G carries every
    connection as linear (damping rate c_ext), and the connections ``nl`` that depart
    from that (tyres, asymmetric or rubbing struts, devices) are evaluated one by one,
    f_j their force, f_lin,j its linear part, Mb^-1 u_j the rows of MU. Connections are
    sparse rows (CSR: uptr, uidx, uval of u; vptr, vidx, vval of v), indexed unsigned
    (numba then skips the negative-index wraparound). Adaptive inerters change the
    mass matrix by sum_j d_j u_j u_j^T, d_j = max(m_e,j(v_j), m_e,j(0)) - m_b,j, zero
    for a saturated flywheel; the accelerations follow by the Woodbury identity over
    the inerters with d_j != 0 only: a = y - W w, (I + D S) w = D U y, with
    W = Mb^-1 U^T and S = U Mb^-1 U^T (precomputed over all adaptive connections, the
    rows and columns of the active ones picked), the small system factorised by LU
    without pivoting (its leading minors are ratios of determinants of mass matrices,
    all positive), and the factors kept while the active set and D stay the same.
    Devices (:mod:`inerterlab.vehicles.devices`): the core rig of connection j, driven
    by its extension and rate, gives its states' derivatives and a force added to the
    connection's (the core's compiled :func:`~inerterlab.systems._kernel.evaluate`).
    Returns also a status: 0, or 1 + the sample where a device's balance failed.
    """
    n = MU.shape[1]
    nu = np.uint64(n)
    n2 = 2 * n
    nt = r.shape[0]
    m = r.shape[1]
    nx = x0.size
    nz = Az.shape[0]
    nn = nl.size
    fs = np.empty((nt, nn))
    no = optr.size - 1
    zo = np.empty(nx + n + 2 * m)
    ys = np.empty((nt, no))
    x = x0.copy()
    h = dt / sub
    f = np.empty(max(nn, 1))
    K = np.empty((4, nx))
    xt = np.empty(nx)
    na = afw.size
    Mw = np.empty(max(na * na, 1))
    dg = np.empty(max(na, 1))  # D: m_e - m_e,sat of the inerters below saturation
    rd = np.empty(max(na, 1))
    dgf = np.full(max(na, 1), np.nan)  # D of the factor in Mw, rd (NaN: none yet)
    act = np.zeros(max(na, 1), dtype=np.int64)  # the inerters below saturation
    actf = np.full(max(na, 1), -1, dtype=np.int64)  # ... of the factor
    kf = 0
    gen = np.empty(max(na, 1))
    slope = np.empty(m)
    rs = np.empty(m)
    gs = np.empty(n)
    DW = np.empty(dsize[2])
    road3 = np.zeros(3)
    noimp = np.empty(0)
    status = 0
    exact = rf.shape[0] > 0
    for it in range(nt):
        last = it + 1 == nt
        if not exact:
            for i in range(m):
                if not last:
                    slope[i] = (r[it + 1, i] - r[it, i]) / dt
                else:
                    slope[i] = (r[it, i] - r[it - 1, i]) / dt
            for a in range(n):  # the road-rate part of the linear accelerations
                t = 0.0
                for i in range(m):
                    t += G[a, n2 + m + i] * slope[i]
                gs[a] = t
        for s in range(sub):
            for st in range(4):
                if last and (s > 0 or st > 0):
                    break
                cst = 0.0 if st == 0 else (1.0 if st == 3 else 0.5)
                if exact:
                    row = (it * sub + s) * 2 + (0 if st == 0 else (2 if st == 3 else 1))
                    for i in range(m):
                        rs[i] = rf[row, i]
                        slope[i] = vf[row, i]
                    for a in range(n):
                        t = 0.0
                        for i in range(m):
                            t += G[a, n2 + m + i] * slope[i]
                        gs[a] = t
                else:
                    for i in range(m):
                        rs[i] = r[it, i] + slope[i] * (s * h)
                        if st > 0:
                            rs[i] = rs[i] + cst * h * slope[i]
                if st == 0:
                    for i in range(nx):
                        xt[i] = x[i]
                else:
                    for i in range(nx):
                        xt[i] = x[i] + cst * h * K[st - 1, i]
                # ---- right-hand side at (xt, rs, slope) into K[st] ----
                _linear_part(G, gs, xt, rs, K[st], n, m)
                for a in range(nz):
                    t = 0.0
                    for b in range(nz):
                        t += Az[a, b] * xt[n2 + b]
                    for b in range(n):
                        t += Zq[a, b] * xt[b]
                    for b in range(m):
                        t -= Zr[a, b] * rs[b]
                    K[st, n2 + a] = t
                    for i in range(n):
                        K[st, n + i] -= MFz[i, a] * xt[n2 + a]
                for jj in range(nn):
                    j = nl[jj]
                    d = 0.0
                    dd = 0.0
                    for p in range(uptr[j], uptr[j + 1]):
                        i = uidx[p]
                        d += uval[p] * xt[i]
                        dd += uval[p] * xt[nu + i]
                    for p in range(vptr[j], vptr[j + 1]):
                        i = vidx[p]
                        d -= vval[p] * rs[i]
                        dd -= vval[p] * slope[i]
                    kd = k[j] * d
                    ce = c_ext[j]
                    cm = c_cmp[j]  # both loaded: a select, not a branch on the sign of dd
                    flin = kd + ce * dd
                    fj = kd + (cm if dd <= 0.0 else ce) * dd
                    if fric[j] != 0.0:
                        fj += fric[j] * math.tanh(dd / fv[0])
                    dv = devof[j]
                    if dv >= 0:
                        road3[0] = d
                        road3[1] = dd
                        a0 = xoff[dv]
                        a1 = xoff[dv + 1]
                        ok = evaluate(0.0, xt[a0:a1], road3, ditab[ioff[dv] : ioff[dv + 1]],
                                      dftab[foff[dv] : foff[dv + 1]], DW, K[st, a0:a1],
                                      noimp)  # fmt: skip
                        if not ok and status == 0:
                            status = it + 1
                        fo = 3 * ditab[ioff[dv] + I_NN]  # the element forces in DW
                        for p in range(dptr[dv], dptr[dv + 1]):
                            fj += dsign[p] * DW[fo + delem[p]]
                    if unilateral[j] == 1 and preload[j] - fj < 0.0:
                        fj = preload[j]
                    f[jj] = fj
                    delta = flin - fj
                    if delta != 0.0:
                        for a in range(n):
                            K[st, n + a] += MU[jj, a] * delta
                if na > 0:
                    # Woodbury: (Mb + U' D U)^-1 g = y - W w, y = Mb^-1 g (above),
                    # w = (I + D S)^-1 D U y, W = Mb^-1 U', S = U Mb^-1 U', Mb the mass
                    # matrix with every flywheel saturated, D = m_e - m_e,sat: only the
                    # inerters whose flywheel is below saturation (D != 0) enter. Every
                    # leading block of I + D S has det(Mb + U_p' D_p U_p) / det(Mb) > 0
                    # (a mass matrix with inertances >= the rest ones), so LU without
                    # pivoting meets positive pivots (L below the diagonal of Mw, U
                    # above, 1/pivots in rd); factors kept while the set and D stay
                    kk = 0
                    for jj in range(na):
                        j = afw[jj]
                        v = 0.0
                        for p in range(uptr[j], uptr[j + 1]):
                            v += uval[p] * xt[nu + uidx[p]]
                        me, _ = flywheel_inertance(rows, jj * NPAR, v, 0.0, 0.0)
                        dj = max(me, me0[jj]) - mb[jj]
                        if dj != 0.0:
                            uy = 0.0
                            for p in range(uptr[j], uptr[j + 1]):
                                uy += uval[p] * K[st, nu + uidx[p]]
                            act[kk] = jj
                            dg[kk] = dj
                            gen[kk] = dj * uy
                            kk += 1
                    if kk > 0:
                        same = kk == kf
                        for a in range(kk):
                            if act[a] != actf[a] or dg[a] != dgf[a]:
                                same = False
                            actf[a] = act[a]
                            dgf[a] = dg[a]
                        kf = kk
                        if not same:
                            for a in range(kk):
                                for b in range(kk):
                                    Mw[a * kk + b] = dg[a] * S[act[a], act[b]] + (
                                        1.0 if a == b else 0.0
                                    )
                            for q in range(kk):
                                piv = 1.0 / Mw[q * kk + q]
                                rd[q] = piv
                                for a in range(q + 1, kk):
                                    el = Mw[a * kk + q] * piv
                                    Mw[a * kk + q] = el
                                    for b in range(q + 1, kk):
                                        Mw[a * kk + b] -= el * Mw[q * kk + b]
                        for a in range(kk):  # forward (unit lower), then back substitution
                            t = gen[a]
                            for q in range(a):
                                t -= Mw[a * kk + q] * gen[q]
                            gen[a] = t
                        for a in range(kk - 1, -1, -1):
                            t = gen[a]
                            for q in range(a + 1, kk):
                                t -= Mw[a * kk + q] * gen[q]
                            gen[a] = t * rd[a]
                        for a in range(n):
                            t = K[st, n + a]
                            for q in range(kk):
                                t -= W[a, act[q]] * gen[q]
                            K[st, n + a] = t
                # ---- end ----
                if s == 0 and st == 0:
                    for jj in range(nn):
                        fs[it, jj] = f[jj]
                    for i in range(nx):
                        zo[i] = x[i]
                    for i in range(n):
                        zo[nx + i] = K[0, n + i]
                    for i in range(m):
                        zo[nx + n + i] = r[it, i]
                        zo[nx + n + m + i] = slope[i]
                    for o in range(no):
                        t = 0.0
                        for p in range(optr[o], optr[o + 1]):
                            t += oval[p] * zo[oidx[p]]
                        ys[it, o] = t
            if last:
                break
            for i in range(nx):
                x[i] = x[i] + h / 6.0 * (K[0, i] + 2.0 * K[1, i] + 2.0 * K[2, i] + K[3, i])
    return fs, ys, status


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

    ``r`` is either an array, joined by straight lines between its samples, or a
    :class:`~inerterlab.vehicles.spectral.StageRoad` (a generated road, exact at every
    Runge-Kutta stage; its ``dt`` and ``substeps`` must be these).
    ``substeps`` Runge-Kutta steps per road sample. ``friction`` [N] is the Coulomb
    friction of every strut, regularised over ``friction_velocity`` [m/s]. Starts at rest in static equilibrium
    on the first road heights (computed with the linear model, where every tyre presses).
    """
    from .spectral import StageRoad

    dt = check_positive("dt", dt, "s")
    if isinstance(r, StageRoad):
        if r.substeps != substeps or not math.isclose(r.dt, dt, rel_tol=1e-12):
            raise ParameterError(
                "substeps/dt",
                (substeps, dt),
                f"those the road was evaluated for ({r.substeps}, {r.dt:g} s)",
            )
        rf = np.ascontiguousarray(r.heights, dtype=float)
        vf = np.ascontiguousarray(r.rates, dtype=float)
        r = np.ascontiguousarray(r.samples, dtype=float)
    else:
        r = np.ascontiguousarray(np.asarray(r, dtype=float))
        rf = vf = np.zeros((0, r.shape[1] if r.ndim == 2 else 1))
    if r.ndim != 2 or r.shape[1] != len(vehicle.inputs) or r.shape[0] < 2:
        raise ParameterError("r", f"array of shape {r.shape}", f"(n_t >= 2, {len(vehicle.inputs)})")
    for name, val in (("rebound", rebound), ("compression", compression)):
        check_positive(name, val)
    if not isinstance(substeps, int) or substeps < 1:
        raise ParameterError("substeps", substeps, "an integer >= 1")
    check_nonnegative("friction", friction, "N")
    v_f = check_positive("friction_velocity", friction_velocity, "m/s")
    tables, nl, preload = _tables(
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
    A, Br, _, _, _, _ = vehicle.state_space(devices=True)
    from .statics import rest_state

    x0 = rest_state(vehicle, A, Br, r[0])
    n = len(vehicle.dofs)
    for con, dev in vehicle.nonlinear_devices():
        rate = dev.fastest_rate()
        if rate * dt / substeps > 2.5:  # RK4 is stable for |h lambda| < 2.78 (real axis)
            raise ParameterError(
                "substeps",
                substeps,
                f"at least {math.ceil(rate * dt / 2.5)}: the device at {con.name} "
                f"({dev.source}) has a rate of {rate:.4g} 1/s, which needs steps below "
                f"{2.5 / rate:.3g} s",
            )
        extension = float(con.u @ x0[:n] - con.v @ r[0])
        x0 = np.concatenate([x0, dev.initial_state(extension)])
    nz = x0.size - 2 * n
    names = [k for k in vehicle.outputs if not k.endswith("_tyre_load")]
    outs = [vehicle.outputs[k] for k in names]
    CY = np.array([np.concatenate([o.P, o.V, np.zeros(nz)]) for o in outs]).reshape(len(outs), -1)
    CA = np.array([o.G for o in outs]).reshape(len(outs), n)
    CR = np.array([o.R for o in outs]).reshape(len(outs), r.shape[1])
    CS = np.array([o.S for o in outs]).reshape(len(outs), r.shape[1])
    fs, Y, status = _run(x0, r, dt, substeps, rf, vf, *tables, *_csr(np.hstack([CY, CA, CR, CS])))
    if status:
        raise ParameterError(
            "substeps",
            substeps,
            f"more: a device's force balance could not be solved at t = {(status - 1) * dt:.6g} s",
        )
    outputs = {k: Y[:, i] for i, k in enumerate(names)}
    contact, lift = {}, {}
    for col, j in enumerate(nl.tolist()):
        con = vehicle.connections[j]
        if con.name.endswith("_tyre"):
            corner = con.name[: -len("_tyre")]
            total = preload[j] - fs[:, col]
            contact[corner] = total
            outputs[f"{corner}_tyre_load"] = total - preload[j]
            lift[corner] = float(np.mean(total <= 1e-9 * preload[j]))
    return NonlinearResult(
        time=dt * np.arange(r.shape[0]),
        outputs=outputs,
        contact_force=contact,
        lift_off_fraction=lift,
    )
