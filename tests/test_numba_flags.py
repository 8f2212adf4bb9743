"""numba compiles a kernel's not-yet-compiled callees with the kernel's fastmath and
error-model flags, and caches those copies. A vehicle kernel compiled with ``fastmath``
before ``slider_state_derivative`` had been compiled once made every later caller (the
reproduction's force-law comparison) get a contracted copy, 9e-8 of the peak off. So
``fastmath`` is allowed only on leaf kernels, which call no other compiled function."""

from __future__ import annotations

import importlib
import pkgutil

from numba.core.registry import CPUDispatcher

import inerterlab


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


def test_fastmath_kernels_are_leaves():
    found = []
    for name, disp in _dispatchers().items():
        if not disp.targetoptions.get("fastmath"):
            continue
        found.append(name)
        glb = disp.py_func.__globals__
        callees = [g for g in disp.py_func.__code__.co_names if isinstance(glb.get(g), CPUDispatcher)]
        assert not callees, f"{name} is compiled with fastmath and calls compiled {callees}"
    assert "inerterlab.vehicles.nonlinear._linear_part" in found, found
