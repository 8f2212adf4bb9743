"""Adaptive Dormand-Prince 5(4) for the core systems, with road segments and road steps.

The tableau, error weights and the order-4 continuous extension are DOPRI5's; the
step-size control is the classic one of Hairer, Norsett and Wanner (Solving ODEs I,
II.4): h_new = h min(5, max(0.2, 0.9 err^(-1/5))). Steps never cross a road segment
edge; where the road displacement jumps at an edge, the impulse that the dampers
attached to the road pass (c x jump per unit jump, precomputed) is applied by
integrating the impulse flow M(x)^-1 J over a unit interval with the same pair at
rtol 1e-13: exact for constant inertances (one step) and, for a speed-dependent one,
the momentum balance the force law implies (thesis law: the integral of m_e(v) dv).
"""

from __future__ import annotations

import math
import time

import numba as nb
import numpy as np

from ._compiled import record, rhs_for
from ._kernel import (
    ELEM_W,
    GROUND,
    I_DNS,
    I_ELEM,
    I_NE,
    I_NN,
    I_NOB,
    I_NODE,
    I_OBS,
    NODE_W,
    OBS_FOURTH,
    OBS_LINEAR,
    OBS_PEAK,
    OBS_SQUARE,
    OBS_W,
    ROAD,
    _work_size,
    end_force,
    observe,
    peaks,
    road_layout_of,
    signal,
    switches,
    switches_read_forces,
)
from .observers import NO_SPLIT, filter_split

# The Dormand-Prince 5(4) pair (Dormand & Prince 1980; the coefficients as in Hairer,
# Norsett & Wanner, Solving ODEs I, Table II.5.2), its error weights (order 5 minus
# order 4) and the weights of DOPRI5's order-4 continuous extension.
C2, C3, C4, C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = (
    9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0,
)  # fmt: skip
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
E1, E3, E4, E5, E6, E7 = (
    71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0,
    -1.0 / 40.0,
)  # fmt: skip
D1, D3, D4, D5, D6, D7 = (
    -12715105075.0 / 11282082432.0, 87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0,
)  # fmt: skip

#: the Dormand-Prince pair as arrays (rows of the stages; the last row is the order-5
#: weights), error weights and dense-output weights, from the named constants
_TAB_A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [A21, 0.0, 0.0, 0.0, 0.0, 0.0],
        [A31, A32, 0.0, 0.0, 0.0, 0.0],
        [A41, A42, A43, 0.0, 0.0, 0.0],
        [A51, A52, A53, A54, 0.0, 0.0],
        [A61, A62, A63, A64, A65, 0.0],
        [B1, 0.0, B3, B4, B5, B6],
    ]
)
_TAB_C = np.array([0.0, C2, C3, C4, C5, 1.0, 1.0])
_TAB_E = np.array([E1, 0.0, E3, E4, E5, E6, E7])
_TAB_D = np.array([D1, 0.0, D3, D4, D5, D6, D7])

OK, TOO_MANY_STEPS, STEP_TOO_SMALL, NOT_FINITE, ROAD_STEP, BALANCE_FAILED = 0, 1, 2, 3, 4, 5
IMPULSE_RTOL = 1e-13
#: an exact step in a linear regime keeps every regime's argument at least this many
#: times its threshold
X_MARGIN = 1.1
# crossings closer than this (a fraction of the step) to the earliest one in a step are
# one event: their elements switch together at its instant
SIMULTANEOUS = 1e-9
# a switching function just past its crossing starts the next step at this value with
# the sign of its new side (not at 0, as it did: a return across the kink within that
# step, an adaptive flywheel grazing its saturation speed, was then no sign change and
# went unseen, and the element kept the other side's law; docs/decisions.md, stop 62)
PAST_KINK = 1e-150
# a return is located after the last point where the function still has its new side's
# sign, found by halving the step towards its start down to this fraction of it; found
# nowhere, the function turned back at once (the crossing's rounding, or a sliding mode
# along the kink, each side's law driving it towards the other): not an event, the
# element keeps its new side (a search from the start itself stopped in the crossing's
# rounding, and the two sides then took turns at one instant until the step budget ran
# out)
RETURN_LEAST = 1e-6


# The helpers the stepping calls per stage, step or event allocate nothing and are
# compiled without numba's reference counting (``_nrt=False``): see the note in
# :mod:`._kernel` (the counting of their array arguments cost more than their work).
# They take numpy's error model, as the element kernels do: a division by zero gives inf
# or nan, which an attempt's finiteness test turns into a smaller step or a status,
# where Python's model tested every division and would raise out of the kernel (on the
# sine run, 1-2 % of its time; the results equal to the last bit).


