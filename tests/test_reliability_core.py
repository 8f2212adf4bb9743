"""Reliability of the model core's own checks (issue #39, part three).

Three classes, each generated rather than listed by hand:

- every numeric parameter of every registered element is held to the physical range of
  its quantity, through the Python API and through ``simulate --network`` (tiny, huge,
  denormal and non-finite values, and the range's own ends accepted);
- :func:`~inerterlab.networks.enumerate_networks` bounds its budget itself, by the same
  count and limit as the command line;
- a sine run whose steps would pass ``max_steps`` is refused up front by a measured
  estimate, which agrees with the real step count (so a refused run would truly have
  failed and an accepted one completes).
"""

from __future__ import annotations

import math
import time

import pytest

from _capped import assert_user_error, run_capped
from inerterlab.cli import main
from inerterlab.elements import ELEMENTS, UNIT_QUANTITY
from inerterlab.errors import MESSAGE_LIMIT, PHYSICAL_RANGES, ParameterError

# a hang guard, not a speed limit: under pytest-xdist a worker may compile the core's
# kernels inside one of these tests (the first of its worker to simulate), 150-250 s of
# CPU on a slow machine
pytestmark = pytest.mark.timeout(900)


# -------------------------------------------------------------------------------------
# physical ranges of element parameters


def _numeric_parameters():
    """(prefix, class, parameter) for every numeric parameter of every element."""
    return [
        (prefix, cls, p)
        for prefix, cls in sorted(ELEMENTS.items())
        for p in cls.PARAMETERS
        if p.choices is None
    ]


_NUMERIC = _numeric_parameters()


def _bad_values(p):
    lo, hi, _ = PHYSICAL_RANGES[p.quantity]
    return {
        "tiny": lo / 1e3,
        "denormal": 1e-320,
        "huge": hi * 1e3,
        "1e300": 1e300,
        "nan": math.nan,
        "inf": math.inf,
    }


_RANGED = [(prefix, cls, p) for prefix, cls, p in _NUMERIC if p.quantity is not None]
_CASES = [
    (prefix, cls, p, kind, x) for prefix, cls, p in _RANGED for kind, x in _bad_values(p).items()
]
_IDS = [f"{prefix}.{p.name}-{kind}" for prefix, _, p, kind, _ in _CASES]


def test_every_numeric_parameter_has_a_physical_range_or_is_dimensionless():
    # a new element in a new unit must name its quantity, or its parameters go unchecked
    for prefix, _, p in _NUMERIC:
        assert p.unit in UNIT_QUANTITY or p.unit == "", (prefix, p.name, p.unit)
        assert p.unit == "" or p.quantity is not None
    assert len(_RANGED) >= 20


def _base(cls, name: str | None = None) -> dict:
    """The example, without the parameter that ``name`` gives another way (a device's
    ratio when its inertance is set)."""
    out = dict(cls.EXAMPLE or {})
    for a, b in cls.ALTERNATIVES.items():
        if name in (a, b):
            out.pop(b if name == a else a, None)
    return out


@pytest.mark.parametrize("prefix, cls, p, kind, x", _CASES, ids=_IDS)
def test_api_refuses_out_of_range_element_parameters(prefix, cls, p, kind, x):
    lo, hi, unit = PHYSICAL_RANGES[p.quantity]
    with pytest.raises(ParameterError) as e:
        cls.from_value(prefix, {**_base(cls, p.name), p.name: x})
    msg = str(e.value)
    assert p.name in msg or (prefix in msg and len(cls.PARAMETERS) == 1), msg
    if math.isfinite(x):
        assert f"{lo:g} to {hi:g} {unit}" in msg, msg
    assert len(msg) <= MESSAGE_LIMIT and "\n" not in msg


@pytest.mark.parametrize("prefix, cls, p", _RANGED, ids=[f"{a}.{c.name}" for a, _, c in _RANGED])
def test_api_accepts_the_ends_of_the_range(prefix, cls, p):
    lo, hi, _ = PHYSICAL_RANGES[p.quantity]
    for x in (lo, hi):
        if p.high < math.inf and x >= p.high:
            continue
        el = cls.from_value(prefix, {**_base(cls, p.name), p.name: x})
        assert getattr(el, p.name) == x
    if p.low == 0 and not p.low_open:  # closed at 0: "left out" stays allowed
        assert getattr(cls.from_value(prefix, {**_base(cls, p.name), p.name: 0.0}), p.name) == 0.0


