"""The compiled right-hand side and outputs of every core system.

One function serves every network and system: the structure is data, read from two
tables (see :mod:`inerterlab.systems` for the public contract).

Integer table ``itab`` (int64): a header of :data:`HEADER` entries (counts and offsets,
the ``I_*`` indices; ``I_DNS``: where the factored mass matrix's entry starts, 0 for
none, :func:`dense_tables`), then one block of :data:`NODE_W` per node
(type, displacement state, velocity state, index within its type, reference node of its
floating inertance component or -1), one block of
:data:`ELEM_W` per primitive element (kernel code, top node, bottom node, offset of its
parameter row in ``ftab``, offset of its own states or -1, and the rows of its top and
bottom nodes in the mass matrix, or -1 where they have none) and the node lists of each
type. Float table ``ftab`` (float64): the node masses, the matrix that gives the
displacements of spring-only nodes from the others, and one row of
:data:`inerterlab.elements._base.NPAR` parameters per element.

Node types: ground (fixed), road (the prescribed input: displacement, velocity and
acceleration), dynamic (a mass or an inertance attached: displacement and velocity are
states), velocity (massless, no inertance, a damper attached: displacement is a state,
velocity follows from the force balance) and spring-only (massless, only springs:
displacement follows from the spring balance). An element's force F acts on its top
node as -F and on its bottom node as +F (a stretched spring pulls its ends together).

Floating inertance components: massless nodes joined by inertances to each other only
(no mass, no terminal), as in a series chain of members that each hold an inerter
between two springs. Their common motion carries no inertia: it is set by the force
balance of the whole component, like a massless node. One node of the component, the
reference, is a velocity node (dampers attached to the component; its balance sums the
forces on every node of the component) or a spring-only node (springs only). The others
are relative nodes (type REL): their displacement and velocity relative to the
reference are states, and their accelerations relative to it follow from the mass
matrix with the reference taken as fixed (the inertances act on relative motion only).
Floating damper components, massless velocity nodes joined by dampers to each other
only, are split the same way: the reference is a spring-only node (the springs set the
common motion), the others relative velocity nodes (type RELV: the displacement
relative to the reference is a state, the relative velocity solves the node's balance,
in which only dampers inside the component act).

Bodies with several coordinates (:mod:`inerterlab.systems.vehicle`): a body's coordinates
(bounce, pitch, roll) are dynamic nodes whose masses are its mass and moments of
inertia; an attachment point is a combination node (type LIN), its displacement a fixed
linear combination sum c_j X_j of dynamic nodes (block: type, offset of the member list
in ``itab``, member count, offset of the coefficients in ``ftab``, -1). An element with
an end at a combination node (its mass-matrix row -2) passes its force to the members
by the coefficients and stamps its inertance as me g g^T, g the combination of its end
rows, so the mass matrix couples the coordinates. A road node's block holds the index k
of its road: its displacement, velocity and acceleration are road[3k:3k+3]
(:func:`road_layout`; the header's ``I_NRD`` counts the roads).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._views import readonly
from ..elements._base import DAMPER, FLYWHEEL, FRICTION, INERTER, SPRING, TYRE
from ..elements._inertial import (
    inertial_law,
    inertial_rate,
    inertial_switch,
    inertial_switch_reads_force,
)
from ..elements.adaptive_flywheel import factor_inertance
from ..elements.damper import damper_force
from ..elements.friction import friction_force
from ..elements.inerter import inerter_inertance
from ..elements.spring import spring_force, spring_slope, spring_switch
from ..elements.tyre import tyre_force, tyre_switch

GROUND, ROAD, DYN, VEL, POS, REL, RELV, LIN = 0, 1, 2, 3, 4, 5, 6, 7
NODE_W = 5
ELEM_W = 7
(
    I_NN, I_NE, I_ND, I_NV, I_NP, I_NS, I_NODE, I_ELEM, I_DYN, I_VEL, I_POS, I_FMASS, I_FR,
    I_NI, I_NR, I_NL, I_NRD, I_NOB, I_OBS, I_NSG, I_SG, I_SGF, I_DNS,
) = range(23)  # fmt: skip
HEADER = 23
#: observers (see :func:`observe`): the width of an observer row in ``itab`` and the
#: kinds. A state observer q (its state ``y[slot]``) integrates q' = a (``OBS_LINEAR``,
#: a filter state when a reads other observer states), a^2, a^4 or a b of its signals
#: a and b; ``OBS_PEAK`` keeps the running maximum of a in y[slot] (derivative 0, set
#: after each accepted step)
OBS_W = 4
OBS_LINEAR, OBS_SQUARE, OBS_FOURTH, OBS_PRODUCT, OBS_PEAK = 0, 1, 2, 3, 4
#: status of the velocity solve (written to the last slot of ``out`` by :func:`evaluate`)
SOLVE_OK, SOLVE_FAILED = 0, 1
_NO_IMPULSE = np.empty(0)
#: ``imp`` of :func:`evaluate` for the flow of a road velocity jump
ROAD_JERK = np.array([np.nan])
#: ``imp`` of :func:`evaluate` for the switching functions alone, from the nodes' motion
#: (:func:`switches_at`), into ``dx``
SWITCHES_ONLY = np.array([np.inf])
#: ``imp`` of :func:`evaluate` for :func:`switches` of the work array as the last
#: evaluation left it, into ``dx`` (a structure's own code writes them out)
SWITCHES_OF_WORK = np.array([-np.inf])
#: ``imp`` of :func:`evaluate` for an integrator's inner stage: ``dx`` as without an
#: impulse, but the work array need not receive the outputs (node motion, element
#: forces, switching functions): nothing reads it before the next whole evaluation. A
#: structure's own code leaves those stores out; :func:`evaluate` makes them all
STAGE = np.array([np.inf, np.inf])


# Reference counting. A function compiled by numba with its runtime (NRT, the default)
# counts every array argument up on entry and down at exit, each an atomic operation.
# The right-hand side and the helpers the integrator calls once per stage take seven to
# fifteen arrays each: the counting was most of their time (decisions.md, "The
# right-hand side without reference counting (issue #34)"). So every function on that
# path that allocates nothing is compiled with ``_nrt=False`` (numba refuses an
# allocation there, so a function that later needs one fails to compile instead of
# leaking); their arrays belong to the caller, which keeps them alive across the call.

@nb.njit(cache=True, inline="always")
def road_layout(nroads, ne):
    """The layout of the road vector that :func:`evaluate` reads, the one place it is
    defined: 3 entries per road (displacement, velocity, acceleration; road k from
    3 k, at least one road), then one free slot (the harmonic balance keeps its
    frequency there), then one held side per element (see :func:`evaluate`). Returns
    (length, the free slot, the first held side) for ``nroads`` roads and ``ne``
    elements."""
    free = 3 * max(nroads, 1)
    return free + 1 + ne, free, free + 1


@nb.njit(cache=True, inline="always")
def road_layout_of(itab):
    """:func:`road_layout` of a compiled system (its roads and elements)."""
    return road_layout(itab[I_NRD], itab[I_NE])


@nb.njit(cache=True, inline="always")
def _solve(M, m0, r, r0, n):
    """Solve M x = r (n x n, row-major in M from M[m0]; r from r[r0]) in place by Gaussian
    elimination with partial pivoting; x in r. Returns False if M is singular. Offsets,
    not slices: a slice per call costs a view. Each pivot's reciprocal is taken once and
    multiplies (its column's factors, its row's back substitution): one division per
    pivot, not one per entry, on the chain from one pivot to the next."""
    if n == 1:  # the elimination below for one unknown, without its loops
        piv = M[m0]
        if piv == 0.0 or not math.isfinite(piv):
            return False
        r[r0] = r[r0] * (1.0 / piv)
        return True
    for k in range(n):
        p = k
        big = abs(M[m0 + k * n + k])
        for i in range(k + 1, n):
            if abs(M[m0 + i * n + k]) > big:
                big = abs(M[m0 + i * n + k])
                p = i
        if big == 0.0 or not math.isfinite(big):
            return False
        if p != k:
            for j in range(n):
                tmp = M[m0 + k * n + j]
                M[m0 + k * n + j] = M[m0 + p * n + j]
                M[m0 + p * n + j] = tmp
            tmp = r[r0 + k]
            r[r0 + k] = r[r0 + p]
            r[r0 + p] = tmp
        inv = 1.0 / M[m0 + k * n + k]
        for i in range(k + 1, n):
            f = M[m0 + i * n + k] * inv
            if f != 0.0:
                for j in range(k + 1, n):
                    M[m0 + i * n + j] -= f * M[m0 + k * n + j]
                r[r0 + i] -= f * r[r0 + k]
    for k in range(n - 1, -1, -1):
        s = r[r0 + k]
        for j in range(k + 1, n):
            s -= M[m0 + k * n + j] * r[r0 + j]
        r[r0 + k] = s * (1.0 / M[m0 + k * n + k])
    return True


@nb.njit(cache=True, inline="always")
def end_force(itab, ftab, b, x, v):
    """The force [N] of the element whose table entry starts at ``itab[b]``, a spring,
    damper or friction law (their force reads the relative displacement x and velocity
    v of its ends alone: a rig's drive forces from the states)."""
    if itab[b] == SPRING:
        return spring_force(ftab, itab[b + 3], x)
    f, _ = _dissipative(itab[b], ftab, itab[b + 3], v)
    return f


@nb.njit(cache=True, inline="always")
def _dissipative(code, tab, o, v):
    """(F, dF/dv) of a velocity-dependent element at relative velocity v (its parameter
    row from ``tab[o]``)."""
    if code == DAMPER:
        return damper_force(tab, o, v)
    return friction_force(tab[o], tab[o + 1], v)


@nb.njit(cache=True, inline="always")
def _pass_on(itab, ftab, W, nn, ia, ir):
    """The forces gathered at each combination node (``W[ia + n]``) passed on to its
    members' rows, by the combination's coefficients."""
    no = itab[I_NODE]
    for n in range(nn):
        b = no + NODE_W * n
        if itab[b] == LIN:
            mo, cnt, co = itab[b + 1], itab[b + 2], itab[b + 3]
            fn = W[ia + n]
            for j in range(cnt):
                W[ir + itab[no + NODE_W * itab[mo + j] + 3]] += ftab[co + j] * fn


@nb.njit(cache=True, inline="always")
def _element_law(itab, ftab, b, W, top, bot, iv, x, dx, side):
    """(m_e, f) of the element whose row starts at ``itab[b]``, between nodes ``top``
    and ``bot`` (displacements ``W[node]``, velocities ``W[iv + node]``): its force and
    the inertance it adds to the mass matrix (``side``: the road's side of a kink where
    the element is held, else 0)."""
    code = itab[b]
    o = itab[b + 3]
    slot = itab[b + 4]
    d = W[top] - W[bot]
    v = W[iv + top] - W[iv + bot]
    if code == SPRING:
        return 0.0, spring_force(ftab, o, d)
    if code == DAMPER or code == FRICTION:
        f, _ = _dissipative(code, ftab, o, v)
        return 0.0, f
    if code == INERTER:
        return inerter_inertance(ftab, o), 0.0
    if code == TYRE:
        return 0.0, tyre_force(ftab, o, d, v, side)
    # the flywheel-row elements (held on one side of a kink: side)
    return inertial_law(ftab, o, d, v, x, slot, dx, side)


def dense_tables(itab, ftab):
    """(itab, ftab) of the same system with its mass matrix factored beforehand for
    :func:`evaluate` (see :func:`_dense_solve`), or None where that does not apply: a
    node other than ground, road, dynamic node or a combination of those, a clutch or
    a gated screw (their inertance lets go), or a mass matrix singular at rest. Valid
    for these parameter rows only (the node masses, the inerters and the flywheels'
    :func:`~inerterlab.elements.adaptive_flywheel.factor_inertance` are in the factor):
    build it again after changing them."""
    itab = np.asarray(itab, dtype=np.int64)
    ftab = np.asarray(ftab, dtype=float)
    nn, ne, nd = int(itab[I_NN]), int(itab[I_NE]), int(itab[I_ND])
    no, eo, fm = int(itab[I_NODE]), int(itab[I_ELEM]), int(itab[I_FMASS])
    if nd == 0 or itab[I_NV] or itab[I_NP] or itab[I_NR] or itab[I_DNS]:
        return None
    rows = np.zeros((nn, nd))
    typ = [int(itab[no + NODE_W * n]) for n in range(nn)]
    for n in range(nn):
        if typ[n] == DYN:
            rows[n, itab[no + NODE_W * n + 3]] = 1.0
        elif typ[n] not in (GROUND, ROAD, LIN):
            return None
    for n in range(nn):
        if typ[n] == LIN:
            b = no + NODE_W * n
            mo, cnt, co = int(itab[b + 1]), int(itab[b + 2]), int(itab[b + 3])
            for j in range(cnt):
                mem = int(itab[mo + j])
                if typ[mem] == LIN:
                    return None
                rows[n] += ftab[co + j] * rows[mem]
    M0 = np.zeros((nd, nd))
    for n in range(nn):
        if typ[n] == DYN:
            k = itab[no + NODE_W * n + 3]
            M0[k, k] += ftab[fm + n]
    var, U, rest = [], [], []
    for e in range(ne):
        b = eo + ELEM_W * e
        g = rows[itab[b + 1]] - rows[itab[b + 2]]
        o = int(itab[b + 3])
        if itab[b] == INERTER:
            M0 += float(ftab[o]) * np.outer(g, g)
        elif itab[b] == FLYWHEEL:
            if ftab[o + 14] != 0.0:  # a clutch or a gated screw lets go: massless rows
                return None
            # the adaptive flywheel at its factor inertance (on its stops where the law
            # saturates) goes into the factor; the excess over it is updated at every
            # call, and skipped where it is 0
            me0 = factor_inertance(ftab, o)
            M0 += me0 * np.outer(g, g)
            var.append(e)
            U.append(g)
            rest.append(me0)
    m = len(var)
    if nd * nd < m * m + 2 * m:  # the scratch of _dense_solve
        return None
    w = np.linalg.eigvalsh(M0)
    if not np.all(np.isfinite(w)) or w[0] <= 1e-12 * w[-1]:
        return None
    U = np.array(U, float).reshape(m, nd).T
    Minv = np.linalg.inv(M0)
    Z = Minv @ U
    S = U.T @ Z
    block = np.concatenate([Minv.ravel(), Z.ravel(), S.ravel(), U.T.ravel(), rest])
    itab2 = np.concatenate([itab, np.array([ftab.size, m, *var], dtype=np.int64)])
    itab2[I_DNS] = itab.size
    ftab2 = np.concatenate([ftab, block])
    itab2.setflags(write=False)
    ftab2.setflags(write=False)
    return itab2, ftab2


def work_size(itab) -> int:
    """Length of the work array :func:`evaluate` takes (so that a caller evaluating many
    times allocates once): node displacements, velocities and accelerations, element
    forces, then scratch."""
    nn, nd, ne, nv = int(itab[I_NN]), int(itab[I_ND]), int(itab[I_NE]), int(itab[I_NV])
    return 3 * nn + ne + nd * nd + nd + ne + nv * nv + 3 * nv + 3 * ne


@nb.njit(cache=True, inline="always")
def _work_size(itab):
    nn, nd, ne, nv = itab[I_NN], itab[I_ND], itab[I_NE], itab[I_NV]
    return 3 * nn + ne + nd * nd + nd + ne + nv * nv + 3 * nv + 3 * ne


@nb.njit(cache=True, inline="always")
def _switch_slots(itab):
    """Offset in the work array of the flywheel-row elements' switching functions (two
    halves per element, then how many each has), which :func:`evaluate` fills."""
    return _work_size(itab) - 3 * itab[I_NE]


@nb.njit(cache=True, inline="always")
def _slot(itab, no, n):
    """Index of the velocity unknown whose balance node n belongs to, or -1: a velocity
    node's own, or for a relative node its component reference's, if that is one."""
    b = no + NODE_W * n
    typ = itab[b]
    if typ == VEL or typ == RELV:
        return itab[b + 3]
    if typ == REL:
        rb = no + NODE_W * itab[b + 4]
        if itab[rb] == VEL:
            return itab[rb + 3]
    return -1


@nb.njit(cache=True, inline="always")
def _vnode(itab, no, W, nn, n):
    """Velocity of node n while the balances are solved: a relative node's velocity is
    held relative to its reference until the references are known."""
    b = no + NODE_W * n
    if itab[b] == REL:
        return W[nn + n] + W[nn + itab[b + 4]]
    return W[nn + n]


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _vel_residual(itab, ftab, W, gi, ji, nv, want_j):
    """Force balance G = W[gi:gi+nv] of the velocity nodes (and its Jacobian J =
    W[ji:ji+nv*nv] if want_j); X = W[0:nn], V = W[nn:2nn]."""
    ne = itab[I_NE]
    nn = itab[I_NN]
    eo = itab[I_ELEM]
    no = itab[I_NODE]
    for i in range(nv):
        W[gi + i] = 0.0
    if want_j:
        for i in range(nv * nv):
            W[ji + i] = 0.0
    for e in range(ne):
        b = eo + ELEM_W * e
        code = itab[b]
        top = itab[b + 1]
        bot = itab[b + 2]
        ti = _slot(itab, no, top)
        bi = _slot(itab, no, bot)
        if ti < 0 and bi < 0:
            continue
        o = itab[b + 3]
        if code == SPRING:
            f = spring_force(ftab, o, W[top] - W[bot])
            d = 0.0
        elif code == DAMPER or code == FRICTION:
            f, d = _dissipative(
                code, ftab, o, _vnode(itab, no, W, nn, top) - _vnode(itab, no, W, nn, bot)
            )
        else:
            continue  # inertial elements never touch a velocity node
        if ti >= 0:
            W[gi + ti] -= f
            if want_j:
                W[ji + ti * nv + ti] -= d
                if bi >= 0:
                    W[ji + ti * nv + bi] += d
        if bi >= 0:
            W[gi + bi] += f
            if want_j:
                W[ji + bi * nv + bi] -= d
                if ti >= 0:
                    W[ji + bi * nv + ti] += d


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _velocities(itab, ftab, W, s0):
    """Velocities of the massless velocity nodes (in W[nn:2nn]) from their force balance
    (Newton; the balance is strictly decreasing in each node's velocity). Returns False
    on failure. Scratch: W[s0:s0 + nv^2 + 3 nv]."""
    nv = itab[I_NV]
    if nv == 0:
        return True
    nn = itab[I_NN]
    vo = itab[I_VEL]
    yes = nv > 0  # True, not a literal: one compiled _vel_residual, not three
    gi = s0
    ji = s0 + nv
    di = s0 + nv + nv * nv
    v0 = s0 + 2 * nv + nv * nv
    for i in range(nv):
        W[nn + itab[vo + i]] = 0.0
    if nv == 1:
        # safeguarded Newton on a bracket (G is decreasing in v)
        n = nn + itab[vo]
        lo = -math.inf
        hi = math.inf
        u = 0.0
        for _ in range(400):
            W[n] = u
            _vel_residual(itab, ftab, W, gi, ji, nv, yes)
            g = W[gi]
            if g > 0.0:
                lo = u
            elif g < 0.0:
                hi = u
            else:
                return True
            un = u - g / W[ji] if W[ji] < 0.0 else math.nan
            if not (lo < un < hi):
                if math.isfinite(lo) and math.isfinite(hi):
                    un = 0.5 * (lo + hi)
                else:
                    step = max(1.0, 2.0 * abs(u))
                    un = u + step if g > 0.0 else u - step
            if abs(un - u) <= 2e-16 * abs(un) + 1e-300:
                W[n] = un
                return True
            u = un
        W[n] = u
        return False
    # several nodes: Newton with backtracking on |G|
    for _it in range(200):
        _vel_residual(itab, ftab, W, gi, ji, nv, yes)
        g2 = 0.0
        for i in range(nv):
            g2 += W[gi + i] * W[gi + i]
            W[di + i] = -W[gi + i]
            W[v0 + i] = W[nn + itab[vo + i]]
        if g2 == 0.0:
            return True
        if not _solve(W, ji, W, di, nv):
            return False
        step = 1.0
        done = False
        for _ in range(60):
            small = True
            for i in range(nv):
                W[nn + itab[vo + i]] = W[v0 + i] + step * W[di + i]
                if abs(step * W[di + i]) > 2e-16 * abs(W[v0 + i]) + 1e-300:
                    small = False
            if small:
                return True
            _vel_residual(itab, ftab, W, gi, ji, nv, not yes)
            n2 = 0.0
            for i in range(nv):
                n2 += W[gi + i] * W[gi + i]
            if n2 < g2:
                done = True
                break
            step *= 0.5
        if not done:
            for i in range(nv):
                W[nn + itab[vo + i]] = W[v0 + i]
            return True
    return True


@nb.njit(cache=True, inline="always")
def _node_motion(x, road, itab, ftab, W, nn, ne, nd):
    """The first part of :func:`evaluate`: every node's displacement and velocity
    (W[0:nn], W[nn:2nn]) at the state ``x`` and road ``road``, the known accelerations
    (ground, road; NaN elsewhere, the combination nodes' slots zeroed for gathering).
    Returns False where the velocity nodes' balance could not be solved."""
    no = itab[I_NODE]
    npn = itab[I_NP]
    iv = nn
    ia = 2 * nn
    ie = 3 * nn + ne + nd * nd + nd
    for n in range(nn):
        b = no + NODE_W * n
        typ = itab[b]
        W[ia + n] = math.nan
        if typ == GROUND:
            W[n] = 0.0
            W[iv + n] = 0.0
            W[ia + n] = 0.0
        elif typ == ROAD:
            k = 3 * itab[b + 3] if itab[b + 3] > 0 else 0
            W[n] = road[k]
            W[iv + n] = road[k + 1]
            W[ia + n] = road[k + 2]
        elif typ == DYN:
            W[n] = x[itab[b + 1]]
            W[iv + n] = x[itab[b + 2]]
        elif typ == VEL:
            W[n] = x[itab[b + 1]]
            W[iv + n] = 0.0
        elif typ == REL:  # relative to the reference until it is known
            W[n] = x[itab[b + 1]]
            W[iv + n] = x[itab[b + 2]]
        elif typ == RELV:  # relative displacement; the relative velocity is solved
            W[n] = x[itab[b + 1]]
            W[iv + n] = 0.0
        else:
            W[n] = 0.0
            W[iv + n] = 0.0
    nlin = itab[I_NL]
    if nlin > 0:
        _combine(itab, ftab, W, 0, nn)
        _combine(itab, ftab, W, nn, nn)
        for n in range(nn):  # their acceleration slots gather forces until the solve
            if itab[no + NODE_W * n] == LIN:
                W[2 * nn + n] = 0.0
    # spring-only nodes: X_p = R X (R has zero columns for spring-only nodes; relative
    # nodes enter with their relative displacement)
    po = itab[I_POS]
    fr = itab[I_FR]
    for i in range(npn):
        p = itab[po + i]
        s = 0.0
        for j in range(nn):
            s += ftab[fr + i * nn + j] * W[j]
        W[p] = s
    nrel = itab[I_NR]
    if nrel > 0:
        for n in range(nn):
            b = no + NODE_W * n
            if itab[b] == REL or itab[b] == RELV:
                W[n] += W[itab[b + 4]]
    ok = True
    if itab[I_NV] > 0:
        ok = _velocities(itab, ftab, W, ie + ne)
    for i in range(npn):
        p = itab[po + i]
        s = 0.0
        for j in range(nn):
            s += ftab[fr + i * nn + j] * W[iv + j]
        W[iv + p] = s
    if nrel > 0:
        for n in range(nn):
            b = no + NODE_W * n
            if itab[b] == REL or itab[b] == RELV:
                W[iv + n] += W[iv + itab[b + 4]]
            elif itab[b + 4] == n:  # a reference: fixed for the relative accelerations
                W[ia + n] = 0.0
    return ok


# the core's one compiled evaluation: the integrator's generic tier (:mod:`._compiled`,
# which also writes its statements into each structure's own code), :func:`rhs`,
# :func:`outputs`, :func:`switches_at`, the harmonic balance and the Python callers (the
# impulses, the static balance) all call this one copy. They pass contiguous arrays and
# the tables read-only (``readonly``): each further signature would compile the whole of
# it again (about 17 s of CPU). numpy's error model: a division by zero gives inf or NaN,
# which the integrator reports as a non-finite solution (an exception cannot cross the
# function pointer through which it calls the evaluation); every function it calls
# that is compiled on its own sets the same model (tests/test_numba_flags.py)
@nb.njit(cache=True, error_model="numpy", _nrt=False)
def evaluate(t, x, road, itab, ftab, W, dx, imp):
    """Fill the work array ``W`` (:func:`work_size` floats) with the node displacements
    X = W[0:nn], velocities V = W[nn:2nn], accelerations A = W[2nn:3nn] (NaN where not
    defined: the massless nodes) and element forces F = W[3nn:3nn+ne], and ``dx`` with
    the derivative. Returns False if a balance could not be solved. ``road`` is laid out
    by :func:`road_layout`: each road's displacement, velocity and acceleration, a free
    slot (the harmonic balance's frequency), and it may go on with one held side per
    element: where it is not 0, an element with a kink takes the law of that side of it
    (+1 above its switching function's zero, -1 below), continued past it. With a
    non-empty ``imp`` (one impulse per dynamic node) dx is instead the impulse flow
    M(x)^-1 imp on the dynamic nodes' velocities (zero elsewhere): integrated over a unit
    interval it applies the impulse exactly, whatever the velocity dependence of the
    inertances. With ``imp`` = [NaN] (:data:`ROAD_JERK`) it is the flow of a road
    velocity jump: road[2] holds the jump, the forces are left out (finite, they pass no
    impulse in no time) and dx = M(x)^-1 (the inertances' coupling to the road times the
    jump); integrated over a unit interval with the road velocity moving linearly
    through the jump it applies the impulses the inertances on the road pass, whatever
    their velocity dependence. The work array is read by offset, never sliced: a slice
    costs a view per call. Tables from :func:`dense_tables` (header ``I_DNS`` > 0) carry
    the mass matrix factored beforehand: without an impulse the accelerations then come
    from that factor and a low-rank update for the flywheels (:func:`_dense_solve`), the
    same balance by another order of the arithmetic (agreeing to rounding). With ``imp``
    = [inf] (:data:`SWITCHES_ONLY`) it fills only the nodes' displacements and
    velocities and the flywheel-row elements' switching functions, and writes
    :func:`switches` of them into ``dx`` (two per element, so ``dx`` holds 2 ne; see
    :func:`switches_at`). With
    ``imp`` = [-inf] (:data:`SWITCHES_OF_WORK`) it is :func:`switches` of ``W`` as the
    last evaluation left it, into ``dx`` (two per element; the count is not returned),
    and reads nothing else: the integrators call it so through the right-hand side, whose
    compiled code for a structure writes those statements out (:func:`dense_source`).
    With ``imp`` = [inf, inf] (:data:`STAGE`) it is the evaluation without an impulse
    (a structure's own code then leaves out the work array's outputs)."""
    if imp.size == 1 and imp[0] == -math.inf:
        switches(itab, ftab, W, dx)
        return True
    nn = itab[I_NN]
    ne = itab[I_NE]
    nd = itab[I_ND]
    jerk = imp.size == 1 and math.isnan(imp[0])
    flow = imp.size > 0 and not (imp.size == 2 and imp[0] == math.inf)  # STAGE: no flow
    nlen, _, hs = road_layout_of(itab)
    held = road.size >= nlen  # the held sides are given
    no = itab[I_NODE]
    eo = itab[I_ELEM]
    fm = itab[I_FMASS]
    nlin = itab[I_NL]
    nrel = itab[I_NR]
    iv = nn  # velocities
    ia = 2 * nn  # accelerations
    iF = 3 * nn  # element forces
    im = iF + ne  # mass matrix of the dynamic nodes
    ir = im + nd * nd  # right-hand side, then the accelerations
    ie = ir + nd  # inertance of each element
    ok = _node_motion(x, road, itab, ftab, W, nn, ne, nd)
    if imp.size == 1 and imp[0] == math.inf:  # the switching functions alone, into dx
        _inertial_after(itab, ftab, W, x, dx, road, iv, ia, iF, np.bool_(False))
        switches(itab, ftab, W, dx)
        return ok
    if itab[I_DNS] > 0 and not flow:  # the mass matrix factored beforehand
        ok &= _dense_solve(itab, ftab, W, x, dx, road, held, hs, nn, ne, nd, iv, ia, iF, ir, ie)
        return _after_solve(itab, ftab, W, x, dx, road, nn, ne, iv, ia, iF, ie, ir, nrel, ok)
    # forces and the mass matrix of the dynamic nodes
    for i in range(im, ie + ne):
        W[i] = 0.0
    dl = itab[I_DYN]
    for k in range(nd):  # the dynamic nodes' own masses (none at a relative node)
        n = itab[dl + k]
        W[im + k * nd + k] += ftab[fm + n]
    for e in range(ne):
        b = eo + ELEM_W * e
        top = itab[b + 1]
        bot = itab[b + 2]
        me, f = _element_law(itab, ftab, b, W, top, bot, iv, x, dx, road[hs + e] if held else 0.0)
        if jerk:
            f = 0.0
        W[iF + e] = f
        W[ie + e] = me
        ti = itab[b + 5]
        bi = itab[b + 6]
        if ti == -2 or bi == -2:  # an end at a combination node
            if me == 0.0:  # a force only: gathered at the node, passed on once below
                _gather(itab, W, top, -f, ia, ir)
                _gather(itab, W, bot, f, ia, ir)
            else:
                _stamp_combined(itab, ftab, W, top, bot, f, me, im, ir, ia, nd)
            continue
        if ti >= 0:
            W[ir + ti] -= f
        if bi >= 0:
            W[ir + bi] += f
        if me != 0.0:
            if ti >= 0:
                W[im + ti * nd + ti] += me
                if bi >= 0:
                    W[im + ti * nd + bi] -= me
                else:
                    W[ir + ti] += me * W[ia + bot]
            if bi >= 0:
                W[im + bi * nd + bi] += me
                if ti >= 0:
                    W[im + bi * nd + ti] -= me
                else:
                    W[ir + bi] += me * W[ia + top]
    if nlin > 0:  # the forces gathered at combination nodes to their members' rows
        _pass_on(itab, ftab, W, nn, ia, ir)
    if flow and not jerk:
        for i in range(nd):
            W[ir + i] = imp[i]
    if nd > 0:
        _massless_rows(itab, ftab, W, im, ir, iv, ia, nd, flow)
    if nd > 0 and not _solve(W, im, W, ir, nd):
        ok = False
    if not flow:
        return _after_solve(itab, ftab, W, x, dx, road, nn, ne, iv, ia, iF, ie, ir, nrel, ok)
    _accelerations(itab, ftab, W, x, dx, nn, iv, ia, ir)
    if flow:
        for i in range(x.size):
            if i >= itab[I_NS] - itab[I_NI]:
                dx[i] = 0.0
        for n in range(nn):
            b = no + NODE_W * n
            if itab[b] == DYN or itab[b] == REL:
                dx[itab[b + 1]] = 0.0
            elif itab[b] == VEL or itab[b] == RELV:
                dx[itab[b + 1]] = 0.0
        _inertial_after(itab, ftab, W, x, dx, road, iv, ia, iF, np.bool_(True))
        _relative_unknown(itab, W, ia, nn, nrel)
    return ok


@nb.njit(cache=True, inline="always")
def _accelerations(itab, ftab, W, x, dx, nn, iv, ia, ir):
    """Every node's acceleration and the nodes' part of the derivative, once the
    dynamic nodes' accelerations (or impulse flows) are in W[ir:ir+nd]."""
    no = itab[I_NODE]
    for n in range(nn):
        b = no + NODE_W * n
        typ = itab[b]
        if typ == DYN:
            W[ia + n] = W[ir + itab[b + 3]]
            dx[itab[b + 1]] = W[iv + n]
            dx[itab[b + 2]] = W[ia + n]
        elif typ == VEL:
            dx[itab[b + 1]] = W[iv + n]
        elif typ == REL:
            W[ia + n] = W[ir + itab[b + 3]]
            dx[itab[b + 1]] = x[itab[b + 2]]
            dx[itab[b + 2]] = W[ia + n]
        elif typ == RELV:
            dx[itab[b + 1]] = W[iv + n] - W[iv + itab[b + 4]]
    if itab[I_NL] > 0:
        _combine(itab, ftab, W, ia, nn)


@nb.njit(cache=True, inline="always")
def _after_solve(itab, ftab, W, x, dx, road, nn, ne, iv, ia, iF, ie, ir, nrel, ok):
    """The end of :func:`evaluate` (no impulse) once the accelerations of the dynamic
    nodes are in W[ir:ir+nd]: every node's acceleration, the derivative, the inertial
    forces m_e (a_top - a_bottom), the own states' rates and the switching functions."""
    eo = itab[I_ELEM]
    _accelerations(itab, ftab, W, x, dx, nn, iv, ia, ir)
    for e in range(ne):
        if W[ie + e] != 0.0:
            b = eo + ELEM_W * e
            W[iF + e] += W[ie + e] * (W[ia + itab[b + 1]] - W[ia + itab[b + 2]])
    _inertial_after(itab, ftab, W, x, dx, road, iv, ia, iF, np.bool_(True))
    _relative_unknown(itab, W, ia, nn, nrel)
    return ok


# compiled on its own, not inlined: only tables with the mass matrix factored beforehand
# take it (whose structures' own code writes it out, dense_source), and inlined it made
# the evaluation's compilation take about 2.4 s of CPU longer (18.0 against 15.6 s)
@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _dense_solve(itab, ftab, W, x, dx, road, held, hs, nn, ne, nd, iv, ia, iF, ir, ie):
    """Forces and accelerations of a system whose mass matrix was factored beforehand
    (:func:`dense_tables`: every node a ground, road or dynamic node, or a combination
    of them). The mass matrix is M0 + sum_e (m_e(v) - m_e0) g_e g_e^T, M0 the node
    masses, the constant inerters and the adaptive flywheels at their factor inertance
    m_e0 (:func:`~inerterlab.elements.adaptive_flywheel.factor_inertance`: on their
    stops where the law saturates), the sum over the flywheels (m_e changes with their
    motion); a = M^-1 Q by the Woodbury identity about M0^-1 (given): y = M0^-1 Q,
    a = y - Z (I + D S)^-1 D U^T y, U = [g_e], D = diag(m_e - m_e0), Z = M0^-1 U,
    S = U^T M0^-1 U. Where every m_e is m_e0, a = y; where one is not, I + D S is the
    identity but for that row and its unknown is solved alone (the elimination's own
    operations for it); else the whole system. Each element's force f, and m_e times the
    known accelerations of its ends (road, ground), are gathered on its ends' rows;
    nothing is stamped.
    Scratch: the mass matrix's slots (nd^2 >= m^2 + 2 m, checked by dense_tables).
    Returns False where I + D S is singular."""
    eo = itab[I_ELEM]
    no = itab[I_NODE]
    im = ir - nd * nd
    for i in range(nd):
        W[ir + i] = 0.0
    for e in range(ne):
        b = eo + ELEM_W * e
        top = itab[b + 1]
        bot = itab[b + 2]
        me, f = _element_law(itab, ftab, b, W, top, bot, iv, x, dx, road[hs + e] if held else 0.0)
        W[iF + e] = f
        W[ie + e] = me
        g = f
        if me != 0.0:  # m_e times the known accelerations of the ends (road, ground)
            tt = itab[no + NODE_W * top]
            tb = itab[no + NODE_W * bot]
            if tt == ROAD:
                g += me * W[ia + top]
            if tb == ROAD:
                g -= me * W[ia + bot]
        _gather(itab, W, top, -g, ia, ir)
        _gather(itab, W, bot, g, ia, ir)
    if itab[I_NL] > 0:
        _pass_on(itab, ftab, W, nn, ia, ir)
    db = itab[I_DNS]
    fo = itab[db]
    m = itab[db + 1]
    mi = fo  # M0^-1 (nd x nd), then Z (nd x m), then S (m x m)
    zo = fo + nd * nd
    so = zo + nd * m
    y = im  # scratch: y, then w = D U^T y, then the capacitance matrix
    w = im + nd
    cap = w + m
    for i in range(nd):
        acc = 0.0
        for j in range(nd):
            acc += ftab[mi + i * nd + j] * W[ir + j]
        W[y + i] = acc
    for i in range(nd):
        W[ir + i] = W[y + i]
    if m == 0:
        return True
    uo = so + m * m  # U^T (m x nd), then the inertances in M0
    ro = uo + m * nd
    nz = 0  # the flywheels away from the factor's inertance
    last = 0
    for k in range(m):  # w = D U^T y and the capacitance matrix I + D S
        me = W[ie + itab[db + 2 + k]] - ftab[ro + k]
        acc = 0.0
        for j in range(nd):
            acc += ftab[uo + k * nd + j] * W[y + j]
        W[w + k] = me * acc
        for j in range(m):
            W[cap + k * m + j] = (1.0 if j == k else 0.0) + me * ftab[so + k * m + j]
        if me != 0.0:
            nz += 1
            last = k
    if nz == 0:  # I + D S is the identity and w is 0: a = y
        return True
    if nz == 1:  # the identity's rows but one: that unknown alone
        piv = W[cap + last * m + last]
        if piv == 0.0 or not math.isfinite(piv):
            return False
        W[w + last] = W[w + last] * (1.0 / piv)
    elif not _solve(W, cap, W, w, m):
        return False
    for i in range(nd):
        acc = 0.0
        for k in range(m):
            acc += ftab[zo + i * m + k] * W[w + k]
        W[ir + i] -= acc
    return True


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _inertial_after(itab, ftab, W, x, dx, road, iv, ia, iF, rates):
    """The flywheel-row elements' switching functions (into the slots of
    :func:`_switch_slots`) and, with ``rates``, once the accelerations and forces are
    known, the rates of their own states that need them (the clutch's flywheel speed);
    without (:func:`switches_at`: the nodes' motion alone) ``dx``, ``ia`` and ``iF`` are
    not read and the switching functions take the force 0."""
    ne = itab[I_NE]
    eo = itab[I_ELEM]
    sg = _switch_slots(itab)
    nlen, _, hs = road_layout_of(itab)
    held = road.size >= nlen
    for e in range(ne):
        b = eo + ELEM_W * e
        W[sg + 2 * ne + e] = 0.0
        if itab[b] != FLYWHEEL:
            continue
        top = itab[b + 1]
        bot = itab[b + 2]
        o = itab[b + 3]
        so = itab[b + 4]
        side = road[hs + e] if held else 0.0
        v = W[iv + top] - W[iv + bot]
        force = 0.0
        if rates:
            rate = inertial_rate(ftab, o, v, W[ia + top] - W[ia + bot], x, so, side)
            if not math.isnan(rate):
                dx[so] = rate
            force = W[iF + e]
        _switch_halves(ftab, W, x, e, top, bot, o, so, side, v, force, sg, ne)


@nb.njit(cache=True, inline="always")
def _switch_halves(ftab, W, x, e, top, bot, o, so, side, v, force, sg, ne):
    """Flywheel-row element e's switching function (its two signed halves, see
    :func:`switches`, and whether it has one) into the slots of :func:`_switch_slots`
    (from ``sg``), at relative velocity ``v`` and element force ``force``."""
    g1, g2, kind = _switch_pair(ftab, x, o, so, side, W[top] - W[bot], v, force)
    W[sg + 2 * e] = g1
    W[sg + 2 * e + 1] = g2
    W[sg + 2 * ne + e] = 1.0 if kind > 0 else 0.0


@nb.njit(cache=True, inline="always")
def _switch_pair(ftab, x, o, so, side, xr, v, force):
    """A flywheel-row element's two signed halves of its switching function (see
    :func:`switches`) and its kind (:func:`inerterlab.elements._inertial.inertial_switch`),
    at relative displacement ``xr``, velocity ``v`` and element force ``force``."""
    g, g0, a, kind = inertial_switch(ftab, o, xr, v, force, x, so, side)
    if kind == 2:
        return g, g, kind
    d = g - g0 if a >= 0.0 else g0 - g
    return g0 + d, g0 - d, kind


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _massless_rows(itab, ftab, W, im, ir, iv, ia, nd, flow):
    """A dynamic node whose every inertance is disengaged (a one-way clutch running
    free, a screw out of contact) has a zero row in the mass matrix: it is massless for
    now. Its row becomes the time derivative of its force balance G, sum of the springs'
    k (v_t - v_b) and of the dissipative elements' dF/dv (a_t - a_b) = -lambda G, which
    keeps the balance that held when the inertance let go (G = 0) and pulls the
    integration's drift of it back at the node's own rate lambda = sum k / sum dF/dv; in
    an impulse flow its velocity does not change."""
    eo = itab[I_ELEM]
    for k in range(nd):
        zero = True
        for j in range(nd):
            if W[im + k * nd + j] != 0.0:
                zero = False
                break
        if not zero:
            continue
        g = W[ir + k]  # the force balance, zero but for the drift of the integration
        W[ir + k] = 0.0
        if flow:
            W[im + k * nd + k] = 1.0
            continue
        ksum = 0.0
        dsum = 0.0
        for e in range(itab[I_NE]):
            b = eo + ELEM_W * e
            ti = itab[b + 5]
            bi = itab[b + 6]
            if ti != k and bi != k:
                continue
            code = itab[b]
            top = itab[b + 1]
            bot = itab[b + 2]
            o = itab[b + 3]
            sgn = -1.0 if ti == k else 1.0  # the force acts on the top as -F
            if code == SPRING:
                ks = spring_slope(ftab, o, W[top] - W[bot])
                ksum += ks
                W[ir + k] -= sgn * ks * (W[iv + top] - W[iv + bot])
            elif code == DAMPER or code == FRICTION:
                _, d = _dissipative(code, ftab, o, W[iv + top] - W[iv + bot])
                dsum += d
                if ti >= 0:
                    W[im + k * nd + ti] += sgn * d
                else:
                    W[ir + k] -= sgn * d * W[ia + top]
                if bi >= 0:
                    W[im + k * nd + bi] -= sgn * d
                else:
                    W[ir + k] += sgn * d * W[ia + bot]
        if dsum > 0.0:  # the drift decays at the node's own rate, sum k / sum dF/dv
            W[ir + k] -= ksum / dsum * g


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _combine(itab, ftab, W, off, nn):
    """W[off + n] = sum c_j W[off + m_j] at every combination node n (displacements,
    velocities or accelerations of its members)."""
    no = itab[I_NODE]
    for n in range(nn):
        b = no + NODE_W * n
        if itab[b] == LIN:
            mo, cnt, co = itab[b + 1], itab[b + 2], itab[b + 3]
            s = 0.0
            for j in range(cnt):
                s += ftab[co + j] * W[off + itab[mo + j]]
            W[off + n] = s


@nb.njit(cache=True, inline="always")
def _gather(itab, W, n, f, ia, ir):
    """Add the force f to node n: to its row if it has one, to the combination node's
    gathering slot (its acceleration slot, until the solve) if it is one."""
    b = itab[I_NODE] + NODE_W * n
    typ = itab[b]
    if typ == LIN:
        W[ia + n] += f
    elif typ == DYN or typ == REL:
        W[ir + itab[b + 3]] += f


@nb.njit(cache=True, inline="always")
def _end(itab, n, j):
    """(mass-matrix row, coefficient) of the j-th member of element end n: a dynamic or
    relative node is its own single member, a combination node has its list; (-1, 0)
    past the end or at a node with no row."""
    b = itab[I_NODE] + NODE_W * n
    typ = itab[b]
    if typ == LIN:
        if j < itab[b + 2]:
            m = itab[itab[b + 1] + j]
            return itab[itab[I_NODE] + NODE_W * m + 3], j
        return -1, -1
    if j == 0 and (typ == DYN or typ == REL):
        return itab[b + 3], -1
    return -1, -1


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _stamp_combined(itab, ftab, W, top, bot, f, me, im, ir, ia, nd):
    """Stamp an element with an end at a combination node: force -f on the top end's
    rows and +f on the bottom's (times the coefficients); an inertance me adds me g g^T
    to the mass matrix and -me g (known accelerations of the ends) to the right-hand
    side, g = (top rows) - (bottom rows)."""
    no = itab[I_NODE]
    known = 0.0
    for side in range(2):
        n = top if side == 0 else bot
        sg = -1.0 if side == 0 else 1.0
        typ = itab[no + NODE_W * n]
        if typ != LIN and typ != DYN and typ != REL:
            known -= sg * W[ia + n]  # + a_top, - a_bottom
            continue
        cnt = itab[no + NODE_W * n + 2] if typ == LIN else 1
        co = itab[no + NODE_W * n + 3]
        for j in range(cnt):
            row, _ = _end(itab, n, j)
            c = ftab[co + j] if typ == LIN else 1.0
            W[ir + row] += sg * f * c
    if me == 0.0:
        return
    for s1 in range(2):
        n1 = top if s1 == 0 else bot
        g1 = 1.0 if s1 == 0 else -1.0
        t1 = itab[no + NODE_W * n1]
        if t1 != LIN and t1 != DYN and t1 != REL:
            continue
        c1n = itab[no + NODE_W * n1 + 2] if t1 == LIN else 1
        for j1 in range(c1n):
            r1, _ = _end(itab, n1, j1)
            a1 = g1 * (ftab[itab[no + NODE_W * n1 + 3] + j1] if t1 == LIN else 1.0)
            W[ir + r1] -= me * a1 * known
            for s2 in range(2):
                n2 = top if s2 == 0 else bot
                g2 = 1.0 if s2 == 0 else -1.0
                t2 = itab[no + NODE_W * n2]
                if t2 != LIN and t2 != DYN and t2 != REL:
                    continue
                c2n = itab[no + NODE_W * n2 + 2] if t2 == LIN else 1
                for j2 in range(c2n):
                    r2, _ = _end(itab, n2, j2)
                    a2 = g2 * (ftab[itab[no + NODE_W * n2 + 3] + j2] if t2 == LIN else 1.0)
                    W[im + r1 * nd + r2] += me * a1 * a2


@nb.njit(cache=True, inline="always")
def _relative_unknown(itab, W, ia, nn, nrel):
    """The absolute accelerations of a floating component's nodes are not defined (its
    common motion is massless): NaN, as at every massless node."""
    if nrel > 0:
        no = itab[I_NODE]
        for n in range(nn):
            if itab[no + NODE_W * n + 4] >= 0:
                W[ia + n] = math.nan


@nb.njit(cache=True, inline="always")
def signal(itab, ftab, W, x, k, impulsive=False):
    """Signal k of the observers: a sum of coefficients times channels, the channels
    being the outputs of the last :func:`evaluate` (``W[0:3nn+ne]``: node displacements,
    velocities, accelerations, element forces) followed by the states ``x`` (observer
    states included). Stored as compressed rows: itab[I_SG + k] .. itab[I_SG + k + 1]
    index the channel numbers (from itab[I_SG + nsg + 1]) and their coefficients (from
    ftab[I_SGF]). ``impulsive``: only the part an impulse flow carries, the acceleration
    channels (an impulse is a Dirac in the accelerations; every other channel is
    finite)."""
    sg = itab[I_SG]
    nsg = itab[I_NSG]
    ci = sg + nsg + 1
    cf = itab[I_SGF]
    nn = itab[I_NN]
    no = 3 * nn + itab[I_NE]
    acc = 0.0
    for j in range(itab[sg + k], itab[sg + k + 1]):
        c = itab[ci + j]
        if impulsive and not 2 * nn <= c < 3 * nn:
            continue
        acc += ftab[cf + j] * (W[c] if c < no else x[c - no])
    return acc


@nb.njit(cache=True, inline="always")
def observe(itab, ftab, W, x, dx, impulse):
    """The derivatives of the observer states into ``dx`` from the last
    :func:`evaluate` (its work array ``W``) at the state ``x``. During an impulse flow
    (``impulse``: a road step or a road velocity jump, applied over a unit interval) a
    linear observer moves by its signal's acceleration part only (a filter takes the
    Dirac in its input as a jump of its states, exactly) and the others stand (the
    integral of a Dirac's square is not finite: the driver reports it)."""
    ob = itab[I_OBS]
    for q in range(itab[I_NOB]):
        b = ob + OBS_W * q
        kind = itab[b]
        slot = itab[b + 3]
        if kind == OBS_PEAK:
            dx[slot] = 0.0
            continue
        if impulse:
            dx[slot] = signal(itab, ftab, W, x, itab[b + 1], True) if kind == OBS_LINEAR else 0.0
            continue
        a = signal(itab, ftab, W, x, itab[b + 1])
        if kind == OBS_LINEAR:
            dx[slot] = a
        elif kind == OBS_SQUARE:
            dx[slot] = a * a
        elif kind == OBS_FOURTH:
            a2 = a * a
            dx[slot] = a2 * a2
        else:
            dx[slot] = a * signal(itab, ftab, W, x, itab[b + 2])


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def peaks(itab, ftab, W, x):
    """Raise each running peak (``OBS_PEAK``) in ``x`` to its signal's value at the
    last :func:`evaluate`."""
    ob = itab[I_OBS]
    for q in range(itab[I_NOB]):
        b = ob + OBS_W * q
        if itab[b] == OBS_PEAK:
            a = signal(itab, ftab, W, x, itab[b + 1])
            if a > x[itab[b + 3]]:
                x[itab[b + 3]] = a


@nb.njit(cache=True)
def rhs(t, x, road, itab, ftab, out):
    """out = dx/dt at time t, state x, road (displacement, velocity, acceleration).

    Returns True, or False where a force balance could not be solved. Called with
    contiguous arrays (the tables read-only or not), it calls :func:`evaluate` with the
    one signature that is compiled for every caller; an array of another layout compiles
    the whole of it once more."""
    W = np.empty(_work_size(itab))
    ok = evaluate(float(t), x, road, readonly(itab), readonly(ftab), W, out, np.empty(0))
    if itab[I_NOB] > 0:
        observe(readonly(itab), readonly(ftab), W, x, out, np.bool_(False))
    return ok


@nb.njit(cache=True)
def outputs(t, x, road, itab, ftab, out):
    """out = [X (nodes), V (nodes), A (nodes, NaN at massless nodes), F (elements)]."""
    nn = itab[I_NN]
    ne = itab[I_NE]
    W = np.empty(_work_size(itab))
    dx = np.empty(x.size)
    ok = evaluate(float(t), x, road, readonly(itab), readonly(ftab), W, dx, np.empty(0))
    for i in range(3 * nn + ne):
        out[i] = W[i]
    return ok


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def switches(itab, ftab, W, out):
    """The elements' switching functions (a sign change marks a kink of a force law:
    flywheel saturation, free-play contact) from the node displacements and velocities
    of the last :func:`evaluate` (in ``W``) into ``out``, two per element; returns how
    many elements have them (1.0 where an element has none).

    An element declares one switching function g(a) of its argument a (relative
    velocity or displacement), even in a: g = phi(|a|), zero at the kinks a = +-a0. Its
    two signed halves g0 + s (g - g0) and g0 - s (g - g0) (g0 = g(0), s the sign of a)
    are monotone in a, each zero at one kink: a passage from one side through the band
    between the kinks to the other changes the sign of both, which a test of the signs
    at a step's ends sees where g itself, positive at both ends, would not. The element
    is past a kink (above its band) where either half is positive."""
    nn = itab[I_NN]
    eo = itab[I_ELEM]
    count = 0
    for e in range(itab[I_NE]):
        b = eo + ELEM_W * e
        code = itab[b]
        top = itab[b + 1]
        bot = itab[b + 2]
        o = itab[b + 3]
        g = 1.0
        g0 = 1.0
        a = 0.0
        if code == SPRING:
            a = W[top] - W[bot]
            g = spring_switch(ftab, o, a)
            g0 = spring_switch(ftab, o, 0.0)
            if ftab[o + 1] > 0.0:
                count += 1
        elif code == FLYWHEEL:  # computed by evaluate (_inertial_after)
            sg = _switch_slots(itab)
            out[2 * e] = W[sg + 2 * e]
            out[2 * e + 1] = W[sg + 2 * e + 1]
            if W[sg + 2 * itab[I_NE] + e] > 0.0:
                count += 1
            continue
        elif code == TYRE:  # one kink: the contact force, and a half that never changes sign
            out[2 * e] = tyre_switch(ftab, o, W[top] - W[bot], W[nn + top] - W[nn + bot])
            out[2 * e + 1] = -1.0
            if not math.isinf(ftab[o + 2]):
                count += 1
            continue
        d = g - g0 if a >= 0.0 else g0 - g
        out[2 * e] = g0 + d
        out[2 * e + 1] = g0 - d
    return count


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def switches_read_forces(itab, ftab):
    """Whether a switching function of the system reads an element force (a one-way
    clutch's torque): then only the whole :func:`evaluate` gives them, else
    :func:`switches_at` does."""
    eo = itab[I_ELEM]
    for e in range(itab[I_NE]):
        b = eo + ELEM_W * e
        if itab[b] == FLYWHEEL and inertial_switch_reads_force(ftab, itab[b + 3]):
            return True
    return False


@nb.njit(cache=True)
def switches_at(x, road, itab, ftab, W, out):
    """:func:`switches` at the state ``x`` and road ``road`` (laid out as for
    :func:`evaluate`, held sides included) from the nodes' motion alone, without the
    forces, the solve and the derivative: the tyre's contact force and the flywheel's
    saturation read relative displacements and velocities only. For a system whose
    switching functions read no element force (:func:`switches_read_forces` False)
    the values are those of :func:`evaluate` followed by :func:`switches`, to the last
    bit. ``W`` then holds the node displacements and velocities of (x, road) only. A
    driver that holds a structure's compiled right-hand side gets them from one call of
    it with ``imp`` = :data:`SWITCHES_ONLY` and ``out`` for ``dx`` (the structure's own
    code writes those statements out too, :func:`dense_source`, on its local variables:
    it leaves the work array alone). Returns the count of
    :func:`switches` (which writes ``out`` again, with the same values)."""
    evaluate(0.0, x, road, readonly(itab), readonly(ftab), W, out, SWITCHES_ONLY.copy())
    return switches(itab, ftab, W, out)


def solve_source(m: int) -> list[str]:
    """The statements of :func:`_solve` for an m x m system written out on local
    variables: the matrix ``c{i}_{j}``, the right-hand side ``w{i}`` (its solution on
    return), ``sol`` False where the matrix is singular (as :func:`_solve` returns).
    The same operations in the same order (the pivot the first largest magnitude of its
    column, rows swapped where it is not on the diagonal, the pivot's reciprocal
    ``iv{k}``, each row's factor skipped where it is 0.0, the back substitution from the
    last row), so the solution agrees with :func:`_solve`'s to the last bit; but in
    registers: through the work array the compiler stored and loaded every entry at
    every operation, as the matrix and the right-hand side may share its memory. Only
    entries at or right of the pivot's column are swapped: those left of it are never
    read again."""
    L = ["sol = True"]
    for k in range(m):
        body = ["p = " + str(k), f"big = abs(c{k}_{k})"]
        for i in range(k + 1, m):
            body += [f"if abs(c{i}_{k}) > big:", f"    big = abs(c{i}_{k})", f"    p = {i}"]
        body += ["if big == 0.0 or not math.isfinite(big):", "    sol = False"]
        L += ["if sol:"] + ["    " + b for b in body]
        step = []
        for i in range(k + 1, m):
            swap = [f"c{k}_{j}, c{i}_{j} = c{i}_{j}, c{k}_{j}" for j in range(k, m)]
            swap.append(f"w{k}, w{i} = w{i}, w{k}")
            step += [f"{'if' if i == k + 1 else 'elif'} p == {i}:"] + ["    " + x for x in swap]
        step.append(f"iv{k} = 1.0 / c{k}_{k}")
        for i in range(k + 1, m):
            step += [f"f = c{i}_{k} * iv{k}", "if f != 0.0:"]
            step += [f"    c{i}_{j} -= f * c{k}_{j}" for j in range(k + 1, m)]
            step.append(f"    w{i} -= f * w{k}")
        L += ["if sol:"] + ["    " + x for x in step]
    back = []
    for k in range(m - 1, -1, -1):
        back.append(f"s = w{k}")
        back += [f"s -= c{k}_{j} * w{j}" for j in range(k + 1, m)]
        back.append(f"w{k} = s * iv{k}")
    L += ["if sol:"] + ["    " + x for x in back]
    return L


def dense_source(itab) -> str | None:
    """The body of :func:`evaluate` for the structure ``itab`` written out as straight-line
    Python (every table look-up, loop and branch on the structure resolved: constant
    offsets, one statement per node, element and matrix entry), for a system with
    :func:`dense_tables` whose nodes are ground, road, dynamic and combination nodes of
    dynamic nodes; None for any other. ``ftab`` stays data (masses, laws, the factor).
    The statements are those :func:`evaluate`, :func:`_node_motion`,
    :func:`_dense_solve` and :func:`_after_solve` execute for this structure, in their
    order, each sum from 0.0 term by term as there, so the result agrees with
    :func:`evaluate`'s to the last bit; but the intermediate values are local
    variables (``X3``, ``V3``, ``A3`` node 3's displacement, velocity, acceleration,
    ``F5``, ``M5`` element 5's force and inertance, ``R2`` row 2's force, then its
    acceleration), each written to the work array once, where it is an output, and
    never read back from it (the compiler keeps them in registers: it cannot where
    they go through an array that may share memory with the state), and the terms
    U^T y of the flywheels' update over coordinates that neither end of the flywheel
    touches are left out (their factor is 0.0 by construction: a term 0.0 * y adds
    nothing to a sum started from 0.0, for finite y). Called with
    :data:`SWITCHES_ONLY` (the switching functions from the nodes' motion), it computes
    them from those local variables and writes nothing to the work array (no reader
    needs it: :func:`switches_at` runs the generic :func:`evaluate`); with ``STAGE``,
    it leaves the outputs out. An impulse flow (``imp`` not empty otherwise) goes to
    :func:`evaluate` itself (the generic evaluation, compiled once for every system: an
    impulse is rare, and a second copy of its statements for the structure took a third
    of the structure's compilation). The
    names it calls are those of :data:`DENSE_IMPORTS`."""
    it = [int(v) for v in np.asarray(itab, dtype=np.int64)]
    db = it[I_DNS]
    if db == 0 or it[I_NV] or it[I_NP] or it[I_NR]:
        return None
    nn, ne, nd = it[I_NN], it[I_NE], it[I_ND]
    no, eo = it[I_NODE], it[I_ELEM]
    iv, ia, iF = nn, 2 * nn, 3 * nn
    nlen = 3 * max(it[I_NRD], 1) + 1 + ne
    hs = nlen - ne
    sg = 3 * nn + ne + nd * nd + nd + ne  # _switch_slots (no velocity nodes)
    typ = [it[no + NODE_W * n] for n in range(nn)]
    if any(t not in (GROUND, ROAD, DYN, LIN) for t in typ):
        return None
    row = [it[no + NODE_W * n + 3] for n in range(nn)]

    def members(n):  # (member node, ftab offset of its coefficient)
        b = no + NODE_W * n
        return [(it[it[b + 1] + j], it[b + 3] + j) for j in range(it[b + 2])]

    lins = [n for n in range(nn) if typ[n] == LIN]
    if any(typ[mem] != DYN for n in lins for mem, _ in members(n)):
        return None

    def combo(n, q):
        s = "0.0"
        for mem, c in members(n):
            s = f"({s} + ftab[{c}] * {q}{mem})"
        return s

    def coords(n):  # the coordinates (mass-matrix rows) node n moves
        if typ[n] == DYN:
            return {row[n]}
        return {row[mem] for mem, _ in members(n)} if typ[n] == LIN else set()

    def switch_lines(pos, vel, halves):
        """switches() into dx, the nodes' displacements and velocities read as the
        expressions pos(n), vel(n), a flywheel's two halves by the statements
        halves(e, o, slot, top, bot)."""
        out = []
        for e in range(ne):
            b = eo + ELEM_W * e
            code, top, bot, o, slot = it[b], it[b + 1], it[b + 2], it[b + 3], it[b + 4]
            if code == SPRING:
                out += [f"    a = {pos(top)} - {pos(bot)}", f"    g = spring_switch(ftab, {o}, a)",
                        f"    g0 = spring_switch(ftab, {o}, 0.0)",
                        "    d = g - g0 if a >= 0.0 else g0 - g",
                        f"    dx[{2 * e}] = g0 + d", f"    dx[{2 * e + 1}] = g0 - d"]  # fmt: skip
            elif code == FLYWHEEL:
                out += halves(e, o, slot, top, bot)
            elif code == TYRE:
                out += [f"    dx[{2 * e}] = tyre_switch(ftab, {o}, {pos(top)} - {pos(bot)}, "
                        f"{vel(top)} - {vel(bot)})", f"    dx[{2 * e + 1}] = -1.0"]  # fmt: skip
            else:  # no switching function: its halves 1.0 + 0.0 and 1.0 - 0.0
                out += [f"    dx[{2 * e}] = 1.0", f"    dx[{2 * e + 1}] = 1.0"]
        return out

    # switches() of the work array (the halves its evaluation stored)
    S = switch_lines(lambda n: f"W[{n}]", lambda n: f"W[{nn + n}]", lambda e, o, slot, top, bot: [
        f"    dx[{2 * e}] = W[{sg + 2 * e}]", f"    dx[{2 * e + 1}] = W[{sg + 2 * e + 1}]"])
    # the same from the nodes' motion in the local variables (the halves computed there)
    SL = switch_lines(lambda n: f"X{n}", lambda n: f"V{n}", lambda e, o, slot, top, bot: [
        f"    side = road[{hs + e}] if held else 0.0",
        f"    g, g0, kd = _switch_pair(ftab, x, {o}, {slot}, side, X{top} - X{bot}, "
        f"V{top} - V{bot}, 0.0)", f"    dx[{2 * e}] = g", f"    dx[{2 * e + 1}] = g0"])
    L = ["if imp.size == 1 and imp[0] == -math.inf:  # SWITCHES_OF_WORK: switches()"] + S
    L += ["    return True",
          "only = imp.size == 1 and imp[0] == math.inf  # SWITCHES_ONLY",
          "stage = imp.size == 2 and imp[0] == math.inf  # STAGE: no outputs in W",
          "if imp.size != 0 and not only and not stage:",
          "    return evaluate(t, x, road, ITAB, ftab, W, dx, imp)"]  # fmt: skip
    L.append(f"held = road.size >= {nlen}")
    for n in range(nn):
        if typ[n] == GROUND:
            L += [f"X{n} = 0.0", f"V{n} = 0.0", f"A{n} = 0.0"]
        elif typ[n] == ROAD:
            k = 3 * row[n] if row[n] > 0 else 0
            L += [f"X{n} = road[{k}]", f"V{n} = road[{k + 1}]", f"A{n} = road[{k + 2}]"]
        elif typ[n] == DYN:
            b = no + NODE_W * n
            L += [f"X{n} = x[{it[b + 1]}]", f"V{n} = x[{it[b + 2]}]"]
    for n in lins:
        L.append(f"X{n} = {combo(n, 'X')}")
    for n in lins:
        L.append(f"V{n} = {combo(n, 'V')}")
    # the switching functions alone, from the nodes' motion (_inertial_after's without
    # rates, then switches()), into dx: from the local variables, the work array left alone
    L.append("if only:")
    L += SL
    L.append("    return True")
    L.append("if not stage:")
    for n in range(nn):  # the node outputs known before the forces
        L += [f"    W[{n}] = X{n}", f"    W[{iv + n}] = V{n}"]
        if typ[n] in (GROUND, ROAD):
            L.append(f"    W[{ia + n}] = A{n}")
    for n in lins:  # the forces gathered at a combination node
        L.append(f"G{n} = 0.0")
    L.append("ok = True")
    # _dense_solve: each element's force on its ends' rows
    for i in range(nd):
        L.append(f"R{i} = 0.0")

    def gather(n, g):
        if typ[n] == LIN:
            return [f"G{n} += {g}"]
        if typ[n] == DYN:
            return [f"R{row[n]} += {g}"]
        return []

    inertial = []
    for e in range(ne):
        b = eo + ELEM_W * e
        code, top, bot, o, slot = it[b], it[b + 1], it[b + 2], it[b + 3], it[b + 4]
        side = f"(road[{hs + e}] if held else 0.0)"
        L += [f"d = X{top} - X{bot}", f"v = V{top} - V{bot}"]
        if code == SPRING:
            L += [f"F{e} = spring_force(ftab, {o}, d)"]
        elif code == DAMPER:
            L += [f"F{e}, _ = damper_force(ftab, {o}, v)"]
        elif code == FRICTION:
            L += [f"F{e}, _ = friction_force(ftab[{o}], ftab[{o + 1}], v)"]
        elif code == INERTER:
            L += [f"M{e} = inerter_inertance(ftab, {o})", f"F{e} = 0.0"]
        elif code == TYRE:
            L += [f"F{e} = tyre_force(ftab, {o}, d, v, {side})"]
        elif code == FLYWHEEL:
            L.append(f"M{e}, F{e} = inertial_law(ftab, {o}, d, v, x, {slot}, dx, {side})")
        else:
            return None
        L.append(f"g = F{e}")
        if code in (INERTER, FLYWHEEL):
            inertial.append(e)
            known = []
            if typ[top] == ROAD:
                known.append(f"    g += M{e} * A{top}")
            if typ[bot] == ROAD:
                known.append(f"    g -= M{e} * A{bot}")
            if known:
                L += [f"if M{e} != 0.0:", *known]
        L += gather(top, "-g") + gather(bot, "g")
    for n in lins:  # _pass_on
        for mem, c in members(n):
            L.append(f"R{row[mem]} += ftab[{c}] * G{n}")
    fo, m = it[db], it[db + 1]
    var = it[db + 2 : db + 2 + m]
    zo = fo + nd * nd
    so = zo + nd * m
    uo = so + m * m
    ro = uo + m * nd
    for i in range(nd):
        s = "0.0"
        for j in range(nd):
            s = f"({s} + ftab[{fo + i * nd + j}] * R{j})"
        L.append(f"y{i} = {s}")
    if m > 0:
        for k in range(m):
            b = eo + ELEM_W * var[k]
            touched = coords(it[b + 1]) | coords(it[b + 2])
            L.append(f"mk{k} = M{var[k]} - ftab[{ro + k}]")
            s = "0.0"
            for j in range(nd):
                if j in touched:
                    s = f"({s} + ftab[{uo + k * nd + j}] * y{j})"
            L.append(f"w{k} = mk{k} * {s}")
        # every inertance at the factor's (its rows of I + D S are the identity's, w is
        # 0): a = y; one away from it: one unknown (the elimination's own operations)
        L.append("nz = " + " + ".join(f"(mk{k} != 0.0)" for k in range(m)))
        L.append("if nz == 0:")
        L += [f"    R{i} = y{i}" for i in range(nd)]
        L.append("else:")
        full = []
        for k in range(m):
            for j in range(m):
                one = 1.0 if j == k else 0.0
                full.append(f"c{k}_{j} = {one} + mk{k} * ftab[{so + k * m + j}]")
        full += solve_source(m)
        if m > 1:
            L.append("    if nz == 1:")
            for k in range(m):
                L += [
                    "        " + ("if" if k == 0 else "elif") + f" mk{k} != 0.0:"
                    if k < m - 1
                    else "        else:",
                    f"            c{k}_{k} = 1.0 + mk{k} * ftab[{so + k * m + k}]",
                    f"            sol = c{k}_{k} != 0.0 and math.isfinite(c{k}_{k})",
                    "            if sol:",
                    f"                w{k} = w{k} * (1.0 / c{k}_{k})",
                ]
            L.append("    else:")
            L += ["        " + x for x in full]
        else:
            L += ["    " + x for x in full]
        L.append("    if not sol:")
        L.append("        ok = False")
        L += [f"        R{i} = y{i}" for i in range(nd)]
        L.append("    else:")
        for i in range(nd):
            s = "0.0"
            for k in range(m):
                s = f"({s} + ftab[{zo + i * m + k}] * w{k})"
            L.append(f"        R{i} = y{i} - {s}")
    else:
        L += [f"R{i} = y{i}" for i in range(nd)]
    # _after_solve (the work array's outputs, in a stage left out, after the derivative)
    out = []
    for n in range(nn):
        if typ[n] == DYN:
            b = no + NODE_W * n
            L += [f"A{n} = R{row[n]}", f"dx[{it[b + 1]}] = V{n}", f"dx[{it[b + 2]}] = A{n}"]
            out.append(f"    W[{ia + n}] = A{n}")
    for n in lins:
        L.append(f"A{n} = {combo(n, 'A')}")
        out.append(f"    W[{ia + n}] = A{n}")
    for e in inertial:
        b = eo + ELEM_W * e
        top, bot = it[b + 1], it[b + 2]
        L += [f"if M{e} != 0.0:", f"    F{e} += M{e} * (A{top} - A{bot})"]
    for e in range(ne):
        out.append(f"    W[{iF + e}] = F{e}")
    for e in range(ne):  # _inertial_after
        b = eo + ELEM_W * e
        out.append(f"    W[{sg + 2 * ne + e}] = 0.0")
        if it[b] != FLYWHEEL:
            continue
        top, bot, o, slot = it[b + 1], it[b + 2], it[b + 3], it[b + 4]
        L += [f"side = road[{hs + e}] if held else 0.0",
              f"rate = inertial_rate(ftab, {o}, V{top} - V{bot}, A{top} - A{bot}, x, {slot}, side)",
              "if not math.isnan(rate):",
              f"    dx[{slot}] = rate"]  # fmt: skip
        out += [f"    side = road[{hs + e}] if held else 0.0",
                f"    _switch_halves(ftab, W, x, {e}, {top}, {bot}, {o}, {slot}, side, V{top} - V{bot}, "
                f"F{e}, {sg}, {ne})"]  # fmt: skip
    L += ["if not stage:", *out, "return ok"]
    return "\n".join("    " + line for line in L) + "\n"


#: the module-level names :func:`dense_source`'s statements call
DENSE_IMPORTS = (
    "import math\n"
    "from inerterlab.elements._inertial import inertial_law, inertial_rate\n"
    "from inerterlab.elements.damper import damper_force\n"
    "from inerterlab.elements.friction import friction_force\n"
    "from inerterlab.elements.inerter import inerter_inertance\n"
    "from inerterlab.elements.spring import spring_force, spring_switch\n"
    "from inerterlab.elements.tyre import tyre_force, tyre_switch\n"
    "from inerterlab.systems._kernel import _switch_halves, _switch_pair\n"
)
