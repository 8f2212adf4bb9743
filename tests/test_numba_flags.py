"""numba compiles a kernel's not-yet-compiled callees with the kernel's fastmath and
error-model flags (when the callee does not set them itself), and caches those copies.
A vehicle kernel compiled with ``fastmath`` before ``slider_state_derivative`` had been
compiled once made every later caller (the reproduction's force-law comparison) get a
contracted copy, 9e-8 of the peak off. So a kernel with a non-default fastmath or error
model may call only compiled functions that set the same option themselves; results
then never depend on which kernel was compiled first."""

from __future__ import annotations

import importlib
import pkgutil

import numba as nb
from numba.core.registry import CPUDispatcher

import inerterlab

DEFAULTS = {"fastmath": None, "error_model": "python"}


def _dispatchers():
    seen = {}
    for info in pkgutil.walk_packages(inerterlab.__path__, "inerterlab."):
        if info.name.endswith("__main__"):
            continue
        mod = importlib.import_module(info.name)
        for obj in vars(mod).values():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == info.name:
                seen[f"{info.name}.{obj.py_func.__name__}"] = obj
    return seen


def _callees(disp):
    """The compiled functions a kernel calls: its direct callees, and through each one
    it inlines (``inline="always"``: its code is typed and compiled inside the caller,
    under the caller's flags, so no copy of it is cached) that one's callees in turn."""
    found, todo, inlined = {}, [disp], set()
    while todo:
        d = todo.pop()
        glb = d.py_func.__globals__
        for g in d.py_func.__code__.co_names:
            callee = glb.get(g)
            if not isinstance(callee, CPUDispatcher):
                continue
            if callee.targetoptions.get("inline", "never") == "always":
                if id(callee) not in inlined:
                    inlined.add(id(callee))
                    todo.append(callee)
            else:
                found[g] = callee
    return found


def test_inherited_flags_reach_no_callee():
    kernels = _dispatchers()
    checked = set()
    for name, disp in kernels.items():
        if disp.targetoptions.get("inline", "never") == "always":
            continue  # compiled inside its callers, under theirs
        callees = None
        for option, default in DEFAULTS.items():
            value = disp.targetoptions.get(option, default)
            if not value or value == default:
                continue
            checked.add((name, option))
            callees = _callees(disp) if callees is None else callees
            for cname, callee in callees.items():
                assert option in callee.targetoptions, (
                    f"{name} sets {option}={value!r} and calls {cname}, which does not set "
                    f"{option}: numba would compile and cache {cname} with it"
                )
    # the kernels with a non-default error model are checked (no kernel sets fastmath):
    # the core's one evaluation (the integrator's generic tier, the Python callers)
    assert ("inerterlab.systems._kernel.evaluate", "error_model") in checked, checked


@nb.njit
def _leaf(x):
    return x / 2.0


@nb.njit(inline="always")
def _middle(x):
    return _leaf(x)


@nb.njit(error_model="numpy")
def _top(x):
    return _middle(x)


def test_a_callee_reached_through_an_inlined_function_is_checked():
    # _top compiles _middle's code inside itself, and so calls _leaf: the rule reaches it
    assert set(_callees(_top)) == {"_leaf"}
    assert set(_callees(_middle)) == {"_leaf"}
