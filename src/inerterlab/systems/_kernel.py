"""The compiled right-hand side and outputs of every core system.

One function serves every network and system: the structure is data, read from two
tables (see :mod:`inerterlab.systems` for the public contract).

Integer table ``itab`` (int64): a header of :data:`HEADER` entries (counts and offsets,
the ``I_*`` indices), then one block of :data:`NODE_W` per node
(type, displacement state, velocity state, index within its type), one block of
:data:`ELEM_W` per primitive element (kernel code, top node, bottom node, offset of its
parameter row in ``ftab``, offset of its own states or -1) and the node lists of each
type. Float table ``ftab`` (float64): the node masses, the matrix that gives the
displacements of spring-only nodes from the others, and one row of
:data:`inerterlab.elements._base.NPAR` parameters per element.

Node types: ground (fixed), road (the prescribed input: displacement, velocity and
acceleration), dynamic (a mass or an inertance attached: displacement and velocity are
states), velocity (massless, no inertance, a damper attached: displacement is a state,
velocity follows from the force balance) and spring-only (massless, only springs:
displacement follows from the spring balance). An element's force F acts on its top
node as -F and on its bottom node as +F (a stretched spring pulls its ends together).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..elements._base import DAMPER, FRICTION, INERTER, NPAR, SPRING
from ..elements.adaptive_flywheel import flywheel_inertance, slider_derivative
from ..elements.damper import damper_force
from ..elements.friction import friction_force
from ..elements.inerter import inerter_inertance
from ..elements.spring import spring_force

GROUND, ROAD, DYN, VEL, POS = 0, 1, 2, 3, 4
NODE_W = 4
ELEM_W = 5
(
    I_NN, I_NE, I_ND, I_NV, I_NP, I_NS, I_NODE, I_ELEM, I_DYN, I_VEL, I_POS, I_FMASS, I_FR,
    I_NI,
) = range(14)  # fmt: skip
HEADER = 16
#: status of the velocity solve (written to the last slot of ``out`` by :func:`evaluate`)
SOLVE_OK, SOLVE_FAILED = 0, 1
_NO_IMPULSE = np.empty(0)
#: ``imp`` of :func:`evaluate` for the flow of a road velocity jump
ROAD_JERK = np.array([np.nan])


@nb.njit(cache=True)
def _solve(M, r, n):
    """Solve M x = r (n x n, row-major in M) in place by Gaussian elimination with partial
    pivoting; x in r. Returns False if M is singular."""
    for k in range(n):
        p = k
        big = abs(M[k * n + k])
        for i in range(k + 1, n):
            if abs(M[i * n + k]) > big:
                big = abs(M[i * n + k])
                p = i
        if big == 0.0 or not math.isfinite(big):
            return False
        if p != k:
            for j in range(n):
                tmp = M[k * n + j]
                M[k * n + j] = M[p * n + j]
                M[p * n + j] = tmp
            tmp = r[k]
            r[k] = r[p]
            r[p] = tmp
        piv = M[k * n + k]
        for i in range(k + 1, n):
            f = M[i * n + k] / piv
            if f != 0.0:
                for j in range(k + 1, n):
                    M[i * n + j] -= f * M[k * n + j]
                r[i] -= f * r[k]
    for k in range(n - 1, -1, -1):
        s = r[k]
        for j in range(k + 1, n):
            s -= M[k * n + j] * r[j]
        r[k] = s / M[k * n + k]
    return True


@nb.njit(cache=True)
def _dissipative(code, row, v):
    """(F, dF/dv) of a velocity-dependent element at relative velocity v."""
    if code == DAMPER:
        return damper_force(row, v)
    return friction_force(row[0], row[1], v)


@nb.njit(cache=True)
def _vel_residual(itab, ftab, X, V, G, J, nv, want_j):
    """Force balance G of the velocity nodes (and its Jacobian J if want_j)."""
    ne = itab[I_NE]
    eo = itab[I_ELEM]
    no = itab[I_NODE]
    for i in range(nv):
        G[i] = 0.0
    if want_j:
        for i in range(nv * nv):
            J[i] = 0.0
    for e in range(ne):
        b = eo + ELEM_W * e
        code = itab[b]
        top = itab[b + 1]
        bot = itab[b + 2]
        ti = itab[no + NODE_W * top + 3] if itab[no + NODE_W * top] == VEL else -1
        bi = itab[no + NODE_W * bot + 3] if itab[no + NODE_W * bot] == VEL else -1
        if ti < 0 and bi < 0:
            continue
        row = ftab[itab[b + 3] : itab[b + 3] + NPAR]
        if code == SPRING:
            f = spring_force(row, X[top] - X[bot])
            d = 0.0
        elif code == DAMPER or code == FRICTION:
            f, d = _dissipative(code, row, V[top] - V[bot])
        else:
            continue  # inertial elements never touch a velocity node
        if ti >= 0:
            G[ti] -= f
            if want_j:
                J[ti * nv + ti] -= d
                if bi >= 0:
                    J[ti * nv + bi] += d
        if bi >= 0:
            G[bi] += f
            if want_j:
                J[bi * nv + bi] -= d
                if ti >= 0:
                    J[bi * nv + ti] += d


def work_size(itab) -> int:
    """Length of the scratch array :func:`evaluate` takes as ``work`` (so that a caller
    evaluating many times allocates once)."""
    nd, ne, nv = int(itab[I_ND]), int(itab[I_NE]), int(itab[I_NV])
    return nd * nd + nd + ne + nv * nv + 3 * nv


@nb.njit(cache=True)
def _velocities(itab, ftab, X, V, work):
    """Velocities of the massless velocity nodes from their force balance (Newton; the
    balance is strictly decreasing in each node's velocity). Returns False on failure.
    ``work``: scratch of at least nv^2 + 3 nv floats."""
    nv = itab[I_NV]
    if nv == 0:
        return True
    vo = itab[I_VEL]
    G = work[0:nv]
    J = work[nv : nv + nv * nv]
    dv = work[nv + nv * nv : 2 * nv + nv * nv]
    v0 = work[2 * nv + nv * nv : 3 * nv + nv * nv]
    for i in range(nv):
        V[itab[vo + i]] = 0.0
    if nv == 1:
        # safeguarded Newton on a bracket (G is decreasing in v)
        n = itab[vo]
        lo = -math.inf
        hi = math.inf
        u = 0.0
        for _ in range(400):
            V[n] = u
            _vel_residual(itab, ftab, X, V, G, J, 1, True)
            g = G[0]
            if g > 0.0:
                lo = u
            elif g < 0.0:
                hi = u
            else:
                return True
            un = u - g / J[0] if J[0] < 0.0 else math.nan
            if not (lo < un < hi):
                if math.isfinite(lo) and math.isfinite(hi):
                    un = 0.5 * (lo + hi)
                else:
                    step = max(1.0, 2.0 * abs(u))
                    un = u + step if g > 0.0 else u - step
            if abs(un - u) <= 2e-16 * abs(un) + 1e-300:
                V[n] = un
                return True
            u = un
        V[n] = u
        return False
    # several nodes: Newton with backtracking on |G|
    for _it in range(200):
        _vel_residual(itab, ftab, X, V, G, J, nv, True)
        g2 = 0.0
        for i in range(nv):
            g2 += G[i] * G[i]
            dv[i] = -G[i]
            v0[i] = V[itab[vo + i]]
        if g2 == 0.0:
            return True
        if not _solve(J, dv, nv):
            return False
        step = 1.0
        done = False
        for _ in range(60):
            small = True
            for i in range(nv):
                V[itab[vo + i]] = v0[i] + step * dv[i]
                if abs(step * dv[i]) > 2e-16 * abs(v0[i]) + 1e-300:
                    small = False
            if small:
                return True
            _vel_residual(itab, ftab, X, V, G, J, nv, False)
            n2 = 0.0
            for i in range(nv):
                n2 += G[i] * G[i]
            if n2 < g2:
                done = True
                break
            step *= 0.5
        if not done:
            for i in range(nv):
                V[itab[vo + i]] = v0[i]
            return True
    return True


@nb.njit(cache=True)
def evaluate(t, x, road, itab, ftab, X, V, A, F, dx, imp, work=None):
    """Node displacements X, velocities V, accelerations A (NaN where not defined: the
    massless nodes), element forces F and the state derivative dx. Returns False if a
    balance could not be solved. With a non-empty ``imp`` (one impulse per dynamic node)
    dx is instead the impulse flow M(x)^-1 imp on the dynamic nodes' velocities (zero
    elsewhere): integrated over a unit interval it applies the impulse exactly, whatever
    the velocity dependence of the inertances. With ``imp`` = [NaN] (:data:`ROAD_JERK`)
    it is the flow of a road velocity jump: road[2] holds the jump, the forces are left
    out (finite, they pass no impulse in no time) and dx = M(x)^-1 (the inertances'
    coupling to the road times the jump); integrated over a unit interval with the road
    velocity moving linearly through the jump it applies the impulses the inertances on
    the road pass, whatever their velocity dependence. ``work``: scratch of
    :func:`work_size` floats, or None to allocate it here."""
    if work is None:
        work = np.empty(
            itab[I_ND] * itab[I_ND] + itab[I_ND] + itab[I_NE] + itab[I_NV] * itab[I_NV]
            + 3 * itab[I_NV]
        )  # fmt: skip
    nn = itab[I_NN]
    ne = itab[I_NE]
    nd = itab[I_ND]
    jerk = imp.size == 1 and math.isnan(imp[0])
    npn = itab[I_NP]
    no = itab[I_NODE]
    eo = itab[I_ELEM]
    fm = itab[I_FMASS]
    for n in range(nn):
        b = no + NODE_W * n
        typ = itab[b]
        A[n] = math.nan
        if typ == GROUND:
            X[n] = 0.0
            V[n] = 0.0
            A[n] = 0.0
        elif typ == ROAD:
            X[n] = road[0]
            V[n] = road[1]
            A[n] = road[2]
        elif typ == DYN:
            X[n] = x[itab[b + 1]]
            V[n] = x[itab[b + 2]]
        elif typ == VEL:
            X[n] = x[itab[b + 1]]
            V[n] = 0.0
        else:
            X[n] = 0.0
            V[n] = 0.0
    # spring-only nodes: X_p = R X (R has zero columns for spring-only nodes)
    po = itab[I_POS]
    fr = itab[I_FR]
    for i in range(npn):
        p = itab[po + i]
        s = 0.0
        for j in range(nn):
            s += ftab[fr + i * nn + j] * X[j]
        X[p] = s
    nde = nd * nd + nd + ne
    ok = _velocities(itab, ftab, X, V, work[nde:])
    for i in range(npn):
        p = itab[po + i]
        s = 0.0
        for j in range(nn):
            s += ftab[fr + i * nn + j] * V[j]
        V[p] = s
    # forces and the mass matrix of the dynamic nodes
    M = work[0 : nd * nd]
    r = work[nd * nd : nd * nd + nd]
    ME = work[nd * nd + nd : nde]
    for i in range(nde):
        work[i] = 0.0
    for n in range(nn):
        b = no + NODE_W * n
        if itab[b] == DYN:
            k = itab[b + 3]
            M[k * nd + k] += ftab[fm + n]
    for e in range(ne):
        b = eo + ELEM_W * e
        code = itab[b]
        top = itab[b + 1]
        bot = itab[b + 2]
        row = ftab[itab[b + 3] : itab[b + 3] + NPAR]
        v = V[top] - V[bot]
        me = 0.0
        if code == SPRING:
            f = spring_force(row, X[top] - X[bot])
        elif code == DAMPER or code == FRICTION:
            f, _ = _dissipative(code, row, v)
        elif code == INERTER:
            f = 0.0
            me = inerter_inertance(row)
        else:
            so = itab[b + 4]
            if so >= 0:
                me, f = flywheel_inertance(ftab, itab[b + 3], v, x[so], x[so + 1])
                dx[so] = x[so + 1]
                dx[so + 1] = slider_derivative(row, x[so], x[so + 1], v)
            else:
                me, f = flywheel_inertance(ftab, itab[b + 3], v, 0.0, 0.0)
        if jerk:
            f = 0.0
        F[e] = f
        ME[e] = me
        tb = no + NODE_W * top
        bb = no + NODE_W * bot
        ti = itab[tb + 3] if itab[tb] == DYN else -1
        bi = itab[bb + 3] if itab[bb] == DYN else -1
        if ti >= 0:
            r[ti] -= f
        if bi >= 0:
            r[bi] += f
        if me != 0.0:
            if ti >= 0:
                M[ti * nd + ti] += me
                if bi >= 0:
                    M[ti * nd + bi] -= me
                else:
                    r[ti] += me * A[bot]
            if bi >= 0:
                M[bi * nd + bi] += me
                if ti >= 0:
                    M[bi * nd + ti] -= me
                else:
                    r[bi] += me * A[top]
    if imp.size > 0 and not jerk:
        for i in range(nd):
            r[i] = imp[i]
    if nd > 0 and not _solve(M, r, nd):
        ok = False
    for n in range(nn):
        b = no + NODE_W * n
        typ = itab[b]
        if typ == DYN:
            A[n] = r[itab[b + 3]]
            dx[itab[b + 1]] = V[n]
            dx[itab[b + 2]] = A[n]
        elif typ == VEL:
            dx[itab[b + 1]] = V[n]
    if imp.size > 0:
        for i in range(x.size):
            if i >= itab[I_NS] - itab[I_NI]:
                dx[i] = 0.0
        for n in range(nn):
            b = no + NODE_W * n
            if itab[b] == DYN:
                dx[itab[b + 1]] = 0.0
            elif itab[b] == VEL:
                dx[itab[b + 1]] = 0.0
        return ok
    for e in range(ne):
        if ME[e] != 0.0:
            b = eo + ELEM_W * e
            F[e] += ME[e] * (A[itab[b + 1]] - A[itab[b + 2]])
    return ok


@nb.njit(cache=True)
def rhs(t, x, road, itab, ftab, out):
    """out = dx/dt at time t, state x, road (displacement, velocity, acceleration).

    Returns True, or False where a force balance could not be solved."""
    nn = itab[I_NN]
    ne = itab[I_NE]
    X = np.empty(nn)
    V = np.empty(nn)
    A = np.empty(nn)
    F = np.empty(ne)
    return evaluate(t, x, road, itab, ftab, X, V, A, F, out, _NO_IMPULSE)


@nb.njit(cache=True)
def outputs(t, x, road, itab, ftab, out):
    """out = [X (nodes), V (nodes), A (nodes, NaN at massless nodes), F (elements)]."""
    nn = itab[I_NN]
    ne = itab[I_NE]
    X = np.empty(nn)
    V = np.empty(nn)
    A = np.empty(nn)
    F = np.empty(ne)
    dx = np.empty(x.size)
    ok = evaluate(t, x, road, itab, ftab, X, V, A, F, dx, _NO_IMPULSE)
    for i in range(nn):
        out[i] = X[i]
        out[nn + i] = V[i]
        out[2 * nn + i] = A[i]
    for e in range(ne):
        out[3 * nn + e] = F[e]
    return ok
