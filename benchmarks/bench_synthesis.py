"""Time of the positive-real synthesis, and its gap to the enumerated layouts.

For degree 2 and 3, body acceleration, main spring k = 90 kN/m, default car of
``inerterlab h2``:

- the PR search (:func:`inerterlab.synthesis.optimize.synthesize`, its default number
  of differential evolutions, 3 or 6 at degree 3, and their polish), the realisations, and the comparison with the
  enumerated layouts of the default budget whose Y0 has degree <= n
  (:func:`inerterlab.synthesis.design.synthesize_design`, the whole job of
  ``inerterlab network synthesize``);
- baseline, measured in the same run: optimising those layouts one by one
  (:func:`inerterlab.network_design.optimize_network`), the way a designer compares
  layouts without the synthesis. The ratio is PR search time / baseline time.

The first calls compile or load the numba kernels; a warm-up of both routes (degree 1)
comes first and is not timed. Prints the times in seconds, the ratio, the PR optimum and the
gap in percent (positive: the PR optimum is better than the best layout).

The issue's requirement (one objective, 2 cores): degree 2 within 30 s, degree 3 within
5 min, for the whole job; the script says whether each is met.

Run: NUMBA_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_synthesis.py
"""

from __future__ import annotations

import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from inerterlab.synthesis.design import compare_layouts, synthesize_design  # noqa: E402
from inerterlab.synthesis.optimize import synthesize  # noqa: E402

CAR = dict(sprung_mass=370.0, unsprung_mass=25.0, tyre_stiffness=120_000.0, tyre_damping=1300.0)
K = 90_000.0


def main() -> None:
    # warm-up (compile or load the numba kernels of both routes)
    synthesize(1, "body_acc", static_stiffness=K, starts=1)
    compare_layouts(1, "body_acc", K, budget=(1, 1, 2), **CAR)
    for degree in (2, 3):
        t0 = time.perf_counter()
        res = synthesize(degree, "body_acc", static_stiffness=K)
        t_pr = time.perf_counter() - t0
        t0 = time.perf_counter()
        cmp_ = compare_layouts(degree, "body_acc", K, budget=(1, 1, 2), **CAR)
        t_base = time.perf_counter() - t0
        t0 = time.perf_counter()
        job = synthesize_design(degree, "body_acc", static_stiffness=K, **CAR)
        t_job = time.perf_counter() - t0
        best = cmp_["layouts"][0]
        gap = 100.0 * (best["objective"] - res.objective) / best["objective"]
        print(f"degree {degree}, body_acc, k = {K:.0f} N/m")
        print(
            f"  PR search ({len(res.starts)} evolutions + polish):       {t_pr:8.2f} s  "
            f"({res.evaluations} evaluations)"
        )
        print(
            f"  baseline: {len(cmp_['layouts']):2d} enumerated layouts optimised:  {t_base:8.2f} s  "
            f"ratio PR/baseline {t_pr / t_base:6.3f}"
        )
        limit = {2: 30.0, 3: 300.0}[degree]
        print(
            f"  whole job (search, realisations, comparison): {t_job:8.2f} s  "
            f"(required <= {limit:.0f} s: {'met' if t_job <= limit else 'NOT met'})"
        )
        print(
            f"  PR optimum body_acc       {res.objective:.6f} m/s^2 (H2, unit white road velocity)"
        )
        print(f"  best layout {best['network']:<28s} {best['objective']:.6f} m/s^2")
        print(f"  gap                       {gap:.3f} %  (PR optimum better)")
        net = job.get("network")
        if net:
            print(f"  realised as {net['text']} ({net['elements']} elements, {net['method']})")


if __name__ == "__main__":
    main()
