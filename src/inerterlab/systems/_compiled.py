"""The right-hand side of a core system compiled for its structure.

One source, :func:`._kernel.evaluate`, serves every system: it reads the structure
(node types, element kinds, topology) from the integer table ``itab`` and the
parameters from the float table ``ftab``. It is compiled in two tiers, both with the
signature :data:`RHS_SIGNATURE`:

* **generic**: ``itab`` is data: :func:`._kernel.evaluate` itself, the evaluation every
  other caller uses too. Compiled once for every system (cached on disk with the other
  kernels).
* **per structure**: the same statements with ``itab`` bound to the structure's table,
  a compile-time constant (a module generated for the structure,
  :func:`_structure_module`, whose function begins ``itab = ITAB``): the compiler
  resolves every table look-up, drops the branches of the node types and element
  kinds the system does not have and unrolls its short loops; ``ftab`` (masses,
  stiffnesses, ...) stays data, so a parameter sweep or a fit reuses the code. The
  module is named by a hash of ``itab`` and of the package's source
  (:func:`inerterlab._numba_cache.package_source_stamp`), and numba caches its machine
  code next to it: a structure is compiled once per package version (5-6 s of CPU
  for the ``afw`` quarter car with its ride observers), and every later process loads
  it (about 10 ms).

The integrator (:mod:`._integrate`) takes the right-hand side as a first-class function
(a function pointer of :data:`RHS_SIGNATURE`), so it is compiled once for every
structure and either tier. :func:`rhs_for` picks the tier: the per-structure code once
it is on disk, or once the integrations of a structure in a process have taken
:data:`SPECIALISE_AFTER_SECONDS` of CPU time (a sweep, a fit, a long study: the
compilation then pays for itself; a test or a report that runs many structures a few
times each does not pay for theirs), the generic code before. Both evaluate the same
arithmetic in the same order: results agree to the last bit.

Processes that share the cache (a sweep's or a reproduction's workers) compile a
structure once between them: the first to need it claims it with a marker file
(``s_<key>.compiling``, created exclusively, holding its host and process id); the others
go on with the generic code (``auto``) or wait for it (``always``) until it is on disk,
then load it. A marker whose process has ended, or older than
:data:`COMPILING_STALE_SECONDS`, is taken over.
"""

from __future__ import annotations

import ast
import dis
import hashlib
import importlib.util
import inspect
import math
import os
import socket
import sys
import textwrap
import threading
import time
import warnings
from pathlib import Path

import numpy as np
from numba import types
from numba.core.errors import NumbaExperimentalFeatureWarning
from numba.core.typing.typeof import typeof_impl
from numba.experimental.function_type import _get_wrapper_address

from .._numba_cache import FIRST_CLASS_WARNING, package_source_stamp
from . import _kernel
from ._kernel import DENSE_IMPORTS, I_NOB, I_NS, dense_source, evaluate, work_size

# the integrator takes the right-hand side as a first-class function, a feature numba
# marks experimental with a warning wherever it unifies such a function's type while
# compiling (the integrator's first compilation after an install: four times, which a
# command printed as "inerterlab: warning: NumbaExperimentalFeatureWarning: ..."). The
# choice is ours and recorded (docs/decisions.md); the warning leaves a user nothing to
# act on. (The command line sets the same filter inside its own record of warnings.)
warnings.filterwarnings(
    "ignore", message=FIRST_CLASS_WARNING, category=NumbaExperimentalFeatureWarning
)