@nb.njit(cache=True, inline="always")
def road_at(segs, i, t, out):
    """Road displacement, velocity, acceleration on segment ``segs[i]`` at time t (the
    table and a row number, not a row: a slice per call costs a view)."""
    kind = segs[i, 2]
    t0 = segs[i, 0]
    if kind == 3.0:  # several roads, each linear: (x_k, rate_k) from column 3 on
        for k in range(min((segs.shape[1] - 3) // 2, out.size // 3)):
            out[3 * k] = segs[i, 3 + 2 * k] + segs[i, 4 + 2 * k] * (t - t0)
            out[3 * k + 1] = segs[i, 4 + 2 * k]
            out[3 * k + 2] = 0.0
    elif kind == 0.0:
        out[0] = segs[i, 3] + segs[i, 4] * (t - t0)
        out[1] = segs[i, 4]
        out[2] = 0.0
    elif kind == 2.0:  # a measured drive: cubic x, v; the acceleration channel, linear
        u = t - t0
        c1, c2, c3 = segs[i, 4], segs[i, 5], segs[i, 6]
        a0 = segs[i, 7]
        out[0] = segs[i, 3] + u * (c1 + u * (c2 + u * c3))
        out[1] = c1 + u * (2.0 * c2 + 3.0 * u * c3)
        out[2] = a0 + (segs[i, 8] - a0) * (u / (segs[i, 1] - t0))
    else:
        w, ph, amp = segs[i, 6], segs[i, 7], segs[i, 5]
        s = math.sin(w * t + ph)
        out[0] = segs[i, 3] + amp * s
        out[1] = amp * w * math.cos(w * t + ph)
        out[2] = -amp * w * w * s


@nb.njit(cache=True, inline="always")
def _segment_at(segs, rng, t):
    """The segment of rng[0] <= i < rng[1] that holds t, walking from the last one found
    (rng[2], updated): the current one while t is inside it or on either of its ends, so
    a step's stages all take the segment it started on, its last stage that segment's
    left limit at the next edge (:func:`_advance` moves rng[2] on at the start of the
    step that follows)."""
    i = rng[2]
    while i + 1 < rng[1] and segs[i + 1, 0] < t:
        i += 1
    while i > rng[0] and segs[i, 0] > t:
        i -= 1
    rng[2] = i
    return i


@nb.njit(cache=True, inline="always")
def _linear_columns(segs, i):
    """One past the last column of the (height, rate) pairs of a linear segment: one
    road (kind 0) or several (kind 3)."""
    return 5 if segs[i, 2] == 0.0 else segs.shape[1]


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _kinked(segs, i, j):
    """Whether the road's rate changes from segment i to segment j (linear segments,
    kinds 0 and 3: any of its roads'; a measured drive's pieces, kind 2, join with
    continuous rates)."""
    if segs[i, 2] != 3.0 and segs[i, 2] != 0.0:
        return False
    for c in range(4, _linear_columns(segs, i), 2):
        if segs[i, c] != segs[j, c]:
            return True
    return False


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _joins(segs, i, jump_tol):
    """Whether the linear segment i + 1 (kind 0 or 3, as segment i) starts where segment
    i ends on every road, to ``jump_tol``: one run of :func:`_advance` then crosses the
    edge."""
    dt = segs[i, 1] - segs[i, 0]
    if segs[i + 1, 0] != segs[i, 1] or segs[i + 1, 2] != segs[i, 2]:
        return False
    for c in range(3, _linear_columns(segs, i) - 1, 2):
        if abs(segs[i, c] + segs[i, c + 1] * dt - segs[i + 1, c]) > jump_tol:
            return False
    return True


@nb.njit(cache=True, inline="always")
def _f(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy, road, work, stats, oit, fzi):
    """The derivative at (t, y), the observers' included: those of ``oit`` (the
    system's table, or a copy whose observers are those the stages move); the slots the
    stages leave (``fzi``, see :func:`_fz_begin`: a filter and its quadratures, advanced
    outside the stages, and the running peaks) get derivative 0."""
    stats[2] += 1
    if mode == 0:
        road_at(segs, _segment_at(segs, rng, t), t, road)
    elif mode == 1:
        road[0] = road_fixed[0]
        road[1] = road_fixed[1]
        road[2] = 0.0
    else:  # a road velocity jump: v from road_fixed[1] by road_fixed[2] over t in [0, 1]
        road[0] = road_fixed[0]
        road[1] = road_fixed[1] + t * road_fixed[2]
        road[2] = road_fixed[2]
    ok = ev(t, y, road, itab, ftab, work, dy, imp)
    if oit[I_NOB] > 0:
        observe(oit, ftab, work, y, dy, mode != 0)
    d0 = FZ_HEAD + fzi[0] + fzi[1] + fzi[2]
    for i in range(d0, d0 + fzi[3]):
        dy[fzi[i]] = 0.0
    return ok


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _f_once(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy, road, work, stats, oit,
            fzi):  # fmt: skip
    """:func:`_f` as a call, for the places that evaluate once per phase (a first
    stage after exact steps or a kink): not inlined there, to keep compilation short."""
    return _f(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy, road, work, stats, oit,
              fzi)  # fmt: skip


@nb.njit(cache=True, inline="always")
def _dense(y, yt, K, h, th, out):
    """The order-4 continuous extension of the step y -> yt at theta = th."""
    th1 = 1.0 - th
    for i in range(y.size):
        r2, r3, r4, r5 = _dense_terms(y, yt, K, h, i)
        out[i] = y[i] + th * (r2 + th1 * (r3 + th * (r4 + th1 * r5)))


@nb.njit(cache=True, inline="always")
def _dense_terms(y, yt, K, h, i):
    """The coefficients (r2, r3, r4, r5) of component ``i``'s order-4 continuous
    extension y + th (r2 + (1 - th) (r3 + th (r4 + (1 - th) r5)))."""
    r2 = yt[i] - y[i]
    r3 = h * K[0, i] - r2
    r4 = r2 - h * K[6, i] - r3
    acc = 0.0
    for q in range(7):
        acc += _TAB_D[q] * K[q, i]
    return r2, r3, r4, h * acc


# ---------------------------------------------------------------------------------------
# a linear filter among the observers (the Wk weighting), advanced outside the stages of
# the Dormand-Prince steps (tables of :func:`.observers.filter_split`, flat, so that a
# call passes four arrays, not a dozen): with w = z - Q y, w' = A w + (A Q + P) y; over
# an accepted step the continuous extension of y, a quartic in the step's fraction
# theta, drives w exactly, per mode of A = V diag(lam) V^-1.
#
# fzi (int64): nf, m, nq, nd, ns, then the filter's slots (nf), the state columns it and
#   its quadratures read (m), the quadrature observers (nq), the slots the stages leave
#   (nd: the filter, its quadratures, the running peaks)
# fzf (float64): Q (nf x m), the modes' weights (ns: 2 for one of a complex pair, 1 for a
#   real one), Gauss-Legendre nodes (5, symmetric about 1/2) and weights (5), R (2 nq x m)
# fzc (complex128): lam (ns), V (nf x ns), V^-1 (ns x nf), V^-1 (A Q + P) (ns x m),
#   S (2 nq x ns): the quadratures' signals (two rows each: a product's two factors)
#   are Re(S W) + R y over the modes' weighted values W and the states they read
# a step (:func:`_fz_begin`): stc (complex) the modes' coefficients (ns x (FZ_TERMS +
#   5)), e^(x theta) at the nodes and the end (ns x 6) and the modes' values at the
#   middle node and the end, weights included (ns x 6, by :func:`_fz_step`); stf
#   (float) the accepted length, the modes' Taylor terms (ns; 0: particular solution),
#   w0 (nf), the quartic's coefficients (5 x m), then scratch of :func:`_fz_nodes`: a
#   signal's polynomial (FZ_TERMS) and two signals at the nodes (2 x 5)

#: |lam h| below which a filter's mode over a step is summed as its Taylor series in the
#: step's fraction; above it, as a polynomial particular solution plus e^(lam tau) times
#: the initial difference (the particular solution's coefficients grow as k! / |lam h|^k:
#: at 0.5, at most about 900 roundings lost)
FZ_TAYLOR = 0.5
#: the most terms of that Taylor series (|lam h| < 0.5: the 26th is below 1e-25 of the
#: first)
FZ_TERMS = 26
FZ_W = FZ_TERMS + 5  # a mode's row of coefficients in stc
FZ_ST = FZ_W + 12  # all stc holds per mode
FZ_HEAD = 5  # fzi's header


@nb.njit(cache=True)
def fz_scratch(fzi):
    """(stc, stf): the scratch of one filter step for the tables ``fzi``."""
    nf, m, ns = fzi[0], fzi[1], fzi[4]
    return np.zeros(ns * FZ_ST, np.complex128), np.zeros(1 + ns + nf + 5 * m + FZ_TERMS + 10)


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _fz_begin(fzi, fzf, fzc, stc, stf, y, ya, K, h, thx):
    """Set up the filter's accepted step theta in [0, thx] of the attempt (y, ya, K, h):
    per mode (eigenvalue lam, x = lam hs, hs the accepted length) the solution of
    dw/dtheta = x w + hs beta(theta), beta the quartic input through the mode, as its
    Taylor series in theta (terms > 0) or as the polynomial q with q' = x q + hs beta
    plus e^(x theta) (w0 - q(0)) (terms = 0: q's coefficients, w0 - q(0), x)."""
    nf, m, ns = fzi[0], fzi[1], fzi[4]
    fs = FZ_HEAD
    co = fs + nf
    lam0, vi0 = 0, ns + nf * ns
    h0 = vi0 + ns * nf
    fn0, wz0 = 1, 1 + ns
    cf0 = wz0 + nf
    hs = thx * h
    stf[0] = hs
    for j in range(m):
        i = fzi[co + j]
        r2, r3, r4, r5 = _dense_terms(y, ya, K, h, i)
        # the continuous extension y + th (r2 + (1 - th) (r3 + th (r4 + (1 - th) r5)))
        # in powers of theta' = th / thx
        stf[cf0 + j] = y[i]
        stf[cf0 + m + j] = (r2 + r3) * thx
        stf[cf0 + 2 * m + j] = (r4 + r5 - r3) * thx * thx
        stf[cf0 + 3 * m + j] = -(r4 + 2.0 * r5) * thx * thx * thx
        stf[cf0 + 4 * m + j] = r5 * thx * thx * thx * thx
    for i in range(nf):
        acc = y[fzi[fs + i]]
        for j in range(m):
            acc -= fzf[i * m + j] * y[fzi[co + j]]
        stf[wz0 + i] = acc
    for p in range(ns):
        w0 = 0j
        for i in range(nf):
            w0 += fzc[vi0 + p * nf + i] * stf[wz0 + i]
        x = fzc[lam0 + p] * hs
        r = p * FZ_W
        for k in range(5):  # hs beta_k: the input's coefficients in theta
            b = 0j
            for j in range(m):
                b += fzc[h0 + p * m + j] * stf[cf0 + k * m + j]
            stc[r + FZ_TERMS + k] = hs * b
        if abs(x.real) + abs(x.imag) < FZ_TAYLOR:
            a = w0
            stc[r] = a
            big = abs(a.real) + abs(a.imag)
            nt = FZ_TERMS
            for j in range(FZ_TERMS - 1):
                a = x * a + (stc[r + FZ_TERMS + j] if j < 5 else 0j)
                a = a * (1.0 / (j + 1.0))
                stc[r + j + 1] = a
                mag = abs(a.real) + abs(a.imag)
                big = max(big, mag)
                if j >= 5 and mag <= 1e-18 * big:
                    nt = j + 2
                    break
            stf[fn0 + p] = nt
        else:
            xi = 1.0 / x
            q = -stc[r + FZ_TERMS + 4] * xi
            stc[r + 4] = q
            for k in range(3, -1, -1):
                q = ((k + 1.0) * q - stc[r + FZ_TERMS + k]) * xi
                stc[r + k] = q
            stc[r + 5] = w0 - q
            stc[r + 6] = x
            stf[fn0 + p] = 0.0


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _fz_at(fzi, fzf, fzc, stc, stf, th, out, c):
    """The filter's states at theta = th of the step set up by :func:`_fz_begin` into
    their slots of ``out``, which holds the states they read there; ``c``: the point
    of :func:`_fz_step` (0-4 the nodes, 5 the end) that th is, whose modes' values it
    kept, or -1."""
    nf, m, ns = fzi[0], fzi[1], fzi[4]
    fs = FZ_HEAD
    co = fs + nf
    om0 = nf * m
    v0 = ns
    wv0 = ns * (FZ_W + 6)
    for i in range(nf):
        acc = 0.0
        for j in range(m):
            acc += fzf[i * m + j] * out[fzi[co + j]]
        out[fzi[fs + i]] = acc
    for p in range(ns):
        if c >= 0:
            w = stc[wv0 + 6 * p + c]
        else:
            nt = int(stf[1 + p])
            r = p * FZ_W
            if nt > 0:
                w = stc[r + nt - 1]
                for j in range(nt - 2, -1, -1):
                    w = w * th + stc[r + j]
            else:
                w = stc[r + 4]
                for j in range(3, -1, -1):
                    w = w * th + stc[r + j]
                w += np.exp(stc[r + 6] * th) * stc[r + 5]
            w *= fzf[om0 + p]
        for i in range(nf):
            v = fzc[v0 + i * ns + p]
            out[fzi[fs + i]] += v.real * w.real - v.imag * w.imag


@nb.njit(cache=True, inline="always")
def _fz_nodes(fzf, fzc, stc, stf, m, ns, nf, r, s, nd, v):
    """A quadrature's signal Re(S W) + R y at the five Gauss nodes of the filter's step
    into stf[v:v + 5] (its row of R at fzf[r:], of S at fzc[s:]): the modes' series and
    the quartic of the states it reads summed first into one real polynomial in theta
    (nd coefficients, in stf after the quartic's), evaluated at the nodes, plus the
    exponential part of each mode summed as a particular solution (its e^(x theta) at
    the nodes kept in stc by :func:`_fz_step`)."""
    cf0 = 1 + ns + nf
    pc = cf0 + 5 * m
    om0 = nf * m
    gx0 = om0 + ns
    ex0 = ns * FZ_W
    for k in range(5):
        acc = 0.0
        for j in range(m):
            acc += fzf[r + j] * stf[cf0 + k * m + j]
        stf[pc + k] = acc
    for k in range(5, nd):
        stf[pc + k] = 0.0
    for i in range(5):
        stf[v + i] = 0.0
    for p in range(ns):
        g = fzc[s + p] * fzf[om0 + p]
        nt = int(stf[1 + p])
        rr = p * FZ_W
        for k in range(nt if nt > 0 else 5):
            a = stc[rr + k]
            stf[pc + k] += g.real * a.real - g.imag * a.imag
        if nt == 0:
            gd = g * stc[rr + 5]
            b = ex0 + 6 * p
            for i in range(5):
                e = stc[b + i]
                stf[v + i] += gd.real * e.real - gd.imag * e.imag
    t0, t1, t2, t3, t4 = fzf[gx0], fzf[gx0 + 1], fzf[gx0 + 2], fzf[gx0 + 3], fzf[gx0 + 4]
    c = stf[pc + nd - 1]
    a0, a1, a2, a3, a4 = c, c, c, c, c
    for k in range(nd - 2, -1, -1):  # the five sums side by side
        c = stf[pc + k]
        a0 = a0 * t0 + c
        a1 = a1 * t1 + c
        a2 = a2 * t2 + c
        a3 = a3 * t3 + c
        a4 = a4 * t4 + c
    stf[v] += a0
    stf[v + 1] += a1
    stf[v + 2] += a2
    stf[v + 3] += a3
    stf[v + 4] += a4


@nb.njit(cache=True, inline="always")
def _fz_same(fzf, fzc, m, ns, r, s, r1, s1):
    """Whether a quadrature's signal (rows at fzf[r:], fzc[s:]) is the one at fzf[r1:],
    fzc[s1:] (a ride's int a_w^2 and int a_w^4 read one signal)."""
    for j in range(m):
        if fzf[r + j] != fzf[r1 + j]:
            return False
    for p in range(ns):
        if fzc[s + p] != fzc[s1 + p]:
            return False
    return True


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _fz_step(fzi, fzf, fzc, stc, stf, itab, y, ya, K, h, thx, yt):
    """Advance the filter and its quadrature observers over the accepted step theta in
    [0, thx] of the attempt (y, ya, K, h), ending at yt (its other states set): the
    filter exactly, the quadratures (their signals over the filter and the states it
    reads) by the Gauss-Legendre sums on it (:func:`_fz_nodes`). (stc, stf) keep the
    step for values inside it; the modes' values at the middle node and the end are
    kept for the peaks' midpoint and the step's end."""
    nf, m, nq, ns = fzi[0], fzi[1], fzi[2], fzi[4]
    co = FZ_HEAD + nf
    qu = co + m
    gx0 = nf * m + ns
    gw0 = gx0 + 5
    _fz_begin(fzi, fzf, fzc, stc, stf, y, ya, K, h, thx)
    hs = stf[0]
    ex0 = ns * FZ_W
    nd = 5  # the coefficients of the signals' polynomials
    for p in range(ns):
        nt = int(stf[1 + p])
        nd = max(nd, nt)
        if nt == 0:  # e^(x theta) at the five nodes, symmetric about 1/2, and at 1
            x = stc[p * FZ_W + 6]
            e0 = np.exp(x * fzf[gx0])
            e1 = np.exp(x * fzf[gx0 + 1])
            eh = np.exp(x * fzf[gx0 + 2])
            e5 = eh * eh
            b = ex0 + 6 * p
            stc[b] = e0
            stc[b + 1] = e1
            stc[b + 2] = eh
            stc[b + 3] = e5 / e1 if e1 != 0.0 else 0j
            stc[b + 4] = e5 / e0 if e0 != 0.0 else 0j
            stc[b + 5] = e5
    # the modes at the middle node and the end, the two sums side by side
    om0 = nf * m
    wv0 = ns * (FZ_W + 6)
    t2 = fzf[gx0 + 2]
    for p in range(ns):
        nt = int(stf[1 + p])
        r = p * FZ_W
        if nt > 0:
            top, j0 = nt - 1, nt - 2
        else:
            top, j0 = 4, 3
        cf = stc[r + top]
        w2, w5 = cf, cf
        for j in range(j0, -1, -1):
            cf = stc[r + j]
            w2 = w2 * t2 + cf
            w5 = w5 + cf
        if nt == 0:
            b = ex0 + 6 * p
            d = stc[r + 5]
            w2 += stc[b + 2] * d
            w5 += stc[b + 5] * d
        om = fzf[om0 + p]
        b = wv0 + 6 * p
        stc[b + 2] = w2 * om
        stc[b + 5] = w5 * om
    ob = itab[I_OBS]
    r0 = gw0 + 5  # R in fzf, S in fzc
    s0 = ns + 2 * nf * ns + ns * m
    va = 1 + ns + nf + 5 * m + FZ_TERMS  # the signals at the nodes, in stf
    vb = va + 5
    for q in range(nq):
        bo = ob + OBS_W * fzi[qu + q]
        kind = itab[bo]
        for f in range(1 if kind == OBS_SQUARE or kind == OBS_FOURTH else 2):  # its factors
            r = r0 + (2 * q + f) * m
            c = s0 + (2 * q + f) * ns
            if f == 1 or q == 0 or not _fz_same(fzf, fzc, m, ns, r, c, r - 2 * m, c - 2 * ns):
                _fz_nodes(fzf, fzc, stc, stf, m, ns, nf, r, c, nd, va + 5 * f)
        acc = 0.0
        for p in range(5):
            a = stf[va + p]
            if kind == OBS_SQUARE:
                v = a * a
            elif kind == OBS_FOURTH:
                v = a * a
                v = v * v
            else:
                v = a * stf[vb + p]
            acc += fzf[gw0 + p] * v
        slot = itab[bo + 3]
        yt[slot] = y[slot] + hs * acc
    _fz_at(fzi, fzf, fzc, stc, stf, 1.0, yt, np.int64(5))


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _fz_sample(fzi, fzf, fzc, stc, stf, itab, th, y, yt, out):
    """A sample at theta = th of the accepted step from y to yt (``out`` holds its other
    states): the filter exactly, its quadratures linear between the step's ends."""
    _fz_at(fzi, fzf, fzc, stc, stf, th, out, np.int64(-1))
    qu = FZ_HEAD + fzi[0] + fzi[1]
    ob = itab[I_OBS]
    for q in range(fzi[2]):
        s = itab[ob + OBS_W * fzi[qu + q] + 3]
        out[s] = y[s] + th * (yt[s] - y[s])


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _peak_values(itab, ftab, work, y, out):
    """Each observer's signal at the last evaluation into ``out`` (peaks only; the
    others are left as they are)."""
    ob = itab[I_OBS]
    for q in range(itab[I_NOB]):
        b = ob + OBS_W * q
        if itab[b] == OBS_PEAK:
            out[q] = signal(itab, ftab, work, y, itab[b + 1])


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _peak_at(ev, q, x, t, h, y, yx, K, mode, segs, rng, itab, ftab, imp, road_fixed, dy, road,
             work, stats, yd, oit, fzi, fzf, fzc, stc, stf, thx):  # fmt: skip
    """Signal of observer q at theta = x of the step (y, yx, K, h), on its continuous
    extension (a filter outside the stages: exactly, at x / thx of the accepted step
    (stc, stf) of :func:`_fz_begin`)."""
    _dense(y, yx, K, h, x, yd)
    if fzi[0]:
        _fz_at(fzi, fzf, fzc, stc, stf, x / thx, yd, np.int64(-1))
    _f_once(ev, mode, segs, rng, t + x * h, yd, itab, ftab, imp, road_fixed, dy, road, work, stats, oit, fzi)
    return signal(itab, ftab, work, yd, itab[itab[I_OBS] + OBS_W * q + 1])


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _peak_step(ev, stale, t, h, thx, y, yx, yt, K, mode, segs, rng, itab, ftab, imp, road_fixed,
               dy, road, work, stats, yd, p0, pm, p1, oit, fzi, fzf, fzc, stc, stf):  # fmt: skip
    """Raise the running peaks (``OBS_PEAK`` observers, their states in ``yt``) over an
    accepted step: theta in [0, thx] of the attempt (y, yx, K, h) from t, ending at the
    state yt (thx < 1: the step was cut at an event). The values at its start (``p0``),
    end and middle, and where the parabola through those three puts a maximum inside the
    step above the peak so far, the maximum located by successive parabolic
    interpolation on the continuous extension (to 1e-9 of the step). ``stale``: the work
    array does not hold the evaluation at the step's end. p0 receives the end values.
    A filter outside the stages (its step (stc, stf)): read exactly."""
    if stale:
        _f_once(ev, mode, segs, rng, t + thx * h, yt, itab, ftab, imp, road_fixed, dy, road, work,
                stats, oit, fzi)  # fmt: skip
    _peak_values(itab, ftab, work, yt, p1)
    _dense(y, yx, K, h, 0.5 * thx, yd)
    if fzi[0]:  # e^(x / 2) kept by _fz_step: the middle Gauss node is 1/2 to the last bit
        _fz_at(fzi, fzf, fzc, stc, stf, 0.5, yd, np.int64(2))
    _f_once(ev, mode, segs, rng, t + 0.5 * thx * h, yd, itab, ftab, imp, road_fixed, dy, road, work,
            stats, oit, fzi)  # fmt: skip
    _peak_values(itab, ftab, work, yd, pm)
    ob = itab[I_OBS]
    for q in range(itab[I_NOB]):
        b = ob + OBS_W * q
        if itab[b] != OBS_PEAK:
            continue
        slot = itab[b + 3]
        best = max(yt[slot], p0[q], pm[q], p1[q])
        # the parabola through u = 0, 1/2, 1 (u = theta / thx): its vertex, searched
        # also when it falls a little outside the step (a maximum just inside an end,
        # where the parabola's own error can put its vertex past the end: a peak within
        # 1e-3 of a step's length of its end was missed by 2e-7 of its height)
        c2 = 2.0 * (p0[q] - 2.0 * pm[q] + p1[q])
        c1 = -3.0 * p0[q] + 4.0 * pm[q] - p1[q]
        if c2 < 0.0:
            xv = -c1 / (2.0 * c2)
            if -0.25 < xv < 1.25 and p0[q] + xv * (c1 + xv * c2) > best:
                # successive parabolic interpolation on a bracket (a, m, c) of u
                xa, fa = 0.0, p0[q]
                xm, fm = 0.5, pm[q]
                xc, fc = 1.0, p1[q]
                for _ in range(40):
                    d1 = (xm - xa) * (fm - fc)
                    d2 = (xm - xc) * (fm - fa)
                    den = 2.0 * (d1 - d2)
                    xn = xm - ((xm - xa) * d1 - (xm - xc) * d2) / den if den != 0.0 else -1.0
                    if not (xa < xn < xc) or abs(xn - xm) < 1e-12:
                        xn = 0.5 * (xa + xm) if xm - xa > xc - xm else 0.5 * (xm + xc)
                    fn = _peak_at(ev, q, xn * thx, t, h, y, yx, K, mode, segs, rng, itab, ftab, imp,
                                  road_fixed, dy, road, work, stats, yd, oit, fzi, fzf, fzc, stc,
                                  stf, thx)  # fmt: skip
                    best = max(best, fn)
                    if fn >= fm:
                        if xn < xm:
                            xc, fc = xm, fm
                        else:
                            xa, fa = xm, fm
                        xm, fm = xn, fn
                    elif xn < xm:
                        xa, fa = xn, fn
                    else:
                        xc, fc = xn, fn
                    if xc - xa <= 1e-9:
                        break
        yt[slot] = best
        p0[q] = p1[q]


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _sides(sw, road, hs):
    """The side of each element's kink (road[hs + e], hs the first held side of
    :func:`._kernel.road_layout`, see :func:`._kernel.evaluate`) from the signs of its
    two switching functions (:func:`._kernel.switches`)."""
    for e in range(sw.size // 2):
        g = max(sw[2 * e], sw[2 * e + 1])
        road[hs + e] = 1.0 if g > 0.0 else (-1.0 if g < 0.0 else road[hs + e])


@nb.njit(cache=True, inline="always")
def _simultaneous(xloc, th, sw, ne, swf, flipm, xfl, pastv):
    """Mark every switching function whose crossing (theta ``xloc``) lies within
    SIMULTANEOUS of the earliest, ``th``, to switch with it at its instant (two tyres of
    an axle lifting off together: the second one's crossing, a rounding later, would
    otherwise be found again at the start of the next step and its side flipped only at
    that step's end): ``swf`` per function; per element ``flipm`` (it switches), ``xfl``
    (its earliest marked crossing) and ``pastv``, its side past that crossing (above its
    band if that half turns positive, inside it if it turns negative)."""
    for q in range(ne):
        flipm[q] = False
        xfl[q] = 2.0
    for e in range(2 * ne):
        swf[e] = xloc[e] <= th + SIMULTANEOUS
        q = e // 2
        if swf[e] and xloc[e] < xfl[q]:
            xfl[q] = xloc[e]
            flipm[q] = True
            pastv[q] = 1.0 if sw[e] < 0.0 else -1.0


@nb.njit(cache=True, inline="always")
def _switch_at_start(road, hs, ne, flipm, pastv, sw, swf):
    """Crossings at a step's start: the marked elements take their other side's law
    there (``road[hs + q]``) and their switching functions start from
    :data:`PAST_KINK` with the sign of that side."""
    for q in range(ne):
        if flipm[q]:
            road[hs + q] = pastv[q]
    _past_kink(sw, swf, pastv)


@nb.njit(cache=True, inline="always")
def _past_kink(sw, swf, pastv):
    """The switching functions that switched (``swf``) start the next step just past
    their kink: :data:`PAST_KINK` with the sign of their element's new side."""
    for e in range(swf.size):
        if swf[e]:
            sw[e] = pastv[e // 2] * PAST_KINK


@nb.njit(cache=True, inline="always")
def _return_scan(x, gx, g0, a, b, ga, gb):
    """One point x of the search for a return (a switching function that started the
    step at :data:`PAST_KINK` with g0's sign, back across at the step's end): of g0's
    sign, it starts the bracket [x, b] (the search goes on by regula falsi); else the
    return is before it (the bracket's end moves there) and the next point is x / 2.
    Returns (still scanning, the next x, a, b, ga, gb)."""
    if gx * g0 > 0.0:
        return False, x, x, b, gx, gb
    if gx != 0.0:
        b, gb = x, gx
    return True, 0.5 * x, a, b, ga, gb


@nb.njit(cache=True, inline="always")
def _secant(a, b, ga, gb):
    """The regula falsi point of the bracket [a, b] (values ga, gb of opposite signs), or
    its midpoint where rounding puts the secant's root outside."""
    x = (a * gb - b * ga) / (gb - ga)
    return x if a < x < b else 0.5 * (a + b)


@nb.njit(cache=True, inline="always")
def _illinois(a, b, ga, gb, x, gx, side):
    """The Illinois update of the bracket [a, b] by the trial x with value gx: the end of
    gx's sign moves to x, and the value kept at the other end is halved when the same
    end moved twice running (``side`` remembers which end moved last)."""
    if (gx > 0.0) == (ga > 0.0):
        if side == -1:
            gb *= 0.5
        return x, b, gx, gb, -1
    if side == 1:
        ga *= 0.5
    return a, x, ga, gx, 1


@nb.njit(cache=True, inline="always")
def _motion_switches(ev, segs, i, t, y, itab, ftab, road, work, sw, only):
    """The switching functions at (t, y) on segment i into ``sw`` from the nodes' motion
    alone: one call of the right-hand side with ``only`` = :data:`._kernel.SWITCHES_ONLY`
    (as :func:`._kernel.switches_at`; the same values as a whole evaluation's where
    they read no element force)."""
    road_at(segs, i, t, road)
    ev(t, y, road, itab, ftab, work, sw, only)


@nb.njit(cache=True, inline="always")
def _work_switches(ev, y, road, itab, ftab, work, sw, ofw):
    """:func:`._kernel.switches` of the evaluation the work array holds, into ``sw``, by
    the right-hand side called with ``ofw`` = :data:`._kernel.SWITCHES_OF_WORK` (the same
    values: a structure's own code writes the statements out)."""
    ev(0.0, y, road, itab, ftab, work, sw, ofw)


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _locate(ev, e, g0, g1, t, h, y, yt, K, mode, segs, rng, itab, ftab, imp, road_fixed, dy, road,
            work, stats, yd, sw, oit, fzi, cheap, only, ofw):  # fmt: skip
    """theta in (0, 1) where switching function e (of :func:`._kernel.switches`), g0 at
    the step's start and g1 at its end (opposite signs), crosses zero on the step's
    continuous extension (Illinois regula falsi to 1e-12 in theta). ``K`` holds the
    step's stages: 7 rows for the embedded pair (:func:`_dense`), 4 for a classical
    Runge-Kutta step (:func:`_rk4_dense`; :func:`_fixed_rk4` passes the segment it steps
    on as ``rng`` = (i, i + 1, i), mode 0 and no observer slots left out, which is its
    own evaluation). ``cheap`` (mode 0, switching functions that read no element force):
    each iterate's switching functions from the nodes' motion alone (the right-hand side
    called with ``only`` = :data:`._kernel.SWITCHES_ONLY`, equal to the last bit to those
    of the whole evaluation), else from the whole derivative. A function that started
    at :data:`PAST_KINK` (a return) is searched after the last point where it still has
    g0's sign (:func:`_return_scan`); 2.0 (no event) where it has turned back at once
    (:data:`RETURN_LEAST`)."""
    a, b = 0.0, 1.0
    ga, gb = g0, g1
    side = 0
    x = 0.5
    scan = abs(g0) == PAST_KINK  # a return (see RETURN_LEAST): first a point of g0's sign
    for _ in range(90):
        if not scan:
            x = _secant(a, b, ga, gb)
        if K.shape[0] == 4:
            _rk4_dense(y, K[0], K[1], K[2], K[3], h, x, yd)
        else:
            _dense(y, yt, K, h, x, yd)
        tx = t + x * h
        if cheap:
            _motion_switches(ev, segs, _segment_at(segs, rng, tx), tx, yd, itab, ftab, road, work,
                             sw, only)  # fmt: skip
        else:
            _f(ev, mode, segs, rng, tx, yd, itab, ftab, imp, road_fixed, dy, road, work, stats, oit,
               fzi)  # fmt: skip
            _work_switches(ev, yd, road, itab, ftab, work, sw, ofw)
        gx = sw[e]
        if scan:
            scan, x, a, b, ga, gb = _return_scan(x, gx, g0, a, b, ga, gb)
            if x < RETURN_LEAST:
                return 2.0
            continue
        if gx == 0.0:
            return x
        a, b, ga, gb, side = _illinois(a, b, ga, gb, x, gx, side)
        if b - a <= 1e-12:
            break
    return b



# ---------------------------------------------------------------------------------------
# exact steps of a nonlinear system while every nonlinear element sits in its linear
# regime (a saturated flywheel: a constant inertance); the tables come from
# :func:`.core._regime_tables`. The augmented state z = (x, e) carries the road input as
# e = (X1 - X1_0, X1', X1_0) on a segment (X1_0 its displacement offset): e' = Q e with
# Q = [[0, 1, 0], [-w^2, 0, 0], [0, 0, 0]] (w the sine's angular frequency, 0 on a
# linear segment), so z' = M z is linear and z(t + h) = exp(M h) z exactly.


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _x_lookup(keys, h, q):
    """Row of the step length h in the sorted integer keys (lengths in units of q), or
    -1."""
    key = round(h / q)
    lo = 0
    hi = keys.size - 1
    while lo <= hi:
        mid = (lo + hi) // 2
        if keys[mid] == key:
            return mid
        if keys[mid] < key:
            lo = mid + 1
        else:
            hi = mid - 1
    return -1


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _x_input(segs, i, t, road, z, n):
    """The input part of z at time t on segment i (see above)."""
    road_at(segs, i, t, road)
    z[n] = road[0] - segs[i, 3]
    z[n + 1] = road[1]
    z[n + 2] = segs[i, 3]


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _x_guards(XG, c, z, thr, margin, ga, gd):
    """Each regime's argument (ga) and its rate (gd) at z; True if every argument is at
    least ``margin`` x its threshold in magnitude."""
    ng = thr.size
    ok = True
    for g in range(ng):
        a = 0.0
        d = 0.0
        for q in range(z.size):
            a += XG[c, g, q] * z[q]
            d += XG[c, ng + g, q] * z[q]
        ga[g] = a
        gd[g] = d
        if abs(a) < margin * thr[g]:
            ok = False
    return ok


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _x_stays(a0, d0, a1, d1, h, lim):
    """Whether the cubic Hermite interpolant of an argument (values a0, a1 and rates d0,
    d1 at the ends of a step of length h) keeps one sign and magnitude >= lim over the
    step."""
    s = 1.0 if a0 > 0.0 else -1.0
    if s * a1 < lim or s * a0 < lim:
        return False
    m0 = h * d0
    m1 = h * d1
    c2 = 3.0 * (a1 - a0) - 2.0 * m0 - m1
    c3 = 2.0 * (a0 - a1) + m0 + m1
    # p'(th) = m0 + 2 c2 th + 3 c3 th^2: its roots in (0, 1)
    qa = 3.0 * c3
    qb = 2.0 * c2
    for r in range(2):
        if qa != 0.0:
            disc = qb * qb - 4.0 * qa * m0
            if disc < 0.0:
                return True
            th = (-qb + (1.0 - 2.0 * r) * math.sqrt(disc)) / (2.0 * qa)
        elif qb != 0.0:
            if r:
                break
            th = -m0 / qb
        else:
            break
        if 0.0 < th < 1.0:
            p = a0 + th * (m0 + th * (c2 + th * c3))
            if s * p < lim:
                return False
    return True

@nb.njit(cache=True)
def _advance(ev, mode, segs, rng, t, t_end, y, h, last, itab, ftab, imp, road_fixed, rtol, atol,
             t_out, out_y, k, stats, max_steps, XE, XG, xkeys, xthr, xel, xcls, xlev, xq, ctl,
             xo, fz):  # fmt: skip
    """Integrate from t to t_end (the road segments rng[0] <= i < rng[1]: one, or a run of
    measured-drive pieces or of linear segments that join (a sampled road), whose edges
    the steps end on without a restart: the step size carries over; the impulse flow of
    a road step when mode = 1, of a road velocity jump when mode = 2),
    writing dense output at t_out[k:] <= t_end (< t_end unless ``last``).

    Exact steps (``XE`` not empty, segments all of one class ``xcls[i]`` >= 0, one road):
    each ends on the next edge at the latest and reads its input from the segment it is
    on (at an edge the next segment's, and the guards' rates with it), while every
    nonlinear element sits in its linear regime (its switching function positive, its
    argument ``XG[c, g] . z`` at least :data:`X_MARGIN` x its threshold ``xthr[g]`` in
    magnitude, at the ends of the step and on the cubic through them) the state goes
    from break point (sample or segment end) to break point by ``XE[c, j]`` = exp(M h),
    h the length of row j of ``xkeys`` (units of ``xq``); where that length is not in
    the table (break points far apart) or that step would leave the regime, by the
    longest of the level lengths (rows ``xlev``, longest first) that is shorter and
    stays in it. A step that would leave the regime is not taken: the Dormand-Prince
    steps go on from there and locate the switch. ``ctl`` = (longest step, fixed step or 0: steps of that length without
    error control). ``xo`` = (ia, SR, rows (not read here), gw, gx, cap, TR, sref): with
    observers the tables act on the rows ``ia`` of y (the states and the linear
    observers'), the other observers follow the exact steps by :func:`_observe_steps`
    (up to :data:`X_BLOCK` steps at once, the samples taken meanwhile written after
    them, and all before the next adaptive step; ``SR[c]`` and ``TR[c]`` as in
    :func:`_exact_walk`, over z), and no step of class c is longer than cap[c] (their
    quadrature's accuracy); empty ``ia``: no observers, z = (y, e). ``fz``: a
    linear filter among the observers and its quadratures, advanced outside the
    Dormand-Prince stages and error control, exactly over each accepted step
    (:func:`_fz_step`; the tables of :func:`.observers.filter_split`, empty for none).
    Returns (status, k, h)."""
    n = y.size
    # every array the run needs, allocated here: the run itself (:func:`_advance_run`) is
    # compiled without reference counting, which in its loop had cost more than some of
    # the arithmetic (an atomic increment and decrement of each array an inlined helper
    # took or a loop iterated over, at every stage: 30 % of the time of a quarter car's
    # integration without observers)
    work = np.empty(_work_size(itab))
    road = np.zeros(road_layout_of(itab)[0])  # the roads, a free slot, each element's side
    K = np.zeros((7, n))  # the stages k1..k7 (k7: the derivative at the new point)
    dy = np.empty(n)
    yt = np.empty(n)
    fzi = fz[1]
    # the states the stages move (live), and those they leave (dead: the running peaks
    # and the states advanced outside the stages, derivative 0 there; their stage rows
    # of K stay 0 and their error is 0)
    moves = np.ones(n, np.bool_)
    d0 = FZ_HEAD + fzi[0] + fzi[1] + fzi[2]
    for i in range(d0, d0 + fzi[3]):
        moves[fzi[i]] = False
    npk = np.int64(0)  # running peaks (observers)
    for q in range(itab[I_NOB]):
        if itab[itab[I_OBS] + OBS_W * q] == OBS_PEAK:
            moves[itab[itab[I_OBS] + OBS_W * q + 3]] = False
            npk += 1
    live = np.flatnonzero(moves)
    dead = np.flatnonzero(~moves)
    stc, stf = fz_scratch(fzi)  # a filter step (see _fz_begin)
    nob = itab[I_NOB]
    p0 = np.empty(nob)  # running peaks: the values at a step's start, and scratch
    pm = np.empty(nob)
    p1 = np.empty(nob)
    yx = np.empty(n)  # an attempt's end when it was cut at an event
    ne = itab[I_NE]
    sw = np.empty(2 * ne)  # the switching functions, two per element (see _kernel.switches)
    swn = np.empty(2 * ne)
    swx = np.empty(2 * ne)
    yd = np.empty(n)
    xloc = np.empty(2 * ne)  # each switching function's crossing in the attempt (theta)
    xfl = np.empty(ne)  # the earliest crossing of each element's two
    pastv = np.zeros(ne)  # each switching element's side past its crossing
    flipm = np.zeros(ne, np.bool_)  # the elements that switch at the crossing
    swf = np.zeros(2 * ne, np.bool_)  # their switching functions that cross there
    h_side = np.zeros(2)  # a first step size past a kink, into each side
    only = np.full(1, np.inf)  # SWITCHES_ONLY, as a local array (a global one is read-only)
    ofw = np.full(1, -np.inf)  # SWITCHES_OF_WORK
    # the inner stages (all but the last, at the step's end): _kernel.STAGE as a local
    # array (no outputs into the work array) where no observer the stages move reads it;
    # a flow's own imp otherwise
    stg = np.full(2, np.inf) if mode == 0 and imp.size == 0 and fz[0][I_NOB] == 0 else imp
    xia, xSR, _, xgw, xgx, xcap, xTR, xref = xo
    ia = xia if xia.size > 0 else np.arange(n)
    na = ia.size
    z = np.empty(na + 3)
    zs = np.empty(na + 3)  # z at the start of an exact step (the observers' initial vector)
    xpts = np.empty(xgx.size + 2)  # theta of the points: 0, the nodes, 1
    xpts[0] = 0.0
    xpts[-1] = 1.0
    xpts[1:-1] = xgx
    xcoef = np.empty(xTR.shape[3])
    # the exact steps whose observers are summed at once (:func:`_observe_steps`): their
    # initial vectors, lengths and table rows, and the samples taken meanwhile
    xnb = X_BLOCK if xia.size > 0 and itab[I_NOB] > 0 else 1
    xvt = np.empty((na + 3, xnb))
    xh = np.empty(xnb)
    xj = np.empty(xnb, np.int64)
    xpk = np.empty(xnb, np.int64)
    xpp = np.empty(xnb, np.int64)
    xsv = np.empty((xSR.shape[3], xnb))  # scratch of _observe_steps
    xrow = np.empty(xSR.shape[3])
    xnu = xSR.shape[3] // xpts.size
    xhi = np.empty((xnu, xnb))
    xlo = np.empty((xnu, xnb))
    xdone = np.empty(xnu, np.bool_)
    xacc = np.empty(xnb)
    ng = xthr.size
    ga0 = np.empty(ng)
    gd0 = np.empty(ng)
    ga1 = np.empty(ng)
    gd1 = np.empty(ng)
    scratch = (work, road, K, dy, yt, live, dead, stc, stf, p0, pm, p1, yx, sw, swn, swx, yd,
               xloc, xfl, pastv, flipm, swf, h_side, only, ofw, ia, z, zs, xvt, xpts, xcoef, xsv, xrow,
               xh, xj, xpk, xpp, xhi, xlo, xdone, xacc, ga0, gd0, ga1, gd1, stg, np.empty(n))  # fmt: skip
    return _advance_run(ev, mode, segs, rng, t, t_end, y, h, last, itab, ftab, imp, road_fixed,
                        rtol, atol, t_out, out_y, k, stats, max_steps, XE, XG, xkeys, xthr, xel,
                        xcls, xlev, xq, ctl, xo, fz, npk, scratch)  # fmt: skip


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _advance_run(ev, mode, segs, rng, t, t_end, y, h, last, itab, ftab, imp, road_fixed, rtol,
                 atol, t_out, out_y, k, stats, max_steps, XE, XG, xkeys, xthr, xel, xcls, xlev, xq,
                 ctl, xo, fz, npk, scratch):  # fmt: skip
    """The run of :func:`_advance` on the arrays it allocated (``scratch``), compiled
    without numba's reference counting (it allocates nothing); ``npk``: the number of
    running peaks among the observers."""
    (work, road, K, dy, yt, live, dead, stc, stf, p0, pm, p1, yx, sw, swn, swx, yd, xloc, xfl,
     pastv, flipm, swf, h_side, only, ofw, ia, z, zs, xvt, xpts, xcoef, xsv, xrow, xh, xj, xpk, xpp,
     xhi, xlo, xdone, xacc, ga0, gd0, ga1, gd1, stg, es) = scratch  # fmt: skip
    n = y.size
    nl = live[live.size - 1] + 1 if live.size > 0 else 0  # past the last live state
    _, _, hs = road_layout_of(itab)
    oit, fzi, fzf, fzc = fz
    nfz = fzi[0]
    if not _f(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy, road, work, stats, oit, fzi):
        return BALANCE_FAILED, k, h
    for i in range(n):
        K[0, i] = dy[i]
    # running peaks (observers): the values at the start; tracked only where an observer
    # is a peak (the search evaluates the midpoint of every accepted step)
    nob = itab[I_NOB]
    track = mode == 0 and npk > 0
    stale = np.bool_(False)
    hx = 0.0
    thx = 1.0
    if track:
        peaks(itab, ftab, work, y)
        _peak_values(itab, ftab, work, y, p0)
    span = t_end - t
    if span <= 0.0:
        return OK, k, h
    if h <= 0.0:
        h = min(span, 1e-3 * max(span, 1.0))
    elif h > span:
        # the step carried over from the last segment fits this one whole (a sampled
        # road's samples end every step: starting again from 1e-3 s cost a second step
        # per 2 ms sample)
        h = span
    hmax = ctl[0]
    hfix = ctl[1]
    reject_prev = False
    # events: the elements' switching functions at t (sw), at the step's end (swn); a
    # step across a sign change is cut at the crossing (forced: the element whose
    # crossing it lands on), so no step integrates across a kink of a force law
    ne = itab[I_NE]
    flip = -1
    fresh = -1
    cut = False
    events = mode == 0 and switches(itab, ftab, work, sw) > 0
    # the events' location reads the switching functions from the nodes' motion alone
    # where they read no element force (as the classical Runge-Kutta driver does)
    cheap = events and not switches_read_forces(itab, ftab)
    if events:  # every attempt takes the law of the side of each kink it starts on
        _sides(sw, road, hs)
        _f_once(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy, road, work, stats, oit, fzi)
        for i in range(n):
            K[0, i] = dy[i]
    forced = -1
    h_keep = 0.0
    # fixed steps: a step that crosses an event is taken again from its start to the
    # crossing (length h_redo, the element ``redo`` switching at its end)
    redo = -1
    h_redo = 0.0
    # exact steps in the linear regimes: on a segment, or on a run of segments of one
    # class (a sampled road: each step ends on the next edge at the latest, its input
    # that of the segment it is on)
    cx = xcls[rng[0]] if mode == 0 and XE.shape[0] > 0 else -1
    if cx >= 0:
        for i in range(rng[0], rng[1]):  # (one road: several take no exact steps)
            if xcls[i] != cx or segs[i, 2] == 3.0:
                cx = -1
    si = rng[0]  # the segment of the exact steps
    ng = xthr.size
    xia, xSR, _, xgw, xgx, xcap, xTR, xref = xo
    na = ia.size
    xobs = xia.size > 0 and nob > 0
    check = cx >= 0
    cap = math.inf
    while t < t_end:
        if stats[0] + stats[1] >= max_steps:
            return TOO_MANY_STEPS, k, h
        if check:
            check = False
            cap = math.inf
            inside = True
            for g in range(ng):
                if max(sw[2 * xel[g]], sw[2 * xel[g] + 1]) <= 0.0:
                    inside = False
            if inside:
                for i in range(na):
                    z[i] = y[ia[i]]
                si = rng[2]  # the segment from t on (at an edge: the next one)
                while si + 1 < rng[1] and segs[si + 1, 0] <= t:
                    si += 1
                _x_input(segs, si, t, road, z, na)
                inside = _x_guards(XG, cx, z, xthr, X_MARGIN, ga0, gd0)
            taken = 0
            xn = np.int64(0)  # steps whose observers are pending
            xnp = np.int64(0)  # samples taken meanwhile
            nbk = xh.size
            while inside:
                while k < t_out.size and t_out[k] <= t and (last or t_out[k] < t_end):
                    for i in range(n):
                        out_y[k, i] = y[i]
                    if xn > 0:  # its observers once the steps' are summed
                        if xnp == nbk:
                            _observe_steps(itab, y, xn, xh, xj, xvt, xSR[cx], xTR[cx], xgw, xpts,
                                           xref, xsv, xrow, xcoef, xhi, xlo, xdone, xacc, xpk, xpp, xnp,
                                           out_y)  # fmt: skip
                            xn = np.int64(0)
                            xnp = np.int64(0)
                            for i in range(n):
                                out_y[k, i] = y[i]
                        else:
                            xpk[xnp] = k
                            xpp[xnp] = xn
                            xnp += 1
                    k += 1
                if t >= t_end:
                    break
                tb = t_out[k] if k < t_out.size and t_out[k] < t_end else t_end
                if si + 1 < rng[1] and segs[si + 1, 0] < tb:
                    tb = segs[si + 1, 0]  # the segment's end
                gap = tb - t
                # the step to the break point if its length is in the table, else (or
                # where it would leave the regime) the longest level that is shorter
                j = _x_lookup(xkeys, gap, xq)
                hcap = xcap[cx] * (1.0 + 1e-9) if xobs else math.inf
                if j >= 0 and xkeys[j] * xq > hcap:
                    j = -1
                r = 0
                while r < xlev.size and (xkeys[xlev[r]] * xq >= gap or xkeys[xlev[r]] * xq > hcap):
                    r += 1
                if j < 0 and r == xlev.size:
                    if gap > 1e-9 * max(abs(t), 1.0):
                        cap = tb  # the next Dormand-Prince step ends on the break point
                    break
                if stats[0] + stats[1] >= max_steps or xn == nbk:
                    if xn > 0:
                        _observe_steps(itab, y, xn, xh, xj, xvt, xSR[cx], xTR[cx], xgw, xpts,
                                       xref, xsv, xrow, xcoef, xhi, xlo, xdone, xacc, xpk, xpp, xnp,
                                       out_y)  # fmt: skip
                        xn = np.int64(0)
                        xnp = np.int64(0)
                    if stats[0] + stats[1] >= max_steps:
                        return TOO_MANY_STEPS, k, h
                for i in range(na + 3):
                    zs[i] = z[i]
                tn = tb
                stay = False
                while True:
                    if j < 0:
                        if r == xlev.size:
                            break
                        j = xlev[r]
                        r += 1
                        tn = t + xkeys[j] * xq
                    for i in range(na):
                        acc = 0.0
                        for q in range(na + 3):
                            acc += XE[cx, j, i, q] * zs[q]
                        yt[i] = acc
                    for i in range(na):
                        z[i] = yt[i]
                    _x_input(segs, si, tn, road, z, na)
                    stay = _x_guards(XG, cx, z, xthr, X_MARGIN, ga1, gd1)
                    for g in range(ng):
                        stay = stay and _x_stays(ga0[g], gd0[g], ga1[g], gd1[g], tn - t,
                                                 X_MARGIN * xthr[g])  # fmt: skip
                    if stay:
                        break
                    for i in range(na + 3):
                        z[i] = zs[i]
                    j = -1
                if not stay:
                    break
                for i in range(na):
                    y[ia[i]] = yt[i]
                if xobs:
                    for i in range(na + 3):
                        xvt[i, xn] = zs[i]
                    xh[xn] = tn - t
                    xj[xn] = j
                    xn += 1
                for g in range(ng):
                    ga0[g] = ga1[g]
                    gd0[g] = gd1[g]
                t = tn
                stats[0] += 1
                stats[4] += 1
                taken += 1
                if si + 1 < rng[1] and segs[si + 1, 0] <= t:
                    # on the next segment: its input from here (the road's rate changes
                    # at the edge; its height and the state do not), and the guards'
                    # rates with it
                    while si + 1 < rng[1] and segs[si + 1, 0] <= t:
                        si += 1
                    _x_input(segs, si, t, road, z, na)
                    inside = _x_guards(XG, cx, z, xthr, X_MARGIN, ga0, gd0)
            if xn > 0:  # the observers over the steps taken
                _observe_steps(itab, y, xn, xh, xj, xvt, xSR[cx], xTR[cx], xgw, xpts, xref, xsv,
                               xrow, xcoef, xhi, xlo, xdone, xacc, xpk, xpp, xnp, out_y)  # fmt: skip
            if taken:  # the Dormand-Prince steps go on from here: their first stage
                if si != rng[2]:  # on the segment the exact steps reached
                    rng[2] = si
                    h_side[0] = 0.0
                    h_side[1] = 0.0
                    fresh = -1
                _f_once(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy, road, work, stats, oit, fzi)
                for i in range(n):
                    K[0, i] = dy[i]
                if track:  # the peaks' signals at the new start
                    _peak_values(itab, ftab, work, y, p0)
                _work_switches(ev, y, road, itab, ftab, work, sw, ofw)
                _sides(sw, road, hs)
                if t >= t_end:
                    break
        lim = t_end
        if cap < lim:
            lim = cap
        if rng[1] - rng[0] > 1:  # the next edge of the run of segments
            i = rng[2]
            while i + 1 < rng[1] and segs[i + 1, 0] <= t:  # from an edge: the next one
                i += 1
            if i != rng[2]:
                kinked = _kinked(segs, rng[2], i)
                rng[2] = i
                # the first step sizes past kinks are remembered per segment (as when
                # each segment was integrated on its own: a step size remembered from a
                # kink long ago held a sampled road's steps short)
                h_side[0] = 0.0
                h_side[1] = 0.0
                fresh = -1
                if kinked:
                    # the road's rate changes at the edge (a sampled road, linear between
                    # samples): the first stage again, on the new segment, and each
                    # element's side from its switching functions there, as a segment's
                    # start takes them
                    if not _f_once(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy,
                                   road, work, stats, oit, fzi):  # fmt: skip
                        return BALANCE_FAILED, k, h
                    if events:
                        _work_switches(ev, y, road, itab, ftab, work, sw, ofw)
                        moved = False
                        for e in range(ne):
                            g = max(sw[2 * e], sw[2 * e + 1])
                            sd = 1.0 if g > 0.0 else (-1.0 if g < 0.0 else road[hs + e])
                            if sd != road[hs + e]:
                                road[hs + e] = sd
                                moved = True
                        if moved:
                            _f_once(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy,
                                    road, work, stats, oit, fzi)  # fmt: skip
                    for q in range(n):
                        K[0, q] = dy[q]
                    if track:  # a signal may jump with the rate: its value past the edge
                        peaks(itab, ftab, work, y)
                        _peak_values(itab, ftab, work, y, p0)
            if i + 1 < rng[1] and segs[i + 1, 0] < t_end:
                lim = segs[i + 1, 0]
        if lim - t <= 1e-14 * max(abs(t), 1.0):
            # what is left to a break point is below round-off (a sample next to a
            # segment edge, after exact steps): the state stands
            while mode == 0 and k < t_out.size and (t_out[k] < lim or (last and t_out[k] <= lim)):
                for i in range(n):
                    out_y[k, i] = y[i]
                k += 1
            t = lim
            check = cx >= 0
            continue
        if hfix > 0.0:
            h = hfix
        elif h > hmax:
            h = hmax
        h_free = h
        if redo >= 0:
            h = h_redo
            tn = t + h
        elif t + h >= lim or t + 1.01 * h >= lim:
            h = lim - t
            tn = lim
        else:
            tn = t + h
        if h <= 1e-15 * max(abs(t), 1.0):
            return STEP_TOO_SMALL, k, h
        # the stages, one call site (the right-hand side is compiled into this loop
        # once); the last stage's point is the order-5 solution (first same as last)
        ok = True
        stale = np.bool_(False)
        thx = 1.0
        for st in range(1, 7):
            # each state's stage sum term by term in the order of q, the states side by
            # side (contiguous rows of K: the compiler vectorises the loops over i), up
            # to the last state the stages move (every state past it is one they leave,
            # copied below: a ride's filter, quadratures and peaks, which the observers'
            # order puts after those the stages move)
            for i in range(nl):
                dy[i] = 0.0
            for q in range(st):
                a = _TAB_A[st, q]
                for i in range(nl):
                    dy[i] += a * K[q, i]
            for i in range(nl):
                yt[i] = y[i] + h * dy[i]
            for i in dead:  # the states the stages leave
                yt[i] = y[i]
            ts = tn if st >= 5 else t + _TAB_C[st] * h
            ok &= _f(ev, mode, segs, rng, ts, yt, itab, ftab, stg if st < 6 else imp, road_fixed, dy, road,
                     work, stats, oit, fzi)  # fmt: skip
            for i in live:
                K[st, i] = dy[i]
        for i in range(nl):  # the error estimate's sums, as the stages' above
            es[i] = 0.0
        for q in range(7):
            a = _TAB_E[q]
            for i in range(nl):
                es[i] += a * K[q, i]
        err = 0.0
        for i in live:
            sc = atol[i] + rtol * max(abs(y[i]), abs(yt[i]))
            e = h * es[i]
            err += (e / sc) ** 2
        err = math.sqrt(err / max(live.size, 1))
        if hfix > 0.0:  # fixed steps: no error control, but a failure stays one
            if not ok:
                return BALANCE_FAILED, k, h
            if not math.isfinite(err):
                return NOT_FINITE, k, h
            err = 0.0
        if not ok or not math.isfinite(err):
            if h < 1e-14 * max(abs(t), 1.0) or not ok and h < 1e-12:
                return NOT_FINITE if ok else BALANCE_FAILED, k, h
            h *= 0.25
            stats[1] += 1
            reject_prev = True
            forced = -1
            h_keep = 0.0
            continue
        kstart = k
        if err <= 1.0 and events and redo >= 0:
            # the fixed step taken again up to its crossing: the elements found there
            # (flipm, pastv, swf) switch at its end, as at a crossing at theta = 1
            _work_switches(ev, yt, road, itab, ftab, work, swn, ofw)
            stats[3] += 1
            for e in range(2 * ne):
                sw[e] = swn[e]
            _past_kink(sw, swf, pastv)
            flip = redo
            redo = -1
            forced = -1
            h_keep = 0.0
        elif err <= 1.0 and events:
            # at (tn, yt): the last stage's evaluation
            _work_switches(ev, yt, road, itab, ftab, work, swn, ofw)
            th = 2.0
            forced = -1
            for e in range(2 * ne):
                xloc[e] = 2.0
                if sw[e] * swn[e] < 0.0:
                    stale = np.bool_(True)
                    xloc[e] = _locate(ev, e, sw[e], swn[e], t, h, y, yt, K, mode, segs, rng,
                                      itab, ftab, imp, road_fixed, dy, road, work, stats, yd,
                                      swx, oit, fzi, cheap, only, ofw)  # fmt: skip
                    if xloc[e] < th:
                        th = xloc[e]
                        forced = e
            h_keep = 0.0
            if forced >= 0:
                _simultaneous(xloc, th, sw, ne, swf, flipm, xfl, pastv)
                if th <= SIMULTANEOUS:
                    # the crossings are at the step's start: the elements take their
                    # other side's law there and the step is tried again from it
                    _switch_at_start(road, hs, ne, flipm, pastv, sw, swf)
                    if not _f_once(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy,
                                   road, work, stats, oit, fzi):  # fmt: skip
                        return BALANCE_FAILED, k, h
                    for i in range(n):
                        K[0, i] = dy[i]
                    stats[1] += 1
                    continue
                if th < 1.0 - SIMULTANEOUS and hfix > 0.0:
                    # a fixed step: taken again from its start to the crossing, under
                    # the laws it started with (cut on this attempt's extension instead,
                    # as below, fixed steps converged at second order through tyre
                    # lift-off; decisions.md, issue #34)
                    redo = forced
                    h_redo = th * h
                    stats[1] += 1
                    continue
                if th < 1.0 - SIMULTANEOUS:
                    # the step ends at the crossing, on its continuous extension (the
                    # attempt followed one law throughout: its extension is smooth)
                    stats[3] += 1
                    tc = t + th * h
                    while mode == 0 and k < t_out.size and t_out[k] < tc:
                        _dense(y, yt, K, h, (t_out[k] - t) / h, out_y[k])
                        k += 1
                    _dense(y, yt, K, h, th, yd)
                    for i in range(n):
                        yx[i] = yt[i]
                        yt[i] = yd[i]
                    hx = h
                    thx = th
                    tn = tc
                    h_keep = h_free
                    h = th * h
                    cut = True
            for e in range(2 * ne):
                sw[e] = swn[e]
            flip = forced
            if forced >= 0:
                _past_kink(sw, swf, pastv)  # on the kink: the next step starts past it
            forced = -1
        if err <= 1.0 and nfz > 0:  # the filter over the accepted step, exactly
            if thx < 1.0:
                _fz_step(fzi, fzf, fzc, stc, stf, itab, y, yx, K, hx, thx, yt)
                for kk in range(kstart, k):  # the samples the cut step wrote
                    _fz_sample(fzi, fzf, fzc, stc, stf, itab, (t_out[kk] - t) / h, y, yt,
                               out_y[kk])  # fmt: skip
            else:
                _fz_step(fzi, fzf, fzc, stc, stf, itab, y, yt, K, h, 1.0, yt)
        if err <= 1.0:
            stats[0] += 1
            # dense output on (t, tn] (a step cut at a crossing wrote its own)
            if mode == 0 and not cut:
                while k < t_out.size and (t_out[k] < tn or (last and t_out[k] <= tn)):
                    _dense(y, yt, K, h, (t_out[k] - t) / h, out_y[k])
                    if nfz > 0:
                        _fz_sample(fzi, fzf, fzc, stc, stf, itab, (t_out[k] - t) / h, y, yt,
                                   out_y[k])  # fmt: skip
                    k += 1
            if fresh >= 0 and flip < 0:
                h_side[fresh] = h  # the first step that passed after a kink to this side
                fresh = -1
            if track:
                if thx < 1.0:  # cut at an event: the attempt's extension up to the cut
                    _peak_step(ev, stale, t, hx, thx, y, yx, yt, K, mode, segs, rng, itab, ftab,
                               imp, road_fixed, dy, road, work, stats, yd, p0, pm, p1, oit,
                               fzi, fzf, fzc, stc, stf)  # fmt: skip
                else:
                    _peak_step(ev, stale, t, h, 1.0, y, yt, yt, K, mode, segs, rng, itab, ftab, imp,
                               road_fixed, dy, road, work, stats, yd, p0, pm, p1, oit,
                               fzi, fzf, fzc, stc, stf)  # fmt: skip
            for i in range(n):
                y[i] = yt[i]
                K[0, i] = K[6, i]
            t = tn
            into = -1
            if flip >= 0:  # past the kink: its other side's law from here
                for q in range(ne):
                    if flipm[q]:
                        road[hs + q] = pastv[q]
                _f_once(ev, mode, segs, rng, t, y, itab, ftab, imp, road_fixed, dy, road, work, stats, oit, fzi)
                for i in range(n):
                    K[0, i] = dy[i]
                if cut:  # the switching functions at the crossing, not at the step's end
                    _work_switches(ev, y, road, itab, ftab, work, sw, ofw)
                    _past_kink(sw, swf, pastv)
                    cut = False
                into = 0 if pastv[flip // 2] < 0.0 else 1
                flip = -1
            # safety factor 0.8 while an element sits inside its kink's band, where
            # the error per step grows along the way (the flywheel's inertance
            # steepens towards saturation: with 0.9 a third of the attempts there were
            # rejected, one after each accepted step); 0.9 elsewhere. (The PI
            # controller of DOPRI5 cut those rejections further, but took the free-play
            # rattle of tests/test_core_events.py 40x off its closed form.)
            safe = 0.9
            for e in range(ne):
                if road[hs + e] < 0.0:
                    safe = 0.8
            fac = safe * err**-0.2 if err > 0.0 else 5.0
            fac = min(5.0, max(0.2, fac))
            if reject_prev:
                fac = min(fac, 1.0)
            reject_prev = False
            h = h * fac
            if lim < t_end and fac >= 1.0:
                h = max(h, h_free)  # a step cut short by an edge: keep the free size
            if h_keep > 0.0 and fac >= 1.0 and into < 0:
                h = max(h, h_keep)  # a step cut short by an event: the same
            if into >= 0:
                # past a kink the law is another one: not the step size from before it,
                # but at most the first one that passed after the last kink to this side
                h = h_keep if h_keep > 0.0 else h
                if h_side[into] > 0.0:
                    h = min(h, h_side[into])
                fresh = into
            h_keep = 0.0
            check = cx >= 0
        else:
            stats[1] += 1
            reject_prev = True
            forced = -1
            h_keep = 0.0
            h = h * max(0.2, 0.9 * err**-0.2)
    return OK, k, h


@nb.njit(cache=True)
def _integrate(ev, itab, ftab, segs, y, x1_before, t_end, rtol, atol, imp_unit, jump_ok, jump_tol,
              t_out, out_y, stats, jumps, max_steps, v_before, vjump_tol, vjumps, XE, XG, xkeys,
              xthr, xel, xcls, xlev, xq, ctl, xo, fz, fz_none):  # fmt: skip
    """Integrate a core system over the road segments up to t_end.

    ``y`` is advanced in place; samples at ``t_out`` go to ``out_y`` (rows); ``jumps[i]``
    receives the road step at the start of segment i. ``imp_unit`` is the impulse per
    unit road step on each dynamic node, ``jump_ok`` False where a step has no finite
    response (an inerter or a quadratic damper to the road, a rig). Where the road
    velocity jumps by more than ``vjump_tol`` (at the start of a segment; at t = 0 from
    ``v_before``, NaN for none) the impulses of the inertances attached to the road are
    applied by the flow of :data:`._kernel.ROAD_JERK`, and the jump goes to
    ``vjumps[i]``; ``vjump_tol`` = inf where no inertance touches the road. ``stats``:
    steps (exact ones included), rejected steps, right-hand-side calls, events, exact
    steps. The exact steps in linear regimes: see :func:`_advance` (``XE`` empty for
    none); ``ctl``: the step control of :func:`_advance`, ``xo`` its observers in the
    exact steps, ``fz`` the filter it advances outside its stages (``fz_none``: none,
    the impulse flows carry every observer in their stages)."""
    k = 0
    h = 0.0
    prev = x1_before
    free = np.array([math.inf, 0.0])  # the impulse flows: adaptive, in their own unit
    prev_v = v_before
    road = np.zeros(road_layout_of(itab)[0])
    rf = np.empty(3)
    atol_imp = np.empty(y.size)
    for i in range(y.size):
        atol_imp[i] = 1e-3 * atol[i]
    nseg = segs.shape[0]
    rng = np.zeros(3, dtype=np.int64)
    jerk = np.full(1, np.nan)  # ROAD_JERK, as a local array: a global one is typed
    # read-only, and every function it reaches would be compiled a second time.
    # The modes, the first sample and "not last" are read from an array for the same
    # reason: numba compiles a function once per literal constant it is called with
    # (three copies of _advance and of everything it reaches, 10 s at first use)
    modes = np.arange(3)
    flow = modes[1] < 0  # False, not a literal
    s = 0
    while s < nseg:
        t0 = segs[s, 0]
        if t0 >= t_end and s > 0:
            break
        # one segment, or a run of measured-drive pieces (kind 2: x, v and a continuous
        # across their edges, so no jump checks and no restarts between them), or a run
        # of linear segments that join in displacement (a sampled road: kind 3, a
        # vehicle's roads; kind 0, one road) where no inertance touches a road (so no
        # impulses at the kinks): the steps end on the edges, where the first stage is
        # evaluated again on the new rate (the step size carries over, nothing is set up
        # again), and exact steps in linear regimes take each segment's input in turn
        e = s + 1
        if segs[s, 2] == 2.0:
            while e < nseg and segs[e, 2] == segs[s, 2] and segs[e, 0] < t_end:
                e += 1
        elif (segs[s, 2] == 3.0 or segs[s, 2] == 0.0) and vjump_tol == math.inf:
            while e < nseg and segs[e, 0] < t_end and _joins(segs, e - 1, jump_tol):
                e += 1
        rng[0] = s
        rng[1] = e
        rng[2] = s
        road_at(segs, s, t0, road)
        if math.isfinite(prev_v) and abs(road[1] - prev_v) > vjump_tol:
            vjumps[s] = road[1] - prev_v
            rf[0] = prev
            rf[1] = prev_v
            rf[2] = road[1] - prev_v
            st, _, _ = _advance(ev, modes[2], segs, rng, 0.0, 1.0, y, 0.0, flow, itab, ftab, jerk,
                                rf, IMPULSE_RTOL, atol_imp, t_out, out_y, modes[0], stats,
                                max_steps, XE, XG, xkeys, xthr, xel, xcls, xlev, xq, free, xo,
                                fz_none)  # fmt: skip
            if st != OK:
                return st, k
        jump = road[0] - prev
        if abs(jump) > jump_tol:
            jumps[s] = jump
            if not jump_ok:
                return ROAD_STEP, k
            imp = imp_unit * jump
            rf[0] = road[0]
            rf[1] = road[1]
            st, _, _ = _advance(ev, modes[1], segs, rng, 0.0, 1.0, y, 0.0, flow, itab, ftab, imp,
                                rf, IMPULSE_RTOL, atol_imp, t_out, out_y, modes[0], stats,
                                max_steps, XE, XG, xkeys, xthr, xel, xcls, xlev, xq, free, xo,
                                fz_none)  # fmt: skip
            if st != OK:
                return st, k
        while k < t_out.size and t_out[k] <= t0:
            for i in range(y.size):
                out_y[k, i] = y[i]
            k += 1
        t1 = min(segs[e - 1, 1], t_end)
        last = e == nseg or segs[e - 1, 1] >= t_end
        st, k, h = _advance(ev, modes[0], segs, rng, t0, t1, y, h, last, itab, ftab, np.empty(0), rf,
                            rtol, atol, t_out, out_y, k, stats, max_steps, XE, XG, xkeys,
                            xthr, xel, xcls, xlev, xq, ctl, xo, fz)  # fmt: skip
        if st != OK:
            return st, k
        road_at(segs, e - 1, t1, road)
        prev = road[0]
        prev_v = road[1]
        if last:
            break
        s = e
    return OK, k


@nb.njit(cache=True, inline="always")
def _sample_road(segs, s, t, road):
    """The road at the sample time t into ``road``, walking on from segment s to the one
    that holds t (right-continuous); returns that segment."""
    while s + 1 < segs.shape[0] and segs[s + 1, 0] <= t:
        s += 1
    road_at(segs, s, t, road)
    return s


@nb.njit(cache=True)
def _outputs_many(ev, t_out, Y, segs, itab, ftab, O):
    """Outputs (see :func:`._kernel.outputs`) at every sample; the road on the segment
    that holds each time (right-continuous)."""
    nn = itab[I_NN]
    ne = itab[I_NE]
    road = np.zeros(road_layout_of(itab)[0])
    W = np.empty(_work_size(itab))
    dx = np.empty(Y.shape[1])
    imp = np.empty(0)
    s = 0
    ok = True
    for j in range(t_out.size):
        s = _sample_road(segs, s, t_out[j], road)
        ok &= ev(t_out[j], Y[j], road, itab, ftab, W, dx, imp)
        for i in range(3 * nn + ne):
            O[j, i] = W[i]
    return ok


@nb.njit(cache=True)
def _regime_outputs(ev, t_out, Y, segs, itab, ftab, C, D, undefined, Gx, Gu, thr, O):
    """Outputs at every sample into O (one row per output, as :func:`linear_outputs`):
    C x + D u where every regime's argument (rows Gx, Gu over the state and the road)
    is past its threshold, the system there being the linear one (C, D) of its linear
    regimes (:func:`.core._regime_system`; every row of a linear system), NaN in the
    rows ``undefined``; the evaluator elsewhere (a flywheel below saturation)."""
    nn = itab[I_NN]
    ne = itab[I_NE]
    n = Y.shape[1]
    no = 3 * nn + ne
    road = np.zeros(road_layout_of(itab)[0])
    W = np.empty(_work_size(itab))
    dx = np.empty(n)
    imp = np.empty(0)
    s = 0
    ok = True
    for j in range(t_out.size):
        s = _sample_road(segs, s, t_out[j], road)
        lin = True
        for g in range(thr.size):
            a = Gu[g, 0] * road[0] + Gu[g, 1] * road[1] + Gu[g, 2] * road[2]
            for q in range(n):
                a += Gx[g, q] * Y[j, q]
            if not abs(a) > thr[g]:
                lin = False
        if lin:
            for i in range(no):
                if undefined[i]:
                    O[i, j] = math.nan
                    continue
                acc = D[i, 0] * road[0] + D[i, 1] * road[1] + D[i, 2] * road[2]
                for q in range(n):
                    acc += C[i, q] * Y[j, q]
                O[i, j] = acc
        else:
            ok &= ev(t_out[j], Y[j], road, itab, ftab, W, dx, imp)
            for i in range(no):
                O[i, j] = W[i]
    return ok


@nb.njit(cache=True, inline="always")
def _node_xv(itab, n, Y, j, road):
    """(x, v) of node n at sample j: the ground, the drive (road), or a node whose
    displacement and velocity are states (the only kinds :func:`drive_forces` reads)."""
    b = itab[I_NODE] + NODE_W * n
    typ = itab[b]
    if typ == GROUND:
        return 0.0, 0.0
    if typ == ROAD:
        return road[0], road[1]
    return Y[j, itab[b + 1]], Y[j, itab[b + 2]]


@nb.njit(cache=True)
def drive_forces(t_out, Y, segs, itab, ftab, elems, out):
    """The summed force of the elements ``elems`` at every sample into ``out`` (a rig's
    force at its drive), each read from the states as :func:`._kernel.evaluate` computes
    it: springs, dampers and friction between the drive, the ground and nodes whose
    displacement and velocity are states (the caller checks)."""
    eo = itab[I_ELEM]
    road = np.zeros(road_layout_of(itab)[0])
    s = 0
    for j in range(t_out.size):
        s = _sample_road(segs, s, t_out[j], road)
        acc = 0.0
        for q in range(elems.size):
            b = eo + ELEM_W * elems[q]
            xt, vt = _node_xv(itab, itab[b + 1], Y, j, road)
            xb, vb = _node_xv(itab, itab[b + 2], Y, j, road)
            f = end_force(itab, ftab, b, xt - xb, vt - vb)
            acc = f if q == 0 else acc + f
        out[j] = acc


# ---------------------------------------------------------------------------------------
# exact steps of a linear system on a piecewise-linear road


@nb.njit(cache=True, inline="always")
def _series(coef, m, x):
    acc = 0.0
    for k in range(m - 1, -1, -1):
        acc = acc * x + coef[k]
    return acc


#: the linear walk's steps whose observers are summed at once
WALK_BLOCK = 512
#: the same for the exact steps of a system in a linear regime, between adaptive steps
X_BLOCK = 64
#: runs of steps of one length shorter than this have their signals summed step by step
#: (the regime's runs, between adaptive steps, are short: with runs of 8 and more by
#: columns its signals took 1.8x the time they took step by step)
ROW_RUN = 64


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _taylor_peak(TR, j, r, sgn, VT, i, xs, top, coef):
    """The maximum of sgn x the distinct signal r inside step i between the neighbours
    of its point ``top`` (the step's Taylor series in theta, sum_k (TR[j, r, k] . VT[:, i])
    theta^k, exact to round-off), where its derivative changes sign from + to - there:
    found by Newton's method on the derivative, kept inside the bracket of the sign
    change (bisection where Newton leaves it); -inf where it does not (the maximum is
    then at one of the points, which the caller has). ``coef``: scratch of
    TR.shape[2]."""
    npt = xs.size
    m = TR.shape[2]
    if m < 2:
        return -math.inf
    for k in range(m):
        acc = 0.0
        for q in range(VT.shape[0]):
            acc += TR[j, r, k, q] * VT[q, i]
        coef[k] = sgn * acc
    lo = xs[max(top - 1, 0)]
    hi = xs[min(top + 1, npt - 1)]
    d_lo = 0.0
    d_hi = 0.0
    for k in range(m - 1, 0, -1):
        d_lo = d_lo * lo + k * coef[k]
        d_hi = d_hi * hi + k * coef[k]
    if not (d_lo > 0.0 and d_hi < 0.0):
        return -math.inf
    x = xs[top]
    if x <= lo or x >= hi:
        x = 0.5 * (lo + hi)
    for _ in range(60):
        d1 = 0.0
        d2 = 0.0
        for k in range(m - 1, 1, -1):
            d1 = d1 * x + k * coef[k]
            d2 = d2 * x + k * (k - 1) * coef[k]
        d1 = d1 * x + coef[1]
        if d1 > 0.0:
            lo = x
        else:
            hi = x
        xn = x - d1 / d2 if d2 < 0.0 else 0.5 * (lo + hi)
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 1e-14 or hi - lo <= 1e-14:
            x = xn
            break
        x = xn
    return _series(coef, m, x)


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _observe_steps(itab, y, nst, H, J, VT, SR, TR, gw, xs, sref, SV, row, coef, hi, lo, done, acc,
                   pk, pp, npend, out_y):  # fmt: skip
    """The observers over nst exact steps (of the linear walk, or of a regime between
    adaptive steps; step i: length H[i], table row J[i], initial vector VT[:, i] = (the
    augmented state, the road's part), see :func:`.core._point_tables`), advanced in
    ``y`` from their values before the first.

    Every observed signal is linear in the step's initial vector: the distinct ones (nu)
    at the points theta = ``xs`` (the start, the quadrature nodes, the end) are
    SV[p nu + r, i] = sum_q SR[J[i], q, p nu + r] VT[q, i], summed over q in its order
    for each run of steps of one length, the table's zero
    entries skipped (a filter's states reach only the signals that read the filter:
    about half the table of a ride system; a product by BLAS took three times as long);
    a run of fewer than :data:`ROW_RUN` steps step by step, every entry (a row of the
    table at a time: the loop runs along the signals; by the zeros it ran over a handful
    of steps at each of the table's entries); then :func:`_observe_sums`. ``SV``:
    scratch of (SR.shape[2], at least nst), ``row`` of SR.shape[2]; ``hi``,
    ``lo`` (nu x at least nst), ``done`` (nu), ``acc`` (at least nst), ``coef``
    (TR.shape[2]): scratch of :func:`_observe_sums`."""
    nw = SR.shape[2]
    nq = VT.shape[0]
    i0 = 0
    while i0 < nst:
        j = J[i0]
        i1 = i0 + 1
        while i1 < nst and J[i1] == j:
            i1 += 1
        cnt = i1 - i0
        if cnt < ROW_RUN:
            for c in range(i0, i1):
                for w in range(nw):
                    row[w] = 0.0
                for q in range(nq):
                    vq = VT[q, c]
                    for w in range(nw):
                        row[w] += SR[j, q, w] * vq
                for w in range(nw):
                    SV[w, c] = row[w]
            i0 = i1
            continue
        for w in range(nw):
            srow = SV[w, i0:i1]  # views indexed from 0: the loops vectorise (from i0 they
            for c in range(cnt):  # did not, the index's sign unknown: 3.5x slower)
                srow[c] = 0.0
            for q in range(nq):
                s = SR[j, q, w]
                if s != 0.0:
                    vq = VT[q, i0:i1]
                    for c in range(cnt):
                        srow[c] += s * vq[c]
        i0 = i1
    _observe_sums(itab, y, nst, H, J, VT, SV, TR, gw, xs, sref, coef, hi, lo, done, acc, pk, pp,
                  npend, out_y)  # fmt: skip


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _observe_sums(itab, y, nst, H, J, VT, SV, TR, gw, xs, sref, coef, hi, lo, done, acc, pk, pp,
                  npend, out_y):  # fmt: skip
    """The observers over nst exact steps from their signals at the points (``SV``, see
    :func:`_observe_steps`; VT, J, H as there), one observer at a time over the steps:
    the integrals of squares, fourth powers and products by the quadrature (weights
    ``gw``, the sum over the nodes in their order, then y += H[i] x sum, as step by
    step); the running peaks from the points' values and, where a maximum inside the
    step may exceed the peak so far (its highest point above it less a tenth of the
    points' range: between the points a smooth signal rises above them by a few
    hundredths of that), the exact maximum (:func:`_taylor_peak`). A signal k read by an
    observer is sign(sref[k]) times the distinct signal |sref[k]| - 1 (a ride's +-a,
    +-a_w, +-z computed once); each distinct signal's highest and lowest point per step
    is found once, where a peak reads it (a peak of its negative reads the same: max(-s)
    = -min(s)). The linear observers (filters) are propagated with the system and left
    alone.

    Samples taken during the steps: sample pk[s] was taken after pp[s] of them (s <
    npend); its observers' values go to out_y[pk[s]]. Scratch (nothing is allocated
    here): ``hi``, ``lo`` (nu x at least nst), ``done`` (nu), ``acc`` (at least nst),
    ``coef`` (TR.shape[2])."""
    npt = xs.size
    ng = gw.size
    nu = SV.shape[0] // npt
    for r in range(nu):
        done[r] = False
    ob = itab[I_OBS]
    for o in range(itab[I_NOB]):
        bo = ob + OBS_W * o
        kind = itab[bo]
        if kind == OBS_LINEAR:
            continue
        slot = itab[bo + 3]
        ref = sref[itab[bo + 1]]
        r = abs(ref) - 1
        sgn = 1.0 if ref > 0 else -1.0
        if kind == OBS_PEAK:
            if not done[r]:
                for i in range(nst):
                    hi[r, i] = SV[r, i]
                    lo[r, i] = SV[r, i]
                for p in range(1, npt):
                    for i in range(nst):
                        s = SV[p * nu + r, i]
                        hi[r, i] = max(hi[r, i], s)
                        lo[r, i] = min(lo[r, i], s)
                done[r] = True
        else:
            for i in range(nst):
                acc[i] = 0.0
            if kind == OBS_SQUARE:
                for p in range(ng):
                    w = gw[p]
                    for i in range(nst):
                        a = SV[(p + 1) * nu + r, i]
                        acc[i] += w * (a * a)
            elif kind == OBS_FOURTH:
                for p in range(ng):
                    w = gw[p]
                    for i in range(nst):
                        a = SV[(p + 1) * nu + r, i]
                        v = a * a
                        acc[i] += w * (v * v)
            else:
                ref2 = sref[itab[bo + 2]]
                r2 = abs(ref2) - 1
                sgn2 = 1.0 if ref2 > 0 else -1.0
                for p in range(ng):
                    w = gw[p]
                    c1 = (p + 1) * nu + r
                    c2 = (p + 1) * nu + r2
                    for i in range(nst):
                        acc[i] += w * ((sgn * SV[c1, i]) * (sgn2 * SV[c2, i]))
        val = y[slot]
        pi = 0
        for i in range(nst):
            while pi < npend and pp[pi] == i:
                out_y[pk[pi], slot] = val
                pi += 1
            if kind == OBS_PEAK:
                high = hi[r, i] if sgn > 0.0 else -lo[r, i]
                low = lo[r, i] if sgn > 0.0 else -hi[r, i]
                best = max(val, high)
                if high > val - 0.1 * (high - low):
                    top = np.int64(0)  # the first of the highest points
                    for p in range(1, npt):
                        if sgn * SV[p * nu + r, i] > sgn * SV[top * nu + r, i]:
                            top = p
                    best = max(best, _taylor_peak(TR, J[i], r, sgn, VT, i, xs, top, coef))
                val = best
            else:
                val += H[i] * acc[i]
        while pi < npend:
            out_y[pk[pi], slot] = val
            pi += 1
        y[slot] = val


@nb.njit(cache=True)
def _exact_walk(ev, apply, segs, t_out, t_end, y, x1_before, v_before, jump_tol, vjump_tol, jump_ok,
               imp_unit, itab, ftab, hmin, hs, idx, PhiT, GX, GB, out_y, out_u, jumps, vjumps, ia,
               SR, gw, gx, TR, sref):  # fmt: skip
    """The steps of a linear system from one break point to the next, the break points
    being the road segment edges and the sample times ``t_out``.

    Without ``apply``: the step lengths go to ``hs``; returns (OK, number of steps).
    With ``apply``: step i advances the state ``y`` in place by the table row
    ``idx[i]``: y <- Phi y + GX X1(t) + GB X1' (the road displacement at the step's
    start and its constant rate on the segment; see :func:`.core._exact_tables`; Phi
    given transposed, ``PhiT[j, q, i]`` = Phi[j, i, q], so the product runs down
    contiguous columns: each y[i] summed in the order of q, as a row product would),
    samples go to ``out_y`` and the road (X1, X1', X1'' = 0) at them to ``out_u``.
    Road steps and road velocity jumps pass their impulses as in :func:`integrate`
    (constant inertances: the impulse flows are constant and one Euler step of each
    is exact); a road step with no finite response returns ROAD_STEP.

    Break points closer than ``hmin`` [s] to the last are passed without a step (a
    sample and a segment edge that differ by round-off: such a step's table is the
    identity).

    Observers (``itab`` holds them): the tables act on the augmented state, the rows
    ``ia`` of y (the system's states and its linear observers'); the walk keeps each
    step's initial vector v = (augmented state, X1, X1'), its length and table row, and
    every :data:`WALK_BLOCK` steps (and at the end) :func:`_observe_steps` advances the
    other observers over them from their signals at the step's start, the quadrature
    nodes ``gx`` (weights ``gw``) and its end (``SR``, :func:`.core._point_tables`; the
    peaks inside a step from the Taylor rows ``TR``; ``sref``: the signals read) and
    writes their values at the samples taken meanwhile. Without observers ``ia`` is
    every state and the rest is empty."""
    n = y.size
    na = ia.size
    observed = itab[I_NOB] > 0
    xs = np.empty(gx.size + 2)
    xs[0] = 0.0
    xs[-1] = 1.0
    xs[1:-1] = gx
    coef = np.empty(TR.shape[2])
    nbk = WALK_BLOCK if observed and apply else 1
    VT = np.empty((na + 2, nbk))  # the steps' initial vectors, a column each
    v = np.empty(na)
    H = np.empty(nbk)
    J = np.empty(nbk, np.int64)
    SV = np.empty((SR.shape[2], nbk))
    row = np.empty(SR.shape[2])
    nu = SR.shape[2] // xs.size
    hi = np.empty((nu, nbk))
    lo = np.empty((nu, nbk))
    done = np.empty(nu, np.bool_)
    acc = np.empty(nbk)
    pk = np.empty(nbk, np.int64)
    pp = np.empty(nbk, np.int64)
    nst = np.int64(0)
    npend = np.int64(0)
    nseg = segs.shape[0]
    k = 0
    m = 0
    prev = x1_before
    prev_v = v_before
    yn = np.empty(n)
    dx = np.empty(n)
    road = np.zeros(road_layout_of(itab)[0])
    W = np.empty(_work_size(itab))
    jerk = np.full(1, np.nan)
    imp = np.empty(imp_unit.size)
    for s in range(nseg):
        t0 = segs[s, 0]
        if t0 >= t_end and s > 0:
            break
        t1 = min(segs[s, 1], t_end)
        a = segs[s, 3]
        b = segs[s, 4]
        last = s == nseg - 1 or segs[s, 1] >= t_end
        if apply:
            if math.isfinite(prev_v) and abs(b - prev_v) > vjump_tol:
                vjumps[s] = b - prev_v
                road[0] = prev
                road[1] = prev_v
                road[2] = b - prev_v
                ev(0.0, y, road, itab, ftab, W, dx, jerk)
                if observed:
                    observe(itab, ftab, W, y, dx, np.bool_(True))
                for i in range(n):
                    y[i] += dx[i]
            jump = a - prev
            if abs(jump) > jump_tol:
                jumps[s] = jump
                if not jump_ok:
                    return ROAD_STEP, m
                for i in range(imp.size):
                    imp[i] = imp_unit[i] * jump
                road[0] = a
                road[1] = b
                road[2] = 0.0
                ev(0.0, y, road, itab, ftab, W, dx, imp)
                if observed:
                    observe(itab, ftab, W, y, dx, np.bool_(True))
                for i in range(n):
                    y[i] += dx[i]
        t = t0
        while True:
            early = k < t_out.size and t_out[k] <= t0  # a sample at the segment's start
            sample = early or (k < t_out.size and (t_out[k] < t1 or (last and t_out[k] <= t1)))
            tn = t_out[k] if sample and not early else (t0 if early else t1)
            h = tn - t
            if h > hmin:
                if apply:
                    if nst == nbk:
                        _observe_steps(itab, y, nst, H, J, VT, SR, TR, gw, xs, sref, SV, row, coef, hi,
                                       lo, done, acc, pk, pp, npend, out_y)  # fmt: skip
                        nst = np.int64(0)
                        npend = np.int64(0)
                    j = idx[m]
                    xr = a + b * (t - t0)
                    for i in range(na):
                        v[i] = y[ia[i]]
                        yn[i] = GX[j, i] * xr + GB[j, i] * b
                    q = 0
                    while q + 2 <= na:  # two columns at a time, each sum in the order of q
                        z0 = v[q]
                        z1 = v[q + 1]
                        for i in range(na):
                            yn[i] = (yn[i] + PhiT[j, q, i] * z0) + PhiT[j, q + 1, i] * z1
                        q += 2
                    if q < na:
                        z0 = v[q]
                        for i in range(na):
                            yn[i] += PhiT[j, q, i] * z0
                    for i in range(na):
                        y[ia[i]] = yn[i]
                    if observed:
                        for i in range(na):
                            VT[i, nst] = v[i]
                        VT[na, nst] = xr
                        VT[na + 1, nst] = b
                        H[nst] = h
                        J[nst] = j
                        nst += 1
                else:
                    hs[m] = h
                m += 1
            t = tn
            if not sample:
                break
            if apply:
                for i in range(n):
                    out_y[k, i] = y[i]
                out_u[k, 0] = a if early else a + b * (tn - t0)
                out_u[k, 1] = b
                out_u[k, 2] = 0.0
                if nst > 0:  # its observers once the block's are summed
                    if npend == nbk:
                        _observe_steps(itab, y, nst, H, J, VT, SR, TR, gw, xs, sref, SV, row, coef, hi,
                                       lo, done, acc, pk, pp, npend, out_y)  # fmt: skip
                        nst = np.int64(0)
                        npend = np.int64(0)
                        for i in range(n):
                            out_y[k, i] = y[i]
                    else:
                        pk[npend] = k
                        pp[npend] = nst
                        npend += 1
            k += 1
        prev = a + b * (t1 - t0)
        prev_v = b
        if last:
            break
    if nst > 0:
        _observe_steps(itab, y, nst, H, J, VT, SR, TR, gw, xs, sref, SV, row, coef, hi, lo, done, acc,
                       pk, pp, npend, out_y)  # fmt: skip
    return OK, m


def _readonly(a):
    """``a`` as a read-only view (the tables' type in the right-hand side's signature)."""
    if a.flags.writeable:
        a = a.view()
        a.setflags(write=False)
    return a


_NO_LEVELS = np.empty(0, np.int64)
#: no observers in the exact steps of the linear regimes (``xo`` of :func:`_advance`)
_NO_XOBS = (
    np.empty(0, np.int64), np.empty((0, 0, 0, 0)), np.empty((0, 3), np.int64), np.empty(0),
    np.empty(0), np.empty(0), np.empty((0, 0, 0, 0, 0)), np.empty(0, np.int64),
)  # fmt: skip


def _split_of(itab, ftab, n):
    """``fz`` of :func:`_advance`: the observers the stages move (the system's own
    table where nothing is split) and the tables of :func:`.observers.filter_split`."""
    if itab[I_NOB] == 0:
        return (_readonly(itab), *NO_SPLIT)
    return filter_split(itab, ftab, n)


def integrate(itab, ftab, segs, y, x1_before, t_end, rtol, atol, imp_unit, jump_ok, jump_tol,
              t_out, out_y, stats, jumps, max_steps, v_before, vjump_tol, vjumps, XE, XG, xkeys,
              xthr, xel, xcls, xq, ctl, xlev=None, xo=None):  # fmt: skip
    """:func:`_integrate` with the right-hand side compiled for the structure ``itab``
    (:func:`._compiled.rhs_for`); the arguments as there, ``xlev`` the rows of the
    level lengths in the exact-step table (none by default), ``xo`` the observers in
    the exact steps (none by default)."""
    ev = rhs_for(itab)
    ro_itab = _readonly(itab)
    # the generic tier's runs are timed (not while the integrator compiles); asking the
    # dispatcher for its signatures costs about 20 us, so only there
    warm = not ev.specialised and bool(_integrate.signatures)
    t0 = time.process_time()
    out = _integrate(
        ev, ro_itab, _readonly(ftab), segs, y, x1_before, t_end, rtol, atol,
        imp_unit, jump_ok, jump_tol, _readonly(t_out), out_y, stats, jumps, max_steps, v_before,
        vjump_tol, vjumps, XE, XG, xkeys, xthr, xel, xcls,
        _NO_LEVELS if xlev is None else xlev, xq, ctl,
        _signal_tables(_NO_XOBS if xo is None else xo),
        _split_of(itab, ftab, y.size), (ro_itab, *NO_SPLIT),
    )  # fmt: skip
    if warm:
        record(itab, time.process_time() - t0)
    return out


def outputs_many(t_out, Y, segs, itab, ftab, O):
    """:func:`_outputs_many` with the structure's right-hand side."""
    Y = np.ascontiguousarray(Y)  # rows of C layout: the right-hand side's state type
    return _outputs_many(rhs_for(itab, False), t_out, Y, segs, _readonly(itab), _readonly(ftab), O)


def regime_outputs(t_out, Y, segs, itab, ftab, *args):
    """:func:`_regime_outputs` with the structure's right-hand side."""
    Y = np.ascontiguousarray(Y)  # rows of C layout: the right-hand side's state type
    return _regime_outputs(
        rhs_for(itab, False), t_out, Y, segs, _readonly(itab), _readonly(ftab), *args
    )


def _signal_tables(xo):
    """``xo`` with its signal tables (SR, TR) read-only, as :func:`exact_walk` passes
    them: the observers' sums over exact steps are compiled once for both callers."""
    ia, SR, rows, gw, gx, cap, TR, sref = xo
    return ia, _readonly(SR), rows, gw, gx, cap, _readonly(TR), sref


def exact_walk(apply, segs, t_out, t_end, y, x1_before, v_before, jump_tol, vjump_tol, jump_ok,
               imp_unit, itab, ftab, *args):  # fmt: skip
    """:func:`_exact_walk` with the structure's right-hand side (its tables, read, passed
    read-only whether kept on the system or made for this call: one compiled signature)."""
    hmin, hs, idx, PhiT, GX, GB, out_y, out_u, jumps, vjumps, ia, SR, gw, gx, TR, sref = args
    return _exact_walk(
        rhs_for(itab, False), apply, segs, t_out, t_end, y, x1_before, v_before, jump_tol,
        vjump_tol, jump_ok, imp_unit, _readonly(itab), _readonly(ftab), hmin, hs, idx,
        _readonly(PhiT), _readonly(GX), _readonly(GB), out_y, out_u, jumps, vjumps, ia,
        _readonly(SR), gw, gx, _readonly(TR), sref,
    )  # fmt: skip


@nb.njit(cache=True)
def foh_response(Ad, Bd0, Bd1, C, D, u, out):
    """out[i] = C x_i + D u_i of x' = A x + B u from rest, u linear between the uniform
    samples u_i (first-order hold): x_{i+1} = Ad x_i + Bd0 u_i + Bd1 u_{i+1}, the exact
    discretisation (one input; the matrices from :func:`.core._foh_matrices`)."""
    n = Ad.shape[0]
    x = np.zeros(n)
    xn = np.empty(n)
    if u.size:
        out[0] = D * u[0]
    for i in range(1, u.size):
        acc = 0.0
        for r in range(n):
            s = Bd0[r] * u[i - 1] + Bd1[r] * u[i]
            for q in range(n):
                s += Ad[r, q] * x[q]
            xn[r] = s
        for r in range(n):
            x[r] = xn[r]
            acc += C[r] * x[r]
        out[i] = acc + D * u[i]


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def linear_outputs(Yt, Ut, C, D, undefined, O):
    """O = C Yt + D Ut at every sample, state- and output-major (one row per state,
    input or output; rows run over the samples), NaN in the rows ``undefined``."""
    for i in range(C.shape[0]):
        if undefined[i]:
            O[i, :] = math.nan
            continue
        O[i, :] = 0.0
        for q in range(C.shape[1]):
            c = C[i, q]
            if c != 0.0:
                for j in range(O.shape[1]):
                    O[i, j] += c * Yt[q, j]
        for q in range(3):
            d = D[i, q]
            if d != 0.0:
                for j in range(O.shape[1]):
                    O[i, j] += d * Ut[q, j]


# ---------------------------------------------------------------------------------------
# fixed steps of classical Runge-Kutta (RK4) on a road given at samples: the steps end on
# every segment edge (the road's kinks) and every output sample, and are at most the
# fixed step long; no error control. Where the system has switching functions (tyre
# lift-off, flywheel saturation, ...) the switching functions at each step's end are
# evaluated too (with the step's law, on its segment), a sign change of one over the step
# is located on the method's own continuous extension (cubic in the step's fraction,
# from its four stages: no further evaluation of the right-hand side), and the step is
# taken again from its start to the crossing: the state at an event is an RK4 solution
# (order 4), not the extension's (order 3).


@nb.njit(cache=True, inline="always")
def _rk4_f(ev, segs, i, t, y, itab, ftab, imp, dy, road, work, stats):
    """The derivative at (t, y) with the road of segment i (the observers' included)."""
    road_at(segs, i, t, road)
    return _rk4_eval(ev, t, y, itab, ftab, imp, dy, road, work, stats)


@nb.njit(cache=True, inline="always")
def _rk4_eval(ev, t, y, itab, ftab, imp, dy, road, work, stats):
    """:func:`_rk4_f` with the road at t already in ``road``."""
    stats[2] += 1
    ok = ev(t, y, road, itab, ftab, work, dy, imp)
    if itab[I_NOB] > 0:
        observe(itab, ftab, work, y, dy, np.bool_(False))
    return ok


@nb.njit(cache=True, inline="always")
def _rk4_step(ev, segs, i, t, h, y, k1, itab, ftab, imp, k2, k3, k4, ys, yt, road, work, stats):
    """One classical Runge-Kutta step of length h from (t, y), k1 = f(t, y) given: the
    result in yt (ys scratch). Returns False if a force balance failed. ``imp``: that of
    its three stages (:data:`._kernel.STAGE` where no observer reads the work array)."""
    n = y.size
    for q in range(n):
        ys[q] = y[q] + 0.5 * h * k1[q]
    ok = _rk4_f(ev, segs, i, t + 0.5 * h, ys, itab, ftab, imp, k2, road, work, stats)
    for q in range(n):
        ys[q] = y[q] + 0.5 * h * k2[q]
    ok &= _rk4_eval(ev, t + 0.5 * h, ys, itab, ftab, imp, k3, road, work, stats)  # k2's road
    for q in range(n):
        ys[q] = y[q] + h * k3[q]
    ok &= _rk4_f(ev, segs, i, t + h, ys, itab, ftab, imp, k4, road, work, stats)
    for q in range(n):
        yt[q] = y[q] + h / 6.0 * (k1[q] + 2.0 * (k2[q] + k3[q]) + k4[q])
    return ok


@nb.njit(cache=True, inline="always")
def _rk4_dense(y, k1, k2, k3, k4, h, th, out):
    """The continuous extension of the classical Runge-Kutta step of length h from y
    (stages k1 .. k4) at theta = th: y + h (b1 k1 + b2 (k2 + k3) + b4 k4) with
    b1 = th - 3 th^2 / 2 + 2 th^3 / 3, b2 = th^2 - 2 th^3 / 3, b4 = 2 th^3 / 3 - th^2 / 2,
    the step's weights at th = 1 (order 3; Hairer, Norsett and Wanner, Solving Ordinary
    Differential Equations I, section II.6)."""
    th2 = th * th
    th3 = th2 * th
    b1 = th - 1.5 * th2 + th3 * (2.0 / 3.0)
    b2 = th2 - th3 * (2.0 / 3.0)
    b4 = th3 * (2.0 / 3.0) - 0.5 * th2
    for q in range(y.size):
        out[q] = y[q] + h * (b1 * k1[q] + b2 * (k2[q] + k3[q]) + b4 * k4[q])


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _rk4_output(ev, segs, i, tk, y, itab, ftab, imp, dy, W, road, out_o, j):
    """Row j of ``out_o``: the outputs at the sample tk (state ``y``) as
    :func:`_outputs_many` gives them (the road on the segment that holds tk,
    right-continuous, walking on from segment i; no held side; ``road``'s held sides
    are 0), evaluated into ``W``."""
    s = i
    while s + 1 < segs.shape[0] and segs[s + 1, 0] <= tk:
        s += 1
    road_at(segs, s, tk, road)
    ev(tk, y, road, itab, ftab, W, dy, imp)
    for c in range(out_o.shape[1]):
        out_o[j, c] = W[c]


@nb.njit(cache=True, inline="always")
def _rk4_store(ev, segs, i, t, y, itab, ftab, imp, dy, wo, oroad, t_out, out_y, out_o, k, pend):
    """The state at t into the rows of ``out_y`` of the samples up to t; with outputs
    (``out_o`` has rows) a row at t itself is left pending (returned: its outputs come
    from the evaluation at the next step's start, see :func:`_fixed_rk4`), any other
    (one left pending before, a sample within round-off of t) evaluated at once.
    Returns (k, pend)."""
    while k < t_out.size and t_out[k] <= t:
        for q in range(y.size):
            out_y[k, q] = y[q]
        if out_o.shape[0] > 0:
            if pend >= 0:
                _rk4_output(ev, segs, i, t_out[pend], y, itab, ftab, imp, dy, wo, oroad, out_o,
                            pend)  # fmt: skip
                pend = -1
            if t_out[k] == t:
                pend = k
            else:
                _rk4_output(ev, segs, i, t_out[k], y, itab, ftab, imp, dy, wo, oroad, out_o, k)
        k += 1
    return k, pend


@nb.njit(cache=True)
def _fixed_rk4(ev, itab, ftab, segs, y, t_end, hfix, t_out, out_y, stats, max_steps, out_o):
    """Integrate a core system over the road segments ``segs`` (continuous in
    displacement: no road steps) from the start of the first to ``t_end`` by classical
    Runge-Kutta steps of at most ``hfix``, each ending on the next segment edge or
    output sample if that comes sooner (a step within 1 % of its length of one is
    stretched to it). ``y`` is advanced in place; the states at ``t_out`` go to the rows
    of ``out_y``; ``stats`` as :func:`_integrate` (steps, steps tried again at an event
    at their start, right-hand sides, events, 0).

    Events as in :func:`_advance`: each step takes the law of the side of each kink it
    starts on; the crossings of one attempt within :data:`SIMULTANEOUS` (of the step) of
    the earliest are one event, whose elements take their other side's law at its
    instant; at a segment edge each element's side is read from its switching functions
    on the new segment. Running peaks (``OBS_PEAK`` observers) are raised at the start of
    every step and at the end (their values at the step ends only). Returns (status,
    number of samples written).

    ``out_o``: (t_out.size, 3 nn + ne) for the outputs at ``t_out`` too (what
    :func:`_outputs_many` gives from the states), or no rows. At a sample on a segment
    edge the step that starts there evaluates the right-hand side at the sample on the
    segment that follows (right-continuous, as the outputs read the road) with each
    kink's side the one its switching functions give, which is the law the outputs
    evaluate without a held side: where the tables have the mass matrix factored
    (:func:`._kernel.dense_tables`: no clutch, no gated screw, whose laws read the side
    otherwise) and no switching function is exactly 0 there, the outputs are that
    evaluation's, copied; elsewhere they are evaluated."""
    n = y.size
    ne = itab[I_NE]
    # every array the run needs, allocated here: the run (:func:`_fixed_rk4_run`) is
    # compiled without reference counting (see :func:`_advance`)
    work = np.empty(_work_size(itab))
    road_n = road_layout_of(itab)[0]
    road = np.zeros(road_n)
    imp = np.empty(0)
    only = np.full(1, np.inf)  # SWITCHES_ONLY, as a local array (a global one is read-only)
    ofw = np.full(1, -np.inf)  # SWITCHES_OF_WORK
    # the inner stages: _kernel.STAGE as a local array (no outputs into the work array)
    # where no observer reads it
    stg = np.full(2, np.inf) if itab[I_NOB] == 0 else np.empty(0)
    K4 = np.empty((4, n))  # the stages k1..k4, one row each (:func:`_locate` reads them)
    k1, k2, k3, k4 = K4[0], K4[1], K4[2], K4[3]
    rng = np.zeros(3, dtype=np.int64)  # the segment stepped on, for _locate
    mode = np.zeros(1, dtype=np.int64)  # mode 0, from an array: not a literal constant
    rf = np.zeros(3)  # no fixed road (mode 0)
    fzi = np.zeros(FZ_HEAD, dtype=np.int64)  # no observer slots left out of the stages
    f1 = np.empty(n)
    ys = np.empty(n)
    yt = np.empty(n)
    yd = np.empty(n)
    dy = np.empty(n)
    sw = np.empty(2 * ne)
    swn = np.empty(2 * ne)
    swx = np.empty(2 * ne)
    xloc = np.empty(2 * ne)
    xfl = np.empty(ne)
    pastv = np.zeros(ne)
    flipm = np.zeros(ne, np.bool_)
    swf = np.zeros(2 * ne, np.bool_)
    wo = np.empty(work.size)  # the outputs evaluated apart from the stepping
    oroad = np.zeros(road_n)
    scratch = (work, road, imp, only, ofw, K4, k1, k2, k3, k4, f1, ys, yt, yd, dy, sw, swn, swx,
               xloc, xfl, pastv, flipm, swf, wo, oroad, stg, rng, mode, rf, fzi)  # fmt: skip
    return _fixed_rk4_run(ev, itab, ftab, segs, y, t_end, hfix, t_out, out_y, stats, max_steps,
                          out_o, scratch)  # fmt: skip


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _fixed_rk4_run(ev, itab, ftab, segs, y, t_end, hfix, t_out, out_y, stats, max_steps, out_o,
                   scratch):  # fmt: skip
    """The run of :func:`_fixed_rk4` on the arrays it allocated (``scratch``), compiled
    without numba's reference counting (it allocates nothing)."""
    (work, road, imp, only, ofw, K4, k1, k2, k3, k4, f1, ys, yt, yd, dy, sw, swn, swx, xloc, xfl,
     pastv, flipm, swf, wo, oroad, stg, rng, mode, rf, fzi) = scratch  # fmt: skip
    n = y.size
    ne = itab[I_NE]
    nseg = segs.shape[0]
    _, _, hs = road_layout_of(itab)
    reuse = out_o.shape[0] > 0 and itab[I_DNS] > 0
    pend = -1  # a sample at t whose outputs are pending
    i = 0
    t = segs[0, 0]
    k, pend = _rk4_store(ev, segs, i, t, y, itab, ftab, imp, dy, wo, oroad, t_out, out_y, out_o,
                         0, pend)  # fmt: skip
    if not _rk4_f(ev, segs, i, t, y, itab, ftab, imp, k1, road, work, stats):
        return BALANCE_FAILED, k
    events = switches(itab, ftab, work, sw) > 0
    cheap = not switches_read_forces(itab, ftab)
    if events:  # every step takes the law of the side of each kink it starts on
        _sides(sw, road, hs)
        if not _rk4_f(ev, segs, i, t, y, itab, ftab, imp, k1, road, work, stats):
            return BALANCE_FAILED, k
    need = False  # k1 is to be evaluated at (t, y)
    while t < t_end:
        if stats[0] + stats[1] >= max_steps:
            return TOO_MANY_STEPS, k
        moved = False
        while i + 1 < nseg and segs[i + 1, 0] <= t:  # a step that ended on an edge
            i += 1
            moved = True
        natural = moved and reuse
        if need or moved:
            if not _rk4_f(ev, segs, i, t, y, itab, ftab, imp, k1, road, work, stats):
                return BALANCE_FAILED, k
            if events:
                _work_switches(ev, y, road, itab, ftab, work, sw, ofw)
                if moved:  # each element's side from its switching functions here
                    changed = False
                    for e in range(ne):
                        g = max(sw[2 * e], sw[2 * e + 1])
                        if g == 0.0:
                            natural = False
                        sd = 1.0 if g > 0.0 else (-1.0 if g < 0.0 else road[hs + e])
                        if sd != road[hs + e]:
                            road[hs + e] = sd
                            changed = True
                    if changed:
                        if not _rk4_f(ev, segs, i, t, y, itab, ftab, imp, k1, road, work, stats):
                            return BALANCE_FAILED, k
            need = False
        if pend >= 0:  # the outputs of the sample at t
            if natural:  # the evaluation at (t, y) just made, with the outputs' law
                for c in range(out_o.shape[1]):
                    out_o[pend, c] = work[c]
            else:
                _rk4_output(ev, segs, i, t, y, itab, ftab, imp, dy, wo, oroad, out_o, pend)
            pend = -1
        peaks(itab, ftab, work, y)  # the work array holds the evaluation at (t, y)
        lim = t_end if i == nseg - 1 else min(segs[i, 1], t_end)
        if k < t_out.size and t_out[k] < lim:
            lim = t_out[k]
        if lim - t <= 1e-14 * max(abs(t), 1.0):
            # what is left to a break point is below round-off: the state stands
            t = lim
            k, pend = _rk4_store(ev, segs, i, t, y, itab, ftab, imp, dy, wo, oroad, t_out, out_y,
                                 out_o, k, pend)  # fmt: skip
            continue
        h = hfix
        if t + 1.01 * h >= lim:
            h = lim - t
            tn = lim
        else:
            tn = t + h
        ok = _rk4_step(ev, segs, i, t, h, y, k1, itab, ftab, stg, k2, k3, k4, ys, yt, road,
                       work, stats)  # fmt: skip
        if not ok:
            return BALANCE_FAILED, k
        for q in range(n):
            if not math.isfinite(yt[q]):
                return NOT_FINITE, k
        flip = False
        if events:
            # the derivative at the step's end (its law, its segment) serves the next step
            # unless the step ends on a segment edge (the next step's road rate differs:
            # its first stage is evaluated there); there the switching functions alone
            # are read
            fresh = cheap and i + 1 < nseg and segs[i + 1, 0] <= tn
            if fresh:
                _motion_switches(ev, segs, i, tn, yt, itab, ftab, road, work, swn, only)
            else:
                if not _rk4_f(ev, segs, i, tn, yt, itab, ftab, imp, f1, road, work, stats):
                    return BALANCE_FAILED, k
                _work_switches(ev, yt, road, itab, ftab, work, swn, ofw)
            th = 2.0
            forced = -1
            rng[0] = i
            rng[1] = i + 1
            rng[2] = i
            for e in range(2 * ne):
                xloc[e] = 2.0
                if sw[e] * swn[e] < 0.0:
                    xloc[e] = _locate(ev, e, sw[e], swn[e], t, h, y, yt, K4, mode[0], segs, rng,
                                      itab, ftab, imp, rf, dy, road, work, stats, yd, swx, itab,
                                      fzi, cheap, only, ofw)  # fmt: skip
                    if xloc[e] < th:
                        th = xloc[e]
                        forced = e
            if forced >= 0:
                # the crossings within SIMULTANEOUS of the earliest switch with it
                _simultaneous(xloc, th, sw, ne, swf, flipm, xfl, pastv)
                if th <= SIMULTANEOUS:
                    # at the step's start: the other side's law from there, the step again
                    _switch_at_start(road, hs, ne, flipm, pastv, sw, swf)
                    if not _rk4_f(ev, segs, i, t, y, itab, ftab, imp, k1, road, work, stats):
                        return BALANCE_FAILED, k
                    stats[1] += 1
                    continue
                if th < 1.0 - SIMULTANEOUS:  # the step again, from its start to the crossing
                    h = th * h
                    tn = t + h
                    ok = _rk4_step(ev, segs, i, t, h, y, k1, itab, ftab, stg, k2, k3, k4, ys, yt,
                                   road, work, stats)  # fmt: skip
                    if not ok:
                        return BALANCE_FAILED, k
                stats[3] += 1
                flip = True
            else:
                sw, swn = swn, sw  # the step's end's switching functions: the next start's
                if fresh:
                    need = True
                else:
                    for q in range(n):
                        k1[q] = f1[q]  # the derivative at the step's end, with the same law
        else:
            need = True
        stats[0] += 1
        for q in range(n):
            y[q] = yt[q]
        t = tn
        k, pend = _rk4_store(ev, segs, i, t, y, itab, ftab, imp, dy, wo, oroad, t_out, out_y,
                             out_o, k, pend)  # fmt: skip
        if flip:  # past the kink: its other side's law from here
            for q in range(ne):
                if flipm[q]:
                    road[hs + q] = pastv[q]
            if not _rk4_f(ev, segs, i, t, y, itab, ftab, imp, k1, road, work, stats):
                return BALANCE_FAILED, k
            _work_switches(ev, y, road, itab, ftab, work, sw, ofw)
            _past_kink(sw, swf, pastv)  # on the kink: the next step starts past it
    if pend >= 0:
        _rk4_output(ev, segs, i, t, y, itab, ftab, imp, dy, wo, oroad, out_o, pend)
    if itab[I_NOB] > 0:  # the peaks at the end
        _rk4_f(ev, segs, i, t, y, itab, ftab, imp, dy, road, work, stats)
        peaks(itab, ftab, work, y)
    return OK, k


_NO_OUTPUTS = np.empty((0, 0))


def integrate_fixed(itab, ftab, segs, y, t_end, h, t_out, out_y, stats, max_steps, out_o=None):
    """:func:`_fixed_rk4` with the right-hand side compiled for the structure ``itab``
    (:func:`._compiled.rhs_for`). ``segs`` must join in displacement (no road steps).
    ``out_o``: (t_out.size, 3 nn + ne) for the outputs at ``t_out`` (those of
    :func:`outputs_many`), or None."""
    ev = rhs_for(itab)
    warm = not ev.specialised and bool(_fixed_rk4.signatures)  # as in integrate
    t0 = time.process_time()
    out = _fixed_rk4(
        ev, _readonly(itab), _readonly(ftab), segs, y, float(t_end), float(h), t_out, out_y,
        stats, int(max_steps), _NO_OUTPUTS if out_o is None else out_o,
    )  # fmt: skip
    if warm:
        record(itab, time.process_time() - t0)
    return out
