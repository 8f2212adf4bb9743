"""Exact steps through the linear phases of the quarter car.

While the flywheel is saturated (``afw`` with the thesis or momentum law and
|r v| >= w_sat), and always for ``traditional`` and ``cfw``, the quarter car with its
Wk filter is a linear time-invariant system driven by the road, and every road
segment (affine or offset sine) is itself the output of a small linear system. The
state z = (x2, v2, x3, v3, 8 Wk states, road generator g) then obeys z' = M z exactly,
and a step of length ``h`` is the matrix exponential exp(M h) applied to z: no
truncation error, no step-size control.

The road generator is g = (x_a, x_o, v_r) with road displacement x_a + x_o and road
velocity v_r, and g' = (alpha v_r, (1 - alpha) v_r, -omega^2 x_o): alpha = 1, omega = 0
for an affine segment and alpha = 0 for a sine of angular frequency omega. M thus
depends on the segment only through (alpha, omega), and is set up once per distinct pair.

Steps come in four lengths, 10, 5, 2.5 and 1.25 ms (levels 0-3). The outputs (relative
velocity, body acceleration, Wk-weighted acceleration, deflection, grip, tyre force)
at the start, the Gauss-Legendre nodes and the end of a step are rows r exp(M s)
applied to z, precomputed once; the metric integrals are the Gauss-Legendre sums
(16, 10, 8, 8 nodes: below 1e-12 relative error on the fastest transient of the Wk
filter, its 100 Hz section, raised to the fourth power), the peaks the largest of
those values, refined on the polynomial through them. A step is taken only when the
relative velocity stays above the saturation speed (with a margin) at every point, so
it never crosses the kink of the inertia law; the longest such step is taken, and if
none is, the Dormand-Prince integrator of :mod:`._kernels` goes on. See
docs/decisions.md, "Exact steps through the linear phases".
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .model import P_C, P_CT, P_GRIP, P_IM, P_IMT, P_K, P_KIND, P_KT, P_MU

leaf = nb.njit(cache=True, _nrt=False)
# dot products and matrix products may be reassociated (vectorised): round-off only
vleaf = nb.njit(cache=True, _nrt=False, fastmath={"reassoc", "contract"})

NZ = 15  # x2, v2, x3, v3, 8 Wk states, road generator (x_a, x_o, v_r)
NCAR = 4
IG = 12  # first generator index
# outputs
O_V, O_A3, O_AW, O_Z, O_GRIP, O_FT = 0, 1, 2, 3, 4, 5
NO = 6
#: the longest exact step [s] and the number of levels (halvings)
H_EXACT = 0.01
N_LEVELS = 4
#: Gauss-Legendre nodes per level (10, 5, 2.5, 1.25 ms)
N_GAUSS = (16, 10, 8, 8)
N_POINTS_MAX = max(N_GAUSS) + 2
#: terms of the Taylor series of a row times exp(M r), |r| <= 0.625 ms (14 already
#: reach the round-off of the matrix exponential)
N_TAYLOR = 16
#: the relative velocity must exceed the saturation speed by this factor at every
#: point of an exact step
SAT_MARGIN = 1.1


def _level_tables():
    """Per level: point positions in [0, 1] (start, Gauss nodes, end), quadrature
    weights (zero at start and end) and barycentric interpolation weights."""
    xs = np.zeros((N_LEVELS, N_POINTS_MAX))
    wq = np.zeros((N_LEVELS, N_POINTS_MAX))
    bw = np.zeros((N_LEVELS, N_POINTS_MAX))
    npts = np.zeros(N_LEVELS, dtype=np.int64)
    for lev, ng in enumerate(N_GAUSS):
        x, w = np.polynomial.legendre.leggauss(ng)
        pts = np.r_[0.0, 0.5 * (x + 1.0), 1.0]
        n = pts.size
        xs[lev, :n] = pts
        wq[lev, 1 : n - 1] = 0.5 * w
        for i in range(n):
            bw[lev, i] = 1.0 / np.prod(pts[i] - np.delete(pts, i))
        bw[lev, :n] /= np.max(np.abs(bw[lev, :n]))
        npts[lev] = n
    return xs, wq, bw, npts


XS, WQ, BW, NPTS = _level_tables()


@leaf
def build_matrix(p, wk, me, alpha, omega, M, rows):
    """Fill M (NZ x NZ) and the output rows (NO x NZ) of the linear phase with
    effective inertance ``me`` [kg] (unused without an inerter)."""
    for i in range(NZ):
        for j in range(NZ):
            M[i, j] = 0.0
    for o in range(NO):
        for j in range(NZ):
            rows[o, j] = 0.0
    im, imt, mu = p[P_IM], p[P_IMT], p[P_MU]
    d = me / (1.0 + me * mu) if p[P_KIND] == 1.0 else 0.0
    cf = 1.0 - d * mu  # coefficient of fs in fs + f_inerter
    ct = d * imt  # coefficient of ft in fs + f_inerter
    # fs = K (x3 - x2) + C (v3 - v2); ft = KT (x2 - x_a - x_o) + CT (v2 - v_r)
    fs = rows[O_Z]  # scratch, set to the deflection row below
    ft = rows[O_FT]
    fs[0] = -p[P_K]
    fs[2] = p[P_K]
    fs[1] = -p[P_C]
    fs[3] = p[P_C]
    ft[0] = p[P_KT]
    ft[IG] = -p[P_KT]
    ft[IG + 1] = -p[P_KT]
    ft[1] = p[P_CT]
    ft[IG + 2] = -p[P_CT]
    for j in range(NZ):
        s = cf * fs[j] + ct * ft[j]
        M[3, j] = -im * s
        M[1, j] = imt * (s - ft[j])
        rows[O_A3, j] = M[3, j]
    M[0, 1] = 1.0
    M[2, 3] = 1.0
    # Wk: four second-order sections in cascade, input a3 (metrics.wk_sections)
    u = rows[O_AW]
    for j in range(NZ):
        u[j] = rows[O_A3, j]
    for s in range(4):
        i = NCAR + 2 * s
        w0 = wk[s, 0]
        M[i, i + 1] = w0
        for j in range(NZ):
            M[i + 1, j] = w0 * u[j]
        M[i + 1, i] -= w0
        M[i + 1, i + 1] -= wk[s, 1]
        for j in range(NZ):
            u[j] = wk[s, 4] * u[j]
        u[i] += wk[s, 2]
        u[i + 1] += wk[s, 3]
    # road generator
    M[IG, IG + 2] = alpha
    M[IG + 1, IG + 2] = 1.0 - alpha
    M[IG + 2, IG + 1] = -omega * omega
    # the remaining outputs
    for j in range(NZ):
        fs[j] = 0.0
    fs[0] = -1.0
    fs[2] = 1.0
    rows[O_V, 1] = -1.0
    rows[O_V, 3] = 1.0
    g = p[P_GRIP]
    rows[O_GRIP, 0] = g
    rows[O_GRIP, IG] = -g
    rows[O_GRIP, IG + 1] = -g


@vleaf
def _matmul(a, b, out):
    n = a.shape[0]
    for i in range(n):
        for j in range(n):
            out[i, j] = 0.0
        for k in range(n):
            aik = a[i, k]
            for j in range(n):
                out[i, j] += aik * b[k, j]


@vleaf
def _rowmul(r, b, out):
    """out = r b (row vector times square matrix)."""
    n = b.shape[0]
    for j in range(n):
        out[j] = 0.0
    for k in range(n):
        rk = r[k]
        for j in range(n):
            out[j] += rk * b[k, j]


@leaf
def expm(A, h, out, w1):
    """out = exp(A h) by scaling and squaring of a Taylor series (A, out, w1 square)."""
    n = A.shape[0]
    norm = 0.0
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += abs(A[i, j])
        norm = max(norm, s)
    norm *= h
    sq = 0
    while norm > 0.25:
        norm *= 0.5
        sq += 1
    hs = h / 2.0**sq
    # Horner: I + As (I + As/2 (I + ... (I + As/K))), truncation below 0.25^15/15!
    for i in range(n):
        for j in range(n):
            out[i, j] = 1.0 if i == j else 0.0
    for k in range(14, 0, -1):
        c = hs / k
        _matmul(A, out, w1)
        for i in range(n):
            for j in range(n):
                out[i, j] = c * w1[i, j] + (1.0 if i == j else 0.0)
    for _ in range(sq):
        _matmul(out, out, w1)
        for i in range(n):
            for j in range(n):
                out[i, j] = w1[i, j]


@vleaf
def setup(p, wk, me, alpha, omega, M, rows, E, P, RT, T, W, w1):
    """Build M and the rows; E[lev] = exp(M h_lev); RT[lev, k, i NO + o] = component k
    of rows[o] exp(M s_i) at the points s_i of each level. P (9 x NZ x NZ: exp(M k
    sigma)), T (N_TAYLOR x NO x NZ), W (NO x NZ) and w1 are work space."""
    build_matrix(p, wk, me, alpha, omega, M, rows)
    nb_ = 2 ** (N_LEVELS - 1)
    sig = H_EXACT / nb_  # the shortest step
    expm(M, sig, E[N_LEVELS - 1], w1)
    for lev in range(N_LEVELS - 2, -1, -1):
        _matmul(E[lev + 1], E[lev + 1], E[lev])
    # P[k] = exp(M k sigma), k = 0..8
    for i in range(NZ):
        for j in range(NZ):
            P[0, i, j] = 1.0 if i == j else 0.0
            P[1, i, j] = E[N_LEVELS - 1, i, j]
    for k in range(2, nb_ + 1):
        _matmul(P[k - 1], P[1], P[k])
    # Taylor coefficients rows[o] M^k / k!
    for o in range(NO):
        for j in range(NZ):
            T[0, o, j] = rows[o, j]
    for k in range(1, N_TAYLOR):
        for o in range(NO):
            for j in range(NZ):
                T[k, o, j] = 0.0
            for i in range(NZ):
                ti = T[k - 1, o, i] / k
                for j in range(NZ):
                    T[k, o, j] += ti * M[i, j]
    for lev in range(N_LEVELS):
        h = H_EXACT / 2.0**lev
        for ip in range(NPTS[lev]):
            s_pt = XS[lev, ip] * h
            # nearest multiple of sigma, then the Taylor series over |r| <= sigma / 2
            kk = int(s_pt / sig + 0.5)
            kk = min(max(kk, 0), nb_)
            r = s_pt - kk * sig
            for o in range(NO):
                for j in range(NZ):
                    W[o, j] = T[N_TAYLOR - 1, o, j]
            for k in range(N_TAYLOR - 2, -1, -1):
                for o in range(NO):
                    for j in range(NZ):
                        W[o, j] = T[k, o, j] + r * W[o, j]
            for o in range(NO):
                c = ip * NO + o
                for j in range(NZ):
                    RT[lev, j, c] = 0.0
                for i in range(NZ):
                    wi = W[o, i]
                    for j in range(NZ):
                        RT[lev, j, c] += wi * P[kk, i, j]


@vleaf
def outputs(RT, lev, z, F):
    """F[i NO + o] = output o at point i of the level: RT[lev, :, i NO + o] . z."""
    nr = NPTS[lev] * NO
    for c in range(nr):
        F[c] = 0.0
    for k in range(NZ):
        zk = z[k]
        for c in range(nr):
            F[c] += RT[lev, k, c] * zk


@leaf
def saturated(F, lev, v_sat):
    """True when |v| >= SAT_MARGIN v_sat with one sign at every point of the step."""
    lim = SAT_MARGIN * v_sat
    pos = F[O_V] > 0.0
    for ip in range(NPTS[lev]):
        v = F[ip * NO + O_V]
        if (v > 0.0) != pos or abs(v) < lim:
            return False
    return True


@vleaf
def propagate(E, lev, z, zn):
    """zn = E[lev] z."""
    for i in range(NZ):
        s = 0.0
        for k in range(NZ):
            s += E[lev, i, k] * z[k]
        zn[i] = s


@leaf
def interp(F, o, lev, th):
    """Polynomial through the step's points of output o, at theta in [0, 1]
    (barycentric form)."""
    num = 0.0
    den = 0.0
    for ip in range(NPTS[lev]):
        d = th - XS[lev, ip]
        if d == 0.0:
            return F[ip * NO + o]
        c = BW[lev, ip] / d
        num += c * F[ip * NO + o]
        den += c
    return num / den


@leaf
def refine(F, o, sign, lev, ip, peak):
    """Largest value of sign * the polynomial of output o next to point ip, where the
    parabola through ip and its neighbours puts a maximum above ``peak``: successive
    parabolic interpolation, kept inside the bracket; else the value at ip."""
    npt = NPTS[lev]
    f_ip = sign * F[ip * NO + o]
    if ip == 0:
        i1, i2, i3 = 0, 1, 2
        lo, hi = XS[lev, 0], XS[lev, 1]
    elif ip == npt - 1:
        i1, i2, i3 = npt - 3, npt - 2, npt - 1
        lo, hi = XS[lev, npt - 2], XS[lev, npt - 1]
    else:
        i1, i2, i3 = ip - 1, ip, ip + 1
        lo, hi = XS[lev, ip - 1], XS[lev, ip + 1]
    x1, x2, x3 = XS[lev, i1], XS[lev, i2], XS[lev, i3]
    f1 = sign * F[i1 * NO + o]
    f2 = sign * F[i2 * NO + o]
    f3 = sign * F[i3 * NO + o]
    best = f_ip
    for it in range(12):
        d1 = x2 - x1
        d3 = x2 - x3
        p1 = d1 * (f2 - f3)
        p3 = d3 * (f2 - f1)
        den = p1 - p3
        if den == 0.0:
            break
        xv = x2 - 0.5 * (d1 * p1 - d3 * p3) / den
        if not (lo < xv < hi):
            break
        if it == 0:
            # the parabola's own maximum: nothing to gain unless it exceeds the peak
            # (the polynomial's maximum differs from it by far less than its height)
            a = ((f3 - f2) / (x3 - x2) - (f2 - f1) / (x2 - x1)) / (x3 - x1)
            if a >= 0.0:
                break
            bq = (f2 - f1) / (x2 - x1) - a * (x1 + x2)
            top = f1 + (xv - x1) * ((f2 - f1) / (x2 - x1) + a * (xv - x2))
            if top <= peak and bq == bq:
                break
        fv = sign * interp(F, o, lev, xv)
        if fv > best:
            best = fv
        if abs(xv - x2) < 1e-13:
            break
        # keep three points around the best one
        if xv < x2:
            if fv > f2:
                x3, f3 = x2, f2
                x2, f2 = xv, fv
            else:
                x1, f1 = xv, fv
        else:
            if fv > f2:
                x1, f1 = x2, f2
                x2, f2 = xv, fv
            else:
                x3, f3 = xv, fv
    return best