def _simulate_args(prefix, cls, p, x):
    """``simulate --network`` with the element ``prefix`` in parallel with k and c."""
    net = "k | c" if prefix in ("k", "c") else f"k | c | {prefix}"
    params = {"k": 9e4, "c": 5e3}
    values = {**_base(cls, p.name), p.name: x}
    if len(cls.PARAMETERS) == 1:
        params[prefix] = x
    else:
        params.pop(prefix, None)
        for name, v in values.items():
            params[f"{prefix}.{name}"] = v
    args = ["simulate", "--network", net, "--input", "bump", "--horizon", "0.5"]
    for name, v in params.items():
        args += ["-p", f"{name}={v!r}" if isinstance(v, float) else f"{name}={v}"]
    return args


@pytest.mark.parametrize("prefix, cls, p, kind, x", _CASES, ids=_IDS)
def test_cli_simulate_network_refuses_out_of_range_parameters(capsys, prefix, cls, p, kind, x):
    rc = main(_simulate_args(prefix, cls, p, x))
    out, err = capsys.readouterr()
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == 2 and out == "", (rc, out, err)
    assert len(lines) == 1 and lines[0].startswith("inerterlab: error: "), err
    assert len(lines[0]) <= MESSAGE_LIMIT
    assert p.name in lines[0] or prefix in lines[0], lines[0]
    lo, hi, unit = PHYSICAL_RANGES[p.quantity]
    if math.isfinite(x):  # the range itself; a non-finite value is refused as a non-number
        assert f"{lo:g} to {hi:g} {unit}" in lines[0], lines[0]
    else:
        assert unit in lines[0], lines[0]


def test_cli_simulate_network_in_range_still_runs(capsys):
    # the refusals above are not a blanket refusal: the same command in range runs
    rc = main(["simulate", "--network", "k | c", "-p", "k=90000", "-p", "c=1000",
               "--input", "bump", "--horizon", "0.5", "--json"])  # fmt: skip
    out, err = capsys.readouterr()
    assert rc == 0, err
    assert "body_acc" in out


# -------------------------------------------------------------------------------------
# enumerate_networks bounds its own budget


def test_enumerate_networks_refuses_a_large_budget_before_any_work():
    from inerterlab.network_design import count_layouts
    from inerterlab.networks import enumerate_networks

    n = count_layouts(4, 4, 4)["candidates"]
    t0 = time.perf_counter()
    with pytest.raises(ParameterError) as e:
        enumerate_networks(4, 4, 4)
    assert time.perf_counter() - t0 < 10.0
    msg = str(e.value)
    assert "max_layouts=100" in msg and f"{n:.4g}" in msg, msg
    assert "dampers=4, inerters=4, springs=4" in msg


def test_enumerate_networks_and_the_cli_share_one_rule(capsys):
    from inerterlab.networks import enumerate_networks

    with pytest.raises(ParameterError) as e:
        enumerate_networks(2, 2, 2)  # 556 candidates
    rc = main(["network", "enumerate", "--dampers", "2", "--inerters", "2", "--springs", "2"])
    _, err = capsys.readouterr()
    assert rc == 2
    for text in (str(e.value), err):
        assert "this one has 556" in text, text


def test_max_layouts_is_the_limit_both_ways_in_python():
    from inerterlab.networks import enumerate_networks

    assert len(enumerate_networks(1, 1, 2, max_layouts=19)) == 17  # 19 candidates
    with pytest.raises(ParameterError, match="this one has 19"):
        enumerate_networks(1, 1, 2, max_layouts=18)
    for bad in (0, -1, 1.5, True, "100"):
        with pytest.raises(ParameterError, match="max_layouts"):
            enumerate_networks(1, 1, 0, max_layouts=bad)


def test_raising_max_layouts_in_python_still_bounds_memory():
    from inerterlab.networks import enumerate_networks

    with pytest.raises(ParameterError, match="fits in memory"):
        enumerate_networks(4, 4, 4, max_layouts=10**12)


