"""numba passes a caller's fastmath and error-model flags on to the callees it compiles
for it, and caches those copies: a kernel compiled with ``fastmath`` before
``slider_state_derivative`` had been compiled once made every later caller (the force-law
comparison of the reproduction) get a contracted copy, 9e-8 of the peak off. So
``fastmath`` is allowed only on leaf kernels, which call no other compiled function."""

from __future__ import annotations

import ast
from pathlib import Path

import inerterlab

SRC = Path(inerterlab.__file__).resolve().parent


def _fastmath_sites():
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and any(k.arg == "fastmath" for k in node.keywords):
                yield path, node


def test_fastmath_only_in_the_leaf_decorator():
    sites = [(p.relative_to(SRC).as_posix(), n.lineno) for p, n in _fastmath_sites()]
    assert [p for p, _ in sites] == ["suspension/_kernels.py"], sites


def test_leaf_kernels_call_no_compiled_function():
    path = SRC / "suspension" / "_kernels.py"
    tree = ast.parse(path.read_text())
    jitted = set()
    leaves = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            names = {ast.unparse(d).split("(")[0] for d in node.decorator_list}
            if names & {"vleaf", "nb.njit", "njit"}:
                jitted.add(node.name)
            if "vleaf" in names:
                leaves[node.name] = node
    assert leaves, "no vleaf kernels found"
    for name, node in leaves.items():
        called = {
            c.func.id for c in ast.walk(node) if isinstance(c, ast.Call) and isinstance(c.func, ast.Name)
        }
        assert not called & jitted, f"{name} (fastmath) calls compiled {called & jitted}"
