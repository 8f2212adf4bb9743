"""The core's large kernels are compiled once per process, whatever the path that calls them.

Each further signature of one of them (an argument of another layout, a writable table
where another caller passed a read-only one) compiles the whole of it again: 40-60 s of
CPU each on a slow machine, paid by every user's first run and by the test suite. The
script below walks the usual paths (the linearisation, outputs, a nonlinear integration,
the exact steps of a linear system, the harmonic balance of a core system) in a fresh
process and prints the number of signatures each large kernel was compiled for.
"""

import json
import os
import subprocess
import sys

SCRIPT = """
import json
import numpy as np
from inerterlab.systems import _integrate, _kernel, quarter_car
from inerterlab.excitation import bump, sine
from inerterlab.frequency import frequency_response

lin = quarter_car("k | c", {"k": 9e4, "c": 5e3})
lin.linear_state_space()
out = np.empty(len(lin.output_names))
road = np.zeros(_kernel.road_layout_of(lin.itab)[1])
_kernel.outputs(0.0, np.zeros(lin.n_states), road, lin.itab, lin.ftab, out)
lin.simulate(bump(), 1.0)
lin.simulate(sine(0.01, 2.0), 1.0)
quarter_car("afw").simulate(sine(0.01, 2.0), 0.5)
frequency_response(lin, "sihb", freq_hz=np.array([2.0]), amplitude=1e-3, direction="up")
print(json.dumps({
    "evaluate": len(_kernel.evaluate.signatures),
    "integrate": len(_integrate._integrate.signatures),
    "exact_walk": len(_integrate._exact_walk.signatures),
}))
"""


def test_large_kernels_are_compiled_for_one_signature():
    env = {**os.environ, "INERTERLAB_SPECIALISE": "never"}
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True
    )
    counts = json.loads(out.stdout.strip().splitlines()[-1])
    # the thin wrappers around evaluate (``_kernel.rhs``, ``outputs``) may be compiled
    # for the harmonic balance's writable tables too: they pass them on read-only
    assert counts == {"evaluate": 1, "integrate": 1, "exact_walk": 1}, counts