def test_optimize_all_is_bounded_by_the_same_rule():
    from inerterlab.network_design import optimize_all

    with pytest.raises(ParameterError, match="max_layouts=100"):
        optimize_all(4, 4, 4)


# -------------------------------------------------------------------------------------
# sine runs: the step estimate is measured, so the up-front bound is truthful

_SINE = [
    (susp, rtol, f)
    for susp in ("traditional", "afw", "cfw", "device")
    for rtol in (1e-4, 1e-8)
    for f in (2.0, 10.0)
]


@pytest.mark.parametrize("susp, rtol, f", _SINE, ids=[f"{s}-{r:g}-{f:g}Hz" for s, r, f in _SINE])
def test_sine_step_estimate_is_truthful_both_ways(susp, rtol, f):
    from inerterlab import quarter_car
    from inerterlab.excitation import sine
    from inerterlab.simulate import SimulationOptions, _sine_steps, simulate

    model, ex, T = quarter_car(susp).info["model"], sine(0.05, f), 100.0 / f
    st = simulate(model, ex, T, options=SimulationOptions(rtol=rtol)).stats
    real = st["steps"] + st["rejected"]  # the budget counts every attempt
    est = _sine_steps(model, ex, T, SimulationOptions(rtol=rtol), True)
    assert abs(est / real - 1.0) < 0.1, (est, real)
    # a budget 20 % below the real count is refused before the run, naming the horizon
    low = SimulationOptions(rtol=rtol, max_steps=int(0.8 * real))
    with pytest.raises(ParameterError, match="horizon") as e:
        simulate(model, ex, T, options=low)
    assert "measured over its first 20 periods" in str(e.value)
    # a budget 20 % above it runs to the end
    high = SimulationOptions(rtol=rtol, max_steps=int(1.2 * real) + 10)
    st = simulate(model, ex, T, options=high).stats
    assert st["steps"] + st["rejected"] == real


@pytest.mark.parametrize("suspension", ["traditional", "afw", "device"])
@pytest.mark.parametrize("horizon", ["1e5", "4e5"])
def test_cli_long_sine_is_refused_in_seconds(suspension, horizon):
    res = run_capped(
        ["simulate", "--suspension", suspension, "--input", "sine", "--horizon", horizon],
        seconds=30,
        memory_mb=1500,
    )
    line = assert_user_error(res, "horizon", "max_steps")
    assert res.seconds < 20, res.seconds
    assert "integration steps" in line


_CORE = [(net, f) for net in ("k | c", "k | (c - b)", "k | c | fric") for f in (2.0, 10.0)]


@pytest.mark.parametrize("net, f", _CORE, ids=[f"{n}-{f:g}Hz" for n, f in _CORE])
def test_model_core_sine_estimate_is_truthful_both_ways(net, f):
    from inerterlab.excitation import sine
    from inerterlab.simulate import sine_steps
    from inerterlab.systems import quarter_car

    params = {"k": 9e4, "c": 3e3, "b": 200.0, "fric": 50.0}
    sys_ = quarter_car(net, {n: params[n] for n in params if n in net})
    ex, T = sine(0.05, f), 100.0 / f
    real = sys_.simulate(ex, T).stats["steps"]
    est = sine_steps(lambda t: sys_.simulate(ex, t).stats["steps"], ex, T)
    assert abs(est / real - 1.0) < 0.1, (est, real)
    with pytest.raises(ParameterError, match="measured over its first 20 periods"):
        sys_.simulate(ex, T, max_steps=int(0.8 * real))
    assert sys_.simulate(ex, T, max_steps=int(1.2 * real) + 10).stats["steps"] == real


@pytest.mark.parametrize("horizon", ["1e5", "1e6"])
def test_cli_long_sine_on_the_model_core_is_refused_in_seconds(horizon):
    res = run_capped(
        ["simulate", "--network", "k | c", "-p", "k=90000", "-p", "c=1000",
         "--input", "sine", "--horizon", horizon],
        seconds=30,
        memory_mb=1500,
    )  # fmt: skip
    assert_user_error(res, "horizon", "max_steps")
    assert res.seconds < 20, res.seconds