_ro_i = types.Array(types.int64, 1, "C", readonly=True)
_ro_f = types.Array(types.float64, 1, "C", readonly=True)
_f1 = types.float64[::1]
#: (t, x, road, itab, ftab, W, dx, imp) -> ok: the contract of :func:`._kernel.evaluate`
RHS_SIGNATURE = types.boolean(types.float64, _f1, _f1, _ro_i, _ro_f, _f1, _f1, _f1)
RHS_TYPE = types.FunctionType(RHS_SIGNATURE)
#: a structure gets its own compiled code once its integrations in a process have taken
#: this much CPU time [s] with the generic code; or at its first integration when an
#: earlier process compiled it (then it only loads). Measured (docs/decisions.md, stop
#: 61): a quarter car's structure compiles in 5-6 s of CPU once the generic code is
#: compiled, a full car's in about 29 s; the structure's own code takes about a quarter
#: less time on the ``afw`` car's ride run, a third of the time on the full car. So a
#: quarter car that has run 10 s with the generic code would have saved about 2.5 s,
#: half its compilation, and the compiled code serves every later process too; a study
#: shorter than that is not held up by a compilation longer than itself. (It was 2 s,
#: set when a structure compiled in 3-6 s: a sweep of 3000 points on two workers then
#: compiled the same structure in both, 11.8 s where 6.5 s do without.)
SPECIALISE_AFTER_SECONDS = 10.0
#: ``INERTERLAB_SPECIALISE``: ``auto`` (default, as above), ``always`` or ``never``
_MODE_ENV = "INERTERLAB_SPECIALISE"
#: a claim to compile a structure (its marker file) older than this [s] is abandoned
#: (the largest structures compile in about 30 s of CPU; a loaded machine takes longer)
COMPILING_STALE_SECONDS = 600.0
#: how often [s] a process that waits for another's compilation looks for it (``always``)
_WAIT_POLL_SECONDS = 0.2
#: ... and how long [s] it waits before it compiles the structure itself (a full car
#: compiles in about 30 s of CPU)
WAIT_AT_MOST_SECONDS = 120.0


class CompiledRhs(types.WrapperAddressProtocol):
    """A compiled right-hand side of :data:`RHS_SIGNATURE`, passed to the integrator as
    a function pointer. ``specialised``: compiled for one structure."""

    __slots__ = ("_address", "specialised", "_keep")

    def __init__(self, dispatcher, specialised: bool):
        # by the argument types, as a compiled caller's call compiles it: numba files a
        # cached compilation under the signature it was asked for, and a signature with
        # its return type is another entry than the same arguments without it (the one
        # evaluation, reached both ways, was compiled again by a second process)
        dispatcher.compile(RHS_SIGNATURE.args)
        self._keep = dispatcher
        self._address = _get_wrapper_address(dispatcher, RHS_SIGNATURE)
        self.specialised = specialised

    def __wrapper_address__(self) -> int:
        return self._address

    def signature(self):
        return RHS_SIGNATURE

    def __repr__(self) -> str:
        return f"<CompiledRhs {'per structure' if self.specialised else 'generic'}>"


@typeof_impl.register(CompiledRhs)
def _typeof_rhs(val, c):  # one type object: no signature parsing per call
    return RHS_TYPE


_lock = threading.Lock()
_generic: list = []
_specialised: dict[bytes, CompiledRhs] = {}
_spent: dict[bytes, float] = {}  # CPU time [s] of integrations with the generic code
_seen: set[bytes] = set()


def generic() -> CompiledRhs:
    """The right-hand side for any structure (``itab`` read as data)."""
    if not _generic:
        with _lock:
            if not _generic:
                _generic.append(CompiledRhs(evaluate, False))
    return _generic[0]


def _cache_dir() -> Path:
    base = os.environ.get("NUMBA_CACHE_DIR")
    root = Path(base) if base else Path.home() / ".cache" / "inerterlab-numba"
    return root / "structures"


def structure_key(itab: np.ndarray) -> str:
    """Hash of a structure table and of the package source: the name of its compiled
    module."""
    h = hashlib.sha256(np.ascontiguousarray(itab, dtype=np.int64).tobytes())
    h.update(package_source_stamp().encode())
    return h.hexdigest()[:24]


_TEMPLATE = '''"""The right-hand side of one core-system structure (generated by
inerterlab.systems._compiled: the statements of inerterlab.systems._kernel.evaluate, the
structure table below a compile-time constant, the element laws those of its kinds)."""
import numba as nb
import numpy as np

from inerterlab.systems._kernel import {names}


@nb.njit(cache=True, inline="always")
{law}


#: package source {stamp}
ITAB = np.array({itab}, dtype=np.int64)
ITAB.setflags(write=False)


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def rhs(t, x, road, itab, ftab, W, dx, imp):
    itab = ITAB  # the structure: every look-up in it a constant
{body}
'''


