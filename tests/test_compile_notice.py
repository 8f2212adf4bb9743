"""The command line's notice while the package's numerical code compiles.

A first run after an install compiles for one to two minutes and would otherwise say
nothing. The notice is printed once, only on a terminal, and only where numba really
compiles (a run that loads the code from the cache prints nothing)."""

from __future__ import annotations

import io
import subprocess
import sys
import textwrap
from types import SimpleNamespace

from inerterlab.cli import COMPILE_NOTICE, CompileNotice


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _event(module: str):
    fn = SimpleNamespace(__module__=module)
    return SimpleNamespace(data={"dispatcher": SimpleNamespace(py_func=fn)})


def test_once_on_a_terminal_for_the_packages_code():
    out = _Terminal()
    notice = CompileNotice(out)
    notice.on_start(_event("numba.np.arrayobj"))  # numba's own helper: not ours
    assert out.getvalue() == ""
    notice.on_start(_event("inerterlab.systems._integrate"))
    notice.on_start(_event("inerterlab.systems._kernel"))
    notice.on_start(_event("inerterlab_structure_0123"))
    assert out.getvalue() == COMPILE_NOTICE + "\n"


def test_nothing_where_the_output_is_not_a_terminal():
    out = io.StringIO()
    CompileNotice(out).on_start(_event("inerterlab.systems._integrate"))
    assert out.getvalue() == ""


PROBE = """
import io, sys
sys.path.insert(0, {where!r})
from numba.core import event
from inerterlab.cli import CompileNotice

class Terminal(io.StringIO):
    def isatty(self):
        return True

out = Terminal()
notice = CompileNotice(out)
event.register("numba:compile", notice)
import inerterlab_probe
inerterlab_probe.twice(2.0)
event.unregister("numba:compile", notice)
print(repr(out.getvalue()))
"""

MODULE = """
import numba as nb

@nb.njit(cache=True)
def twice(x):
    return 2.0 * x
"""


def test_printed_where_numba_compiles_not_where_it_loads_from_its_cache(tmp_path):
    (tmp_path / "inerterlab_probe.py").write_text(textwrap.dedent(MODULE))
    script = PROBE.format(where=str(tmp_path))

    def run() -> str:
        got = subprocess.run(
            [sys.executable, "-c", script], capture_output=True, text=True, check=True
        )
        return got.stdout.strip().splitlines()[-1]

    assert run() == repr(COMPILE_NOTICE + "\n")  # compiled (and cached)
    assert run() == repr("")  # loaded from numba's cache: no compilation, no notice
