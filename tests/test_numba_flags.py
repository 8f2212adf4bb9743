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


def test_inherited_flags_reach_no_callee():
    kernels = _dispatchers()
    checked = set()
    for name, disp in kernels.items():
        glb = disp.py_func.__globals__
        callees = {g: glb[g] for g in disp.py_func.__code__.co_names if isinstance(glb.get(g), CPUDispatcher)}
        for option, default in DEFAULTS.items():
            value = disp.targetoptions.get(option, default)
            if not value or value == default:
                continue
            checked.add((name, option))
            for cname, callee in callees.items():
                assert option in callee.targetoptions, (
                    f"{name} sets {option}={value!r} and calls {cname}, which does not set "
                    f"{option}: numba would compile and cache {cname} with it"
                )
    # the kernels with a non-default error model are checked (no kernel sets fastmath)
    assert ("inerterlab.elements.adaptive_flywheel.flywheel_inertance", "error_model") in checked, checked