_TEMPLATE_DENSE = '''"""The right-hand side of one core-system structure with its mass matrix factored
beforehand (generated by inerterlab.systems._compiled from
inerterlab.systems._kernel.dense_source: the statements of its evaluate written out;
an impulse flow goes to the generic evaluate)."""
import numba as nb
import numpy as np

from inerterlab.systems._kernel import evaluate
{imports}
#: package source {stamp}
ITAB = np.array({itab}, dtype=np.int64)
ITAB.setflags(write=False)


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def rhs(t, x, road, itab, ftab, W, dx, imp):
{body}'''


def _codes_tested(test, names: dict) -> set[int] | None:
    """The element codes an ``if`` test of :func:`._kernel._element_law` compares
    ``code`` with (``code == X`` or several joined by ``or``); None for another test."""
    if isinstance(test, ast.BoolOp) and isinstance(test.op, ast.Or):
        parts = [_codes_tested(v, names) for v in test.values]
        return None if any(p is None for p in parts) else set().union(*parts)
    if (
        isinstance(test, ast.Compare)
        and isinstance(test.left, ast.Name)
        and test.left.id == "code"
        and len(test.ops) == 1
        and isinstance(test.ops[0], ast.Eq)
        and isinstance(test.comparators[0], ast.Name)
    ):
        return {int(names[test.comparators[0].id])}
    return None


def _law_source(itab) -> tuple[str, set[str]]:
    """:func:`._kernel._element_law` for the element kinds of the structure ``itab``
    alone: its branches for kinds the structure lacks left out, and the flywheel row's
    law (the last statement) too where it has none (``return 0.0, 0.0`` there, never
    reached). Every branch kept is the law's own statements: the same arithmetic. The
    compiler no longer types and lowers the laws the structure cannot reach (a
    structure of springs, dampers and inerters compiles in 2.7-3.0 s instead of 5.2-5.7
    s).
    Returns the source and the module-level names it reads."""
    fn = _kernel._element_law.py_func
    g = fn.__globals__
    tree = ast.parse(textwrap.dedent(inspect.getsource(fn)))
    f = tree.body[0]
    f.decorator_list = []
    eo, ne = int(itab[_kernel.I_ELEM]), int(itab[_kernel.I_NE])
    present = {int(itab[eo + _kernel.ELEM_W * e]) for e in range(ne)}
    named = set()
    body = []
    for st in f.body:
        codes = _codes_tested(st.test, g) if isinstance(st, ast.If) else None
        if codes is not None:
            named |= codes
            if not codes & present:
                continue
        body.append(st)
    if isinstance(body[-1], ast.Return) and present <= named:
        body[-1] = ast.parse("return 0.0, 0.0").body[0]
    f.body = body
    text = ast.unparse(f)
    read = {n.id for n in ast.walk(f) if isinstance(n, ast.Name) and n.id in g}
    return text, read


def _evaluate_source(itab) -> str:
    """The module of a structure (:data:`_TEMPLATE`): :func:`._kernel.evaluate`'s
    statements (its source after the docstring) as ``rhs``, ``itab`` bound to the
    structure's table first, with the import of every module-level name they read.
    (Inlining evaluate into a function that passes the table, as numba's
    ``inline="always"`` does, gave the same machine code and took twice as long to
    compile.)"""
    fn = evaluate.py_func
    src = textwrap.dedent(inspect.getsource(fn))
    body = ast.parse(src).body[0].body
    if isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]  # the docstring
    lines = src.splitlines()[body[0].lineno - 1 :]
    read = {i.argval for i in dis.get_instructions(fn) if i.opname == "LOAD_GLOBAL"}
    law, law_reads = _law_source(itab)  # the module's own _element_law
    read = (read - {"_element_law"}) | law_reads
    names = sorted(n for n in read if n in fn.__globals__)  # not the builtins
    return _TEMPLATE.format(
        names=", ".join(names), stamp=package_source_stamp(), itab=list(map(int, itab)),
        body="\n".join(lines), law=law,
    )  # fmt: skip


