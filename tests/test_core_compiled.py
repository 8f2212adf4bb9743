"""Model core, compilation: the right-hand side compiled for a structure gives the
generic code's results to the last bit; the structure key follows the structure, not
the parameters; exact steps in a linear regime between far-apart samples (level
lengths) against the adaptive steps at a tight tolerance."""

import numpy as np
import pytest

from inerterlab.errors import ParameterError
from inerterlab.excitation import iso8608, sine
from inerterlab.systems import _compiled, _integrate, quarter_car, rig


def _with(rhs, run):
    """``run()`` with every integration on ``rhs``."""
    _integrate.rhs_for = lambda itab, count=True: rhs
    try:
        return run()
    finally:
        _integrate.rhs_for = _compiled.rhs_for


@pytest.mark.parametrize(
    "make, road, T",
    [
        (lambda: quarter_car("afw"), sine(0.05, 5.0), 0.6),  # kinks, exact steps
        (  # friction and a massless velocity node (the balance solved by Newton)
            lambda: rig("k | (c - (k2 | fric))", {"k": 2e4, "c": 800.0, "k2": 5e4, "fric": 40.0}),
            sine(0.01, 3.0),
            0.5,
        ),
        (  # an inerter, no flywheel row: the structure's element law without that branch
            lambda: quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0}),
            iso8608("C", 20.0, seed=2),
            1.0,
        ),
    ],
)
def test_structure_code_equals_generic_code(make, road, T):
    sys_ = make()
    spec = _compiled.specialised(sys_.itab)
    assert spec.specialised and not _compiled.generic().specialised
    a = _with(_compiled.generic(), lambda: sys_.simulate(road, T))
    b = _with(spec, lambda: sys_.simulate(road, T))
    assert np.array_equal(a.states, b.states)
    for k in a.outputs:
        assert np.array_equal(a.outputs[k], b.outputs[k], equal_nan=True), k
    assert a.stats == b.stats


def test_structure_law_has_the_structure_kinds_only():
    """A structure's module carries the element law with the branches of its own
    kinds: no flywheel-row law without such an element (its fall-through never reached),
    the law kept where there is one; the branches kept are the law's own statements."""
    import inspect

    from inerterlab.systems import _kernel

    lin, _ = _compiled._law_source(quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 2e2}).itab)
    fly, _ = _compiled._law_source(quarter_car("afw").itab)
    assert "inertial_law" not in lin and "return (0.0, 0.0)" in lin
    assert "code == INERTER" in lin and "code == TYRE" not in lin
    assert "inertial_law(ftab, o, d, v, x, slot, dx, side)" in fly and "INERTER" not in fly
    whole = inspect.getsource(_kernel._element_law.py_func)
    assert "inertial_law(ftab, o, d, v, x, slot, dx, side)" in whole and "code == TYRE" in whole


def test_structure_key_is_the_structure_not_the_parameters():
    a = quarter_car("k | c", {"k": 2e4, "c": 1e3})
    b = quarter_car("k | c", {"k": 5e4, "c": 3e3})
    c = quarter_car("k | c | b", {"k": 2e4, "c": 1e3, "b": 100.0})
    assert np.array_equal(a.itab, b.itab) and not np.array_equal(a.ftab, b.ftab)
    assert _compiled.structure_key(a.itab) == _compiled.structure_key(b.itab)
    assert _compiled.structure_key(a.itab) != _compiled.structure_key(c.itab)


class _Built:
    """What :func:`_compiled.specialised` returned in the test below (the choice of tier
    is under test there, not the compilation, which the test above checks)."""

    specialised = True


def test_tier_follows_the_setting(monkeypatch):
    sys_ = quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0})
    monkeypatch.setattr(_compiled, "_specialised", {})
    monkeypatch.setattr(_compiled, "_spent", {})
    monkeypatch.setattr(_compiled, "_seen", set())
    monkeypatch.setattr(_compiled, "specialised", lambda itab, wait=True: _Built())
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "never")
    assert not _compiled.rhs_for(sys_.itab).specialised
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "auto")
    _compiled.record(sys_.itab, _compiled.SPECIALISE_AFTER_SECONDS)  # enough work done
    assert _compiled.rhs_for(sys_.itab).specialised
    monkeypatch.setattr(_compiled, "_specialised", {})
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "sometimes")  # not guessed: named
    with pytest.raises(ParameterError, match="INERTERLAB_SPECIALISE.*auto, always or never"):
        _compiled.rhs_for(sys_.itab)


@pytest.mark.parametrize("road", [sine(0.05, 5.0), iso8608("C", 20.0, seed=3)])
def test_level_steps_between_far_samples(road):
    """Samples 0.137 s apart (no step length of the table reaches them): exact steps
    of the level lengths while the flywheel is saturated, Dormand-Prince to each
    sample, within 1e-7 of each state's peak of the adaptive steps at rtol 1e-12."""
    car = quarter_car("afw")
    T = 2.0
    ts = np.arange(0.0, T, 0.137)
    fine = car.simulate(road, T, rtol=1e-12, method="adaptive")
    ref = car.simulate(road, T, rtol=1e-12, method="adaptive", times=ts)
    res = car.simulate(road, T, rtol=1e-8, times=ts)
    if road.name == "sine":
        assert res.stats["exact_steps"] > 100
    peak = np.abs(fine.states).max(axis=0)
    assert (np.abs(res.states - ref.states).max(axis=0) / peak).max() < 1e-7


