"""The exact steps' tables built in compiled code (the parts of
:mod:`.core`'s table building that loop: a sweep or a fit builds them for every new
parameter point)."""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True)
def taylor_chain(M, S, h, shifts, terms):
    """The chain of :func:`.core._taylor_family`: C[k] = S (M h)^k / k! for k below the
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
def point_rows(pw, T, kj, out):
    """out[p, j] = sum_k pw[p, k] T[j, :, k, :] over the first kj[j] terms of length j
    (the signals' rows at a step's inner points from its Taylor rows, padded ``T`` [j,
    r, k, q], ``pw`` [p, k] the points' powers): each sum from 0 in the order of k, as
    numpy's ``einsum("pk,rkq->prq")`` adds them, so the same rows to the last bit."""
    np_, nj = out.shape[0], out.shape[1]
    nr, nq = T.shape[1], T.shape[3]
    for p in range(np_):
        for j in range(nj):
            for r in range(nr):
                for q in range(nq):
                    acc = 0.0
                    for k in range(kj[j]):
                        acc += pw[p, k] * T[j, r, k, q]
                    out[p, j, r, q] = acc
