"""The core's large kernels are compiled once per process, whatever the path that calls them.

Each further signature of one of them (an argument of another layout, a writable table
where another caller passed a read-only one) compiles the whole of it again: 40-60 s of
CPU each on a slow machine, paid by every user's first run and by the test suite. The
scripts below walk the usual paths in fresh processes and print the number of signatures
each large kernel was compiled for.
"""

import json
import os
import subprocess
import sys

import pytest

WALK = """
import json
import numpy as np
from inerterlab.systems import _integrate, _kernel, quarter_car
from inerterlab.excitation import bump, sine

lin = quarter_car("k | c", {"k": 9e4, "c": 5e3})
lin.simulate(bump(), 1.0)
lin.simulate(sine(0.01, 2.0), 1.0)
quarter_car("afw").simulate(sine(0.01, 2.0), 0.5)
print(json.dumps({
    "integrate": len(_integrate._integrate.signatures),
    "exact_walk": len(_integrate._exact_walk.signatures),
}))
"""

# evaluate is reached only inside rhs, outputs and switches_at: a process that loads those
# from the disk cache never compiles (nor lists) it, so this part runs with a cache of its
# own, empty: every compilation it needs happens in it (about a minute of CPU)
COLD = """
import json
import numpy as np
from inerterlab.systems import _kernel, quarter_car

s = quarter_car("k | c | b", {"k": 9e4, "c": 5e3, "b": 50.0})
s.linear_state_space()  # rhs and outputs on the system's read-only tables
x = np.linspace(0.01, 0.04, s.n_states)
road = np.zeros(_kernel.road_layout_of(s.itab)[1])
dx = np.empty(s.n_states)
it, ft = np.array(s.itab), np.array(s.ftab)  # writable copies, as the harmonic balance holds
_kernel.rhs(0.0, x, road, it, ft, dx)
_kernel.outputs(0.0, x, road, it, ft, np.empty(len(s.output_names)))
_kernel.switches_at(x, road, s.itab, s.ftab, np.empty(_kernel.work_size(s.itab)),
                    np.empty(2 * int(s.itab[_kernel.I_NE])))
counts = {"evaluate": len(_kernel.evaluate.signatures), "rhs": len(_kernel.rhs.signatures)}
# a ride metrics run of a nonlinear car (exact steps in its linear regime with their
# observers, the Wk filter outside the stages, running peaks, events): the integrator's
# helpers, each called with constants at some call sites and with variables at others
from inerterlab.excitation import sine
from inerterlab.simulate import simulate
from inerterlab.systems import _integrate as I

simulate(quarter_car("afw"), sine(0.05, 5.0), 1.0, output="metrics")
for f in (I._advance_run, I._observe_steps, I._observe_sums, I._taylor_peak, I._fz_at,
          I._peak_step, I._exact_walk, _kernel._inertial_after, _kernel.observe):
    counts[f.py_func.__name__] = len(f.signatures)
print(json.dumps(counts))
"""


# the same walk in a second process on the cache the first one filled: numba compiles
# nothing of the package (a compiled function reached both from a compiled caller and
# by an explicit signature was filed under two cache entries, and the second process
# compiled the core's evaluation again: 6 s, and the first-run notice, on every
# user's second run)
WARM = """
import json
from numba.core import event

compiled = []


class Seen(event.Listener):
    def on_start(self, ev):
        fn = ev.data["dispatcher"].py_func
        if fn.__module__.startswith("inerterlab"):
            compiled.append(fn.__module__ + "." + fn.__name__)

    def on_end(self, ev):
        pass


event.register("numba:compile", Seen())
exec(compile(COLD_SOURCE, "cold", "exec"), {})
print(json.dumps({"compiled": compiled}))
"""


def _counts(script, **env):
    out = subprocess.run(
        [sys.executable, "-c", script],
        env={**os.environ, "INERTERLAB_SPECIALISE": "never", **env},
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_integrators_are_compiled_for_one_signature():
    # called from Python: kernels loaded from the cache are listed as well
    assert _counts(WALK) == {"integrate": 1, "exact_walk": 1}


@pytest.mark.slow
def test_right_hand_side_is_compiled_once_for_every_caller(tmp_path):
    counts = _counts(COLD, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    # the thin wrapper rhs is compiled for both kinds of tables; evaluate under it once
    assert {k: counts.pop(k) for k in ("evaluate", "rhs")} == {"evaluate": 1, "rhs": 2}
    # the observers' derivatives are inlined at their callers: never compiled on their own
    assert counts.pop("observe") == 0
    # each helper of the integrator once: a literal argument (0, False, a default) at one
    # call site and a variable at another compiled the whole helper twice (the adaptive
    # driver, 11-14 s of CPU a copy: a cold first run took 116 s, then 91 s)
    assert counts == dict.fromkeys(counts, 1), sorted(counts.items())
    # a second process loads all of it from the cache
    warm = WARM.replace("COLD_SOURCE", repr(COLD))
    assert _counts(warm, NUMBA_CACHE_DIR=str(tmp_path / "numba")) == {"compiled": []}


# the harmonic balance's evaluation, reached from the residual, its Jacobian and the Hill
# matrices with its flags: literal True/False arguments compiled it once per combination
HB = """
import json
from inerterlab.frequency import chapter7_system, frequency_response
from inerterlab.frequency import first_order as F

frequency_response(chapter7_system(0.03), "sihb", fmin=0.5, fmax=1.5, df=0.5, harmonics=3)
print(json.dumps({"_evaluate": len(F._evaluate.signatures)}))
"""


@pytest.mark.slow
def test_harmonic_balance_evaluation_is_compiled_once(tmp_path):
    assert _counts(HB, NUMBA_CACHE_DIR=str(tmp_path / "numba")) == {"_evaluate": 1}