class _Loaded:
    """A structure's module as :func:`_compiled._structure_module` returns it, its
    right-hand side the generic one (the claims are under test, not the compiler)."""

    def __init__(self):
        from inerterlab.systems._kernel import evaluate

        self.rhs = evaluate


@pytest.fixture
def cache(monkeypatch, tmp_path):
    """A scratch cache directory, the compiled structures of this process forgotten and
    their modules stood in for (see :class:`_Loaded`)."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(_compiled, "_specialised", {})
    monkeypatch.setattr(_compiled, "_spent", {})
    monkeypatch.setattr(_compiled, "_seen", set())
    made = []
    monkeypatch.setattr(_compiled, "_structure_module", lambda itab, key: made.append(key) or _Loaded())
    return tmp_path / "structures", made


def test_a_structure_another_process_compiles_is_waited_for(cache, monkeypatch):
    """A live process's claim: ``auto`` goes on with the generic code, ``specialised``
    without waiting returns None, and once the other process's code is on disk it is
    loaded (not compiled again); the marker is the other process's and stays."""
    import os
    import socket

    root, made = cache
    sys_ = quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0})
    key = _compiled.structure_key(sys_.itab)
    root.mkdir(parents=True)
    marker = root / f"s_{key}.compiling"
    marker.write_text(f"{socket.gethostname()} {os.getppid()}")  # the parent: alive
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "auto")
    _compiled.record(sys_.itab, 2 * _compiled.SPECIALISE_AFTER_SECONDS)
    assert _compiled.specialised(sys_.itab, wait=False) is None
    assert not _compiled.rhs_for(sys_.itab).specialised
    assert made == []
    (root / f"s_{key}.done").touch()  # the other process is done
    assert _compiled.rhs_for(sys_.itab).specialised
    assert made == [key] and marker.exists()


def test_an_abandoned_claim_is_taken_over(cache, monkeypatch):
    """A claim of a process that has ended, and one older than the limit: taken over,
    compiled here, and the marker removed after."""
    import os
    import socket
    import subprocess
    import sys
    import time

    root, made = cache
    root.mkdir(parents=True)
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)  # fmt: skip
    for i, (pid, age) in enumerate([(int(gone.stdout), 0.0), (os.getppid(), 1e4)]):
        net = ["k | c | b", "k | (c - b)"][i]
        sys_ = quarter_car(net, {"k": 9e4, "c": 5e3, "b": 20.0})
        key = _compiled.structure_key(sys_.itab)
        marker = root / f"s_{key}.compiling"
        marker.write_text(f"{socket.gethostname()} {pid}")
        then = time.time() - age
        os.utime(marker, (then, then))
        assert _compiled.specialised(sys_.itab, wait=False).specialised
        assert made[-1] == key and not marker.exists() and (root / f"s_{key}.done").exists()


def test_always_waits_for_another_process(cache, monkeypatch):
    """``always``: the code another process is compiling is waited for, then loaded."""
    import os
    import socket
    import threading
    import time

    root, made = cache
    sys_ = quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0})
    key = _compiled.structure_key(sys_.itab)
    root.mkdir(parents=True)
    (root / f"s_{key}.compiling").write_text(f"{socket.gethostname()} {os.getppid()}")
    monkeypatch.setenv("INERTERLAB_SPECIALISE", "always")
    done = threading.Timer(0.5, (root / f"s_{key}.done").touch)
    t0 = time.monotonic()
    done.start()
    assert _compiled.rhs_for(sys_.itab).specialised
    assert time.monotonic() - t0 >= 0.45 and made == [key]


def test_always_waits_at_most_the_limit(cache, monkeypatch):
    """A claim that stays (its process alive, nothing on disk): ``always`` waits
    :data:`_compiled.WAIT_AT_MOST_SECONDS`, then compiles the structure itself; the
    other process's marker is left as it is."""
    import os
    import socket
    import time

    root, made = cache
    sys_ = quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200.0})
    key = _compiled.structure_key(sys_.itab)
    root.mkdir(parents=True)
    marker = root / f"s_{key}.compiling"
    marker.write_text(f"{socket.gethostname()} {os.getppid()}")
    monkeypatch.setattr(_compiled, "WAIT_AT_MOST_SECONDS", 0.3)
    t0 = time.monotonic()
    assert _compiled.specialised(sys_.itab).specialised
    assert 0.3 <= time.monotonic() - t0 < 5.0
    assert made == [key] and marker.exists() and (root / f"s_{key}.done").exists()
