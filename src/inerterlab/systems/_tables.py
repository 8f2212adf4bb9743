"""The exact steps' tables built in compiled code (the parts of
:mod:`.core`'s table building that loop: a sweep or a fit builds them for every new
parameter point)."""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True)
def taylor_chain(M, S, h, shifts, terms):
    """The chain of :func:`.core._step_tables`: C[k] = S (M h)^k / k! for k below the
    longest family member's count, and each member's count of terms (``shifts``: the
    members' lengths h 2^e; a member stops once two terms in a row, scaled by 2^(e k),
    fall to 1e-18 of its largest; at most ``terms``). The same products in the same
    order as ``P @ (M * (h / (k + 1)))`` in numpy (the same matrix product of the BLAS),
    so the same chain to the last bit."""
    ne = shifts.size
    nr, nq = S.shape
    out = np.empty((terms + 1, nr, nq))
    P = S.copy()
    out[0] = P
    big0 = 0.0
    for v in P.ravel():
        big0 = max(big0, abs(v))
    small = np.zeros(ne, np.int64)
    big = np.full(ne, big0)
    kj = np.zeros(ne, np.int64)
    live = np.ones(ne, np.bool_)
    nlive = ne
    for k in range(terms):
        for i in range(ne):
            if live[i]:
                kj[i] = k + 1
        P = P @ (M * (h / (k + 1)))
        top0 = 0.0
        for v in P.ravel():
            top0 = max(top0, abs(v))
        for i in range(ne):
            if live[i]:
                top = math.ldexp(top0, shifts[i] * (k + 1))
                big[i] = max(big[i], top)
                small[i] = small[i] + 1 if top <= 1e-18 * big[i] else 0
                if small[i] == 2:
                    live[i] = False
                    nlive -= 1
        if nlive == 0:
            break
        out[k + 1] = P
    return out[: kj.max()], kj


@nb.njit(cache=True)
def abs_range(a):
    """(smallest nonzero |a|, largest |a|) over an array (0, 0 where all are zero)."""
    lo, hi = math.inf, 0.0
    for v in a.ravel():
        x = abs(v)
        if x != 0.0:
            lo = min(lo, x)
            hi = max(hi, x)
    return (0.0, 0.0) if hi == 0.0 else (lo, hi)


@nb.njit(cache=True)
def family_rows(C, kj, shifts, js, pw, TR, R):
    """The members of one family of lengths h 2^shifts[i] (rows js[i] of the tables) from
    the chain C of h (:func:`taylor_chain`): their Taylor rows TR[js[i], r, k, :] =
    C[k, r, :] 2^(shifts[i] k) for k below their count kj[i] (a power of two: exact),
    and the signals' rows at a step's inner points, R[p, js[i]] = sum_k pw[p, k] TR[js[i],
    :, k, :] (``pw`` [p, k] the points' powers), each sum from 0 in the order of k. TR is
    zero past a member's count (given so)."""
    nr, nq = C.shape[1], C.shape[2]
    for i in range(js.size):
        j = js[i]
        for k in range(kj[i]):
            e = shifts[i] * k
            for r in range(nr):
                for q in range(nq):
                    TR[j, r, k, q] = math.ldexp(C[k, r, q], e)
        for p in range(R.shape[0]):
            for r in range(nr):
                for q in range(nq):
                    acc = 0.0
                    for k in range(kj[i]):
                        acc += pw[p, k] * TR[j, r, k, q]
                    R[p, j, r, q] = acc