#: appended to a structure's module: its right-hand side and outputs in the form the
#: harmonic balance calls, ``f(t, x, road, itab, ftab, out) -> bool`` with the work array
#: in ``out`` past the derivatives (:func:`inerterlab.frequency.quarter_car.buffered_rhs`,
#: the same arithmetic as the generic tier's there); compiled only when first used
_FIRST_ORDER = """

from inerterlab.systems import _kernel

FO_N = {n}  # states
FO_W = {w}  # the evaluation's work array


@nb.njit(cache=True)
def first_order_rhs(t, x, road, itab, ftab, out):
    if out.size < FO_N + FO_W:
        return _kernel.rhs(t, x, road, itab, ftab, out)
    return _first_order_rhs(float(t), x, road, itab, ftab, out)


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _first_order_rhs(t, x, road, itab, ftab, out):
    W = out[FO_N : FO_N + FO_W]
    dx = out[:FO_N]
    ok = rhs(t, x, road, _kernel.readonly(itab), _kernel.readonly(ftab), W, dx, out[:0])
    if itab[_kernel.I_NOB] > 0:
        _kernel.observe(_kernel.readonly(itab), _kernel.readonly(ftab), W, x, dx, np.bool_(False))
    return ok


@nb.njit(cache=True)
def first_order_outputs(t, x, road, itab, ftab, out):
    if out.size < FO_N + FO_W:
        return _kernel.outputs(t, x, road, itab, ftab, out)
    return _first_order_outputs(float(t), x, road, itab, ftab, out)


@nb.njit(cache=True, error_model="numpy", _nrt=False)
def _first_order_outputs(t, x, road, itab, ftab, out):
    return rhs(t, x, road, _kernel.readonly(itab), _kernel.readonly(ftab), out[:FO_W],
               out[FO_W : FO_W + FO_N], out[:0])
"""


def _structure_text(itab: np.ndarray) -> str:
    """The source of the module of this structure: :func:`._kernel.evaluate`'s statements
    with the structure table a constant (:func:`_evaluate_source`), or, for tables with
    the mass matrix factored beforehand (:func:`._kernel.dense_tables`), its statements
    written out one by one (:func:`._kernel.dense_source`: the compiler then sees
    straight-line code, where with the table a constant it still walks loops over nodes
    and elements)."""
    values = list(map(int, itab))
    body = dense_source(itab)
    fo = _FIRST_ORDER.format(n=int(itab[I_NS] + itab[I_NOB]), w=work_size(itab))
    if body is None:
        return _evaluate_source(values) + fo
    text = _TEMPLATE_DENSE.format(
        imports=DENSE_IMPORTS, stamp=package_source_stamp(), itab=values, body=body
    )
    return text + fo


def _structure_module(itab: np.ndarray, key: str):
    """Import (writing it first if absent) the module of this structure."""
    path = _cache_dir() / f"s_{key}.py"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        text = _structure_text(itab)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text)
        os.replace(tmp, path)  # atomic: a concurrent process writes the same text
    name = f"inerterlab_structure_{key}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    sys.modules[name] = mod
    return mod


def _alive(host: str, pid: int) -> bool:
    """Whether the process ``pid`` on ``host`` may still run (another host's, or on
    Windows, where signal 0 is not a probe but a console event: assumed; the claim's age
    decides there)."""
    if host != socket.gethostname() or os.name == "nt":
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # it exists (another user's)
        return True
    return True


def _claim(key: str) -> bool:
    """Claim the compilation of structure ``key`` for this process: True unless another
    live process holds a claim younger than :data:`COMPILING_STALE_SECONDS` (its
    marker file); an abandoned claim is taken over."""
    marker = _cache_dir() / f"s_{key}.compiling"
    marker.parent.mkdir(parents=True, exist_ok=True)
    mine = f"{socket.gethostname()} {os.getpid()}"
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
    except FileExistsError:
        try:
            host, pid = marker.read_text().split()
            age = time.time() - marker.stat().st_mtime
            if age < COMPILING_STALE_SECONDS and _alive(host, int(pid)):
                return False
        except FileNotFoundError:  # released meanwhile: compiled, or given up
            return not _done(key).exists()
        except ValueError:  # being written this instant
            return False
        tmp = marker.with_suffix(f".{os.getpid()}.tmp")  # abandoned: take it over
        tmp.write_text(mine)
        os.replace(tmp, marker)
        return True
    with os.fdopen(fd, "w") as f:
        f.write(mine)
    return True


