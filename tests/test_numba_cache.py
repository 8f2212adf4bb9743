"""The compiled kernels' disk cache cannot go stale after an edit in another module."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import inerterlab

# the core's compiled right-hand side of a spring beside a damper, at a state whose
# displacements and velocities all differ: taking the spring for the damper changes the
# derivative (the kernel alone is compiled, not a whole simulation's, so each cold run
# costs one kernel's compilation)
SCRIPT = """
import json
import numpy as np
from inerterlab.systems import _kernel, quarter_car
s = quarter_car("k | c", {"k": 9e4, "c": 5e3})
x = np.linspace(0.01, 0.04, s.n_states)
road = np.zeros(_kernel.road_layout_of(s.itab)[1])
dx = np.empty(s.n_states)
assert _kernel.rhs(0.0, x, road, s.itab, s.ftab, dx)
print(json.dumps(dx.tolist()))
"""


def _run(root: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(root)}
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def _index_files(pkg: Path) -> dict:
    return {p: p.stat().st_mtime_ns for p in (pkg / "systems" / "__pycache__").glob("*.nbi")}


@pytest.mark.slow
def test_edit_in_a_helper_module_recompiles_the_kernel(tmp_path):
    # the core's compiled right-hand side decides by the element codes defined in
    # elements/_base.py; swapping two codes there (and nowhere else) changes the compiled
    # code it needs. A cache keyed on systems/_kernel.py alone would run the old code on
    # the new tables and take the spring for the damper.
    src = Path(inerterlab.__file__).resolve().parent
    pkg = tmp_path / "inerterlab"
    shutil.copytree(src, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    first = _run(tmp_path)
    cached = _index_files(pkg)
    assert cached, "the kernels were not cached on disk"
    assert _run(tmp_path) == first  # from the cache
    assert _index_files(pkg) == cached  # nothing recompiled
    base = pkg / "elements" / "_base.py"
    text = base.read_text()
    line = "SPRING, DAMPER, INERTER, FRICTION, FLYWHEEL = 0, 1, 2, 3, 4"
    assert line in text
    base.write_text(text.replace(line, "SPRING, DAMPER, INERTER, FRICTION, FLYWHEEL = 1, 0, 2, 3, 4"))
    after = _run(tmp_path)
    assert after == first  # same physics, compiled afresh for the new slots
    assert _index_files(pkg) != cached


EDIT_WHILE_RUNNING = """
import inerterlab._numba_cache as c
before = c.package_source_stamp()
f = c.PACKAGE_ROOT / "elements" / "_base.py"
f.write_text(f.read_text() + "\\n# edited while a process runs\\n")
print(before == c.package_source_stamp(), before != c.package_source_stamp.__wrapped__())
"""


def test_stamp_names_the_source_the_process_imported(tmp_path):
    # a process compiles the code it imported: its machine code must be filed under that
    # source's stamp, not under the stamp of files edited while it runs (later processes
    # with the edited source would load the stale code)
    src = Path(inerterlab.__file__).resolve().parent
    shutil.copytree(src, tmp_path / "inerterlab", ignore=shutil.ignore_patterns("__pycache__"))
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", EDIT_WHILE_RUNNING], env=env,
                         capture_output=True, text=True, check=True)  # fmt: skip
    assert out.stdout.split() == ["True", "True"]
