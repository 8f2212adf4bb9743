"""Speed and accuracy of the compiled network H2 evaluation against the plain route.

Network ``k | (k1 - c - b)`` (two internal states: the deflection of k1 and the
velocity across b, so six states with the car's four), default car of ``inerterlab h2``.
One evaluation is parameters in -> three H2 norms out, assembly included.

- compiled: :func:`inerterlab.suspension.network_linear.h2_squared` (admittance
  polynomials, car polynomials, scaled companion form, Routh test, Lyapunov solve of
  the 21 distinct gramian entries), called once per parameter set from Python, and the
  batch kernel ``h2_squared_many`` (one call for many parameter sets, as the optimiser
  uses it);
- plain: the physical state-space assembled in numpy from node equations of this
  network (written out by hand below, independent of the polynomial route) and
  ``scipy.linalg.solve_continuous_lyapunov``.

Prints medians over repeated blocks, the ratio, and the largest relative difference of
the norms between the two routes over random parameter sets.

Run: NUMBA_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_networks.py
"""

from __future__ import annotations

import os
import statistics
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.linalg import solve_continuous_lyapunov  # noqa: E402

from inerterlab.suspension.network_linear import (  # noqa: E402
    h2_squared,
    h2_squared_many,
    network_quarter_car,
)

MS, MU, KT, CT = 370.0, 25.0, 120e3, 1300.0
NET = "k | (k1 - c - b)"


def plain_h2(k, k1, c, b):
    """Node equations, states [z1, z2, v_u, v_s, x1, v_b]; numpy + scipy Lyapunov.

    z1 = x_u - x_road, z2 = x_s - x_u, x1 the compression of k1, v_b the velocity across
    the inerter. The chain force F = k1 x1 = c v_c = b v_b' (massless nodes between),
    and x1' = (v_u - v_s) - F/c - v_b.
    """
    A = np.zeros((6, 6))
    B = np.zeros(6)
    A[0, 2] = 1.0
    B[0] = -1.0  # z1' = v_u - w
    A[1, 2], A[1, 3] = -1.0, 1.0  # z2' = v_s - v_u
    # unsprung: mu v_u' = -kt z1 - ct (v_u - w) + k z2 - k1 x1
    A[2, 0], A[2, 1], A[2, 2], A[2, 4] = -KT / MU, k / MU, -CT / MU, -k1 / MU
    B[2] = CT / MU
    # sprung: ms v_s' = -k z2 + k1 x1
    A[3, 1], A[3, 4] = -k / MS, k1 / MS
    A[4, 2], A[4, 3], A[4, 4], A[4, 5] = 1.0, -1.0, -k1 / c, -1.0
    A[5, 4] = k1 / b
    P = solve_continuous_lyapunov(A, -np.outer(B, B))
    ca = A[3]
    out = np.array([ca @ P @ ca, P[0, 0], P[1, 1]])
    return np.sqrt(out)


def blocks(fn, n, repeat=7):
    per = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn(n)
        per.append((time.perf_counter() - t0) / n)
    return statistics.median(per)


def main() -> None:
    q = network_quarter_car(NET)
    prog, car = q.program, q.car_vector
    rng = np.random.default_rng(0)
    n = 2000
    P = np.column_stack(
        [
            np.full(n, 50e3),
            np.exp(rng.uniform(np.log(5e3), np.log(5e5), n)),
            np.exp(rng.uniform(np.log(300.0), np.log(2e4), n)),
            np.exp(rng.uniform(np.log(5.0), np.log(800.0), n)),
        ]
    )
    out = np.empty(3)
    many = np.empty((n, 3))
    h2_squared(prog, P[0], car, out)  # compile / load the cache
    h2_squared_many(prog, P[:2], car, many[:2])

    def compiled(m):
        for i in range(m):
            h2_squared(prog, P[i], car, out)
            np.sqrt(out)

    def batch(m):
        h2_squared_many(prog, P[:m], car, many[:m])
        np.sqrt(many[:m])

    def plain(m):
        for i in range(m):
            plain_h2(*P[i])

    t_plain = blocks(plain, 500)
    t_comp = blocks(compiled, 2000)
    t_batch = blocks(batch, 2000)
    print(
        f"network {NET!r}, {len(q.polynomials(dict(k=5e4, k1=3e4, c=3e3, b=1e2))['den']) - 1} states"
    )
    print(
        f"plain (numpy assembly + scipy Lyapunov): {t_plain * 1e6:8.2f} us/eval  "
        f"{1 / t_plain:10.0f} evals/s"
    )
    print(
        f"compiled, one call per parameter set:    {t_comp * 1e6:8.2f} us/eval  "
        f"{1 / t_comp:10.0f} evals/s  ratio {t_plain / t_comp:6.1f}"
    )
    print(
        f"compiled batch (one call, {n} sets):    {t_batch * 1e6:8.2f} us/eval  "
        f"{1 / t_batch:10.0f} evals/s  ratio {t_plain / t_batch:6.1f}"
    )
    # accuracy against the plain route
    h2_squared_many(prog, P, car, many)
    ours = np.sqrt(many)
    ref = np.array([plain_h2(*p) for p in P])
    rel = np.abs(ours - ref) / np.abs(ref)
    for j, name in enumerate(("body_acc", "tyre_deflection", "suspension_deflection")):
        print(
            f"max relative difference {name:22s} {rel[:, j].max():.2e} "
            f"(median {np.median(rel[:, j]):.1e}) over {n} random parameter sets"
        )


if __name__ == "__main__":
    main()