def _release(key: str) -> None:
    """Remove this process's claim on structure ``key`` (if it still holds it)."""
    marker = _cache_dir() / f"s_{key}.compiling"
    try:
        if marker.read_text() == f"{socket.gethostname()} {os.getpid()}":
            marker.unlink()
    except (OSError, ValueError):
        pass


def _done(key: str) -> Path:
    """The file that says structure ``key``'s code is compiled and in numba's cache."""
    return _cache_dir() / f"s_{key}.done"


def specialised(itab: np.ndarray, wait: bool = True) -> CompiledRhs | None:
    """The right-hand side compiled for the structure ``itab``: loaded where this or an
    earlier process compiled it, else compiled here (5-30 s of CPU). Where another
    process is compiling it: wait for that (``wait``, up to
    :data:`WAIT_AT_MOST_SECONDS`, then compile it here too), or return None."""
    k = np.ascontiguousarray(itab, dtype=np.int64).tobytes()
    got = _specialised.get(k)
    if got is None:
        with _lock:
            got = _specialised.get(k)
            if got is None:
                key = structure_key(itab)
                claimed = False
                since = time.monotonic()
                while not _done(key).exists():
                    claimed = _claim(key)
                    if claimed:
                        break
                    if not wait:
                        return None
                    if time.monotonic() - since > WAIT_AT_MOST_SECONDS:
                        break  # compiled here too (the other claim may be a reused pid's)
                    time.sleep(_WAIT_POLL_SECONDS)
                try:
                    got = CompiledRhs(_structure_module(itab, key).rhs, True)
                    _done(key).touch()
                finally:
                    if claimed:
                        _release(key)
                _specialised[k] = got
    return got


def first_order_for(itab: np.ndarray):
    """(rhs, outputs) of the structure ``itab`` in the harmonic balance's form (see
    :data:`_FIRST_ORDER`) from its own compiled code, where :func:`rhs_for` gives that
    tier; else None (the generic tier,
    :func:`inerterlab.frequency.quarter_car.buffered_rhs`, serves)."""
    if not rhs_for(itab).specialised:
        return None
    mod = _structure_module(itab, structure_key(itab))
    return mod.first_order_rhs, mod.first_order_outputs


def rhs_for(itab: np.ndarray, count: bool = True) -> CompiledRhs:
    """The right-hand side to integrate the structure ``itab`` with (see the module
    docstring for the tier). ``count``: this is a run of the structure (an
    integration), not a pass over its samples after one."""
    k = itab.tobytes()
    got = _specialised.get(k)
    if got is not None:
        return got
    mode = os.environ.get(_MODE_ENV, "auto")
    if mode not in ("auto", "always", "never"):
        from ..errors import ParameterError

        raise ParameterError(_MODE_ENV, mode, "auto, always or never (environment variable)")
    if mode == "never":
        return generic()
    try:
        if mode == "always":
            return specialised(itab)
        if _spent.get(k, 0.0) >= SPECIALISE_AFTER_SECONDS:
            # compiled here, or loaded once another process has (meanwhile: generic)
            return specialised(itab, wait=False) or generic()
        if count and k not in _seen:
            _seen.add(k)
            if _done(structure_key(itab)).exists():
                return specialised(itab)
    except OSError:  # no writable cache directory: the generic code serves
        _spent[k] = -math.inf
    return generic()


def record(itab: np.ndarray, seconds: float) -> None:
    """Add the CPU time [s] of an integration of the structure ``itab`` with the
    generic code (what :func:`rhs_for` weighs against compiling it)."""
    k = itab.tobytes()
    _spent[k] = _spent.get(k, 0.0) + seconds
