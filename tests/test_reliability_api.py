"""The Python API on hostile arguments: the package's own errors, naming the argument.

Generated cases: every public function of the vehicle, road, unit and network modules
called with values of the wrong type, non-finite numbers, NaN inside arrays, huge unit
exponents, empty and malformed units, duplicated names and out-of-range counts. Each
call either raises an :class:`inerterlab.errors.InerterlabError` whose one-line message
names the argument, or returns a correct result; never another exception, never a NaN.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from inerterlab.errors import (
    MESSAGE_LIMIT,
    InerterlabError,
    ParameterError,
    check_seed,
    one_line,
    shorten,
)

# a hang guard, not a speed limit: under pytest-xdist a worker may compile the core's
# kernels inside one of these tests (the first of its worker to simulate), 150-250 s of
# CPU on a slow machine
pytestmark = pytest.mark.timeout(900)

_BAD_SCALARS = [None, "1", b"1", True, [1.0], {"a": 1}, math.nan, math.inf, -math.inf, object()]


def _raises_own(fn, *args, name: str | None = None, **kw) -> str:
    with pytest.raises(InerterlabError) as exc:
        fn(*args, **kw)
    msg = str(exc.value)
    assert "\n" not in msg and len(msg) <= MESSAGE_LIMIT
    if name is not None:
        assert name in msg, msg
    return msg


# ---------------------------------------------------------------------------------------
# vehicle files and units


@pytest.mark.parametrize("value", [5, 5.0, None, b"model = 'full'", ["x"], {"model": "full"}])
def test_loads_vehicle_refuses_non_text(value):
    from inerterlab.vehicles.config import loads_vehicle

    _raises_own(loads_vehicle, value, name="text")


@pytest.mark.parametrize("value", [5, None, 1.5, b"", ""])
def test_load_vehicle_refuses_non_paths(value):
    from inerterlab.vehicles.config import load_vehicle

    with pytest.raises(InerterlabError):
        load_vehicle(value)


_BAD_UNITS = [
    "/",
    "//",
    "kg/",
    "/s",
    "",
    "  ",
    "m/s/s",
    "km^200/km^200",
    "km^200",
    "m^-400",
    "Gm^6 Gm^6 Gm^6 Gm^6",  # every exponent allowed, the factor not (1e216)
    "um^6 um^6 um^6 um^6 um^6 um^6",
    "kg^99999999999999999999",
    "teleport",
    "N s/m^",
    5,
    None,
]


@pytest.mark.parametrize("unit", _BAD_UNITS)
def test_parse_unit_refuses(unit):
    from inerterlab.vehicles.config import parse_unit

    _raises_own(parse_unit, unit, name="unit")


@pytest.mark.parametrize(
    "unit,factor,dims",
    [("kg", 1.0, (1, 0, 0)), ("1/s", 1.0, (0, 0, -1)), ("N s/m", 1.0, (1, 0, -1)),
     ("kN/m", 1e3, (1, 0, -2)), ("g", 1e-3, (1, 0, 0)), ("t m^2", 1e3, (1, 2, 0))],
)  # fmt: skip
def test_parse_unit_still_reads_units(unit, factor, dims):
    from inerterlab.vehicles.config import parse_unit

    f, d = parse_unit(unit)
    assert f == pytest.approx(factor) and d == dims


_QUANTITIES = {
    "mass": ["1e-320 kg", "1e300 kg", "1e-9 g", "1e20 t", "1200 kg km^200/km^200", "1e999 kg"],
    "stiffness": ["1e-320 N/m", "1e300 kN/m", "1e-9 N/m"],
    "damping": ["1e-320 N s/m", "1e30 N s/m"],
    "length": ["1e-320 m", "1e9 km", "-1e300 m"],
    "inertia": ["1e-320 kg m^2", "1e30 kg m^2"],
}


@pytest.mark.parametrize(
    "dimension,value", [(d, v) for d, vs in _QUANTITIES.items() for v in vs]
)
def test_parse_quantity_outside_the_physical_range(dimension, value):
    from inerterlab.vehicles.config import parse_quantity

    _raises_own(parse_quantity, value, dimension)


@pytest.mark.parametrize("dimension", ["mass", "stiffness", "damping", "length", "inertia"])
def test_parse_quantity_accepts_zero_and_ordinary_values(dimension):
    from inerterlab.errors import PHYSICAL_RANGES
    from inerterlab.vehicles.config import parse_quantity

    lo, hi, unit = PHYSICAL_RANGES[dimension]
    unit = unit.replace("N s/m", "N s/m")
    assert parse_quantity(f"0 {unit}", dimension) == 0.0
    for x in (lo, math.sqrt(lo * hi), hi):
        assert parse_quantity({"value": x, "unit": unit}, dimension) == pytest.approx(x)


@pytest.mark.parametrize(
    "key,value",
    [("sprung_mass", '"1200 kg km^200/km^200"'), ("sprung_mass", '"1e-320 kg"'),
     ("sprung_mass", '"1e300 kg"'), ("pitch_inertia", '"1e-320 kg m^2"'),
     ("cg_to_front", '"1e-320 m"'), ("roll_inertia", '"1e30 kg m^2"')],
)  # fmt: skip
def test_vehicle_file_values_outside_the_physical_range(key, value):
    from inerterlab.vehicles.config import example_vehicle_path, loads_vehicle

    text = example_vehicle_path().read_text(encoding="utf-8")
    lines = [f"{key} = {value}" if ln.startswith(f"{key} =") else ln for ln in text.splitlines()]
    assert any(ln.startswith(f"{key} = {value}") for ln in lines)
    msg = _raises_own(loads_vehicle, "\n".join(lines), "car.toml", name=key)
    assert "car.toml, line" in msg


# ---------------------------------------------------------------------------------------
# road profiles


def _profile(n=4000, dx=0.05, seed=1):
    from inerterlab.vehicles.roads import generate_tracks, road_spectrum

    x, z, _ = generate_tracks(road_spectrum("C"), length=n * dx, step=dx, seed=seed)
    return x, z


@pytest.mark.parametrize("fname", ["fit_iso8608", "iri"])
@pytest.mark.parametrize("which", ["x", "z"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("where", [0, 7, -1])
def test_profile_functions_refuse_non_finite_samples(fname, which, bad, where):
    from inerterlab.vehicles import roads

    x, z = _profile()
    arr = x if which == "x" else z
    arr[where] = bad
    _raises_own(getattr(roads, fname), x, z, name=which)


@pytest.mark.parametrize("fname", ["fit_iso8608", "iri"])
@pytest.mark.parametrize(
    "args",
    [([1.0, 2.0], [1.0]), ("abc", "def"), (None, None), ([[1.0]], [[1.0]]), ([], [])],
)
def test_profile_functions_refuse_bad_arrays(fname, args):
    from inerterlab.vehicles import roads

    _raises_own(getattr(roads, fname), *args)


@pytest.mark.parametrize(
    "kw", [{"band": (2.0, 1.0)}, {"band": (math.nan, 1.0)}, {"band": "x"}, {"segment": 0.0},
           {"segment": 1e-9}, {"waviness": -2.0}, {"waviness": math.nan}],
)  # fmt: skip
def test_fit_iso8608_refuses_bad_settings(kw):
    from inerterlab.vehicles.roads import fit_iso8608

    x, z = _profile()
    _raises_own(fit_iso8608, x, z, **kw, name=next(iter(kw)))


def test_profile_functions_still_work():
    from inerterlab.vehicles.roads import fit_iso8608, iri

    x, z = _profile(20000)
    fit = fit_iso8608(x, z)
    assert fit["road_class"] in "BCD" and math.isfinite(fit["gd_n0"])
    assert 0.5 < iri(x, z) < 20


@pytest.mark.parametrize(
    "kw,name",
    [({"seed": -1}, "seed"), ({"seed": 2**32}, "seed"), ({"seed": 1.5}, "seed"),
     ({"seed": "1"}, "seed"), ({"step": 1e9}, "step"), ({"length": 0.0}, "length"),
     ({"length": math.inf}, "length"), ({"step": math.nan}, "step")],
)  # fmt: skip
def test_generate_tracks_refuses(kw, name):
    from inerterlab.vehicles.roads import generate_tracks, road_spectrum

    args = {"length": 100.0, "step": 0.05, **kw}
    _raises_own(generate_tracks, road_spectrum("C"), **args, name=name)


def test_generate_tracks_refuses_a_non_spectrum():
    from inerterlab.vehicles.roads import generate_tracks

    _raises_own(generate_tracks, "C", length=100.0, name="spectrum")


# ---------------------------------------------------------------------------------------
# networks


@pytest.mark.parametrize("value", [0, -3, 101, 10**9, 1.5, True, "8", None])
def test_optimize_network_refuses_bad_starts(value):
    from inerterlab.network_design import optimize_network

    _raises_own(optimize_network, "k | c", starts=value, name="starts")


@pytest.mark.parametrize("value", [-1, 2**32, 1.0, "0", None])
def test_optimize_network_refuses_bad_seeds(value):
    from inerterlab.network_design import optimize_network

    _raises_own(optimize_network, "k | c", seed=value, name="seed")


@pytest.mark.parametrize("objective", ["body_acc", "tyre_deflection", "suspension_deflection"])
def test_optimize_network_refuses_unused_weights(objective):
    from inerterlab.network_design import optimize_network

    _raises_own(optimize_network, "k | c", objective, weights={"body_acc": 1.0}, name="weight")


@pytest.mark.parametrize("what", ["fixed", "bounds", "weights"])
def test_duplicated_assignments_are_refused(what):
    from inerterlab.network_design import optimize_network

    item = {"fixed": "k=50000", "bounds": "c=10:1000", "weights": "body_acc=1"}[what]
    kw = {what: [item, item]}
    objective = "weighted" if what == "weights" else "body_acc"
    msg = _raises_own(optimize_network, "k | c", objective, **kw)
    assert "twice" in msg


@pytest.mark.parametrize("name", ["k", "c", "b"])
@pytest.mark.parametrize("value", [1e-320, 1e-30, 5e-324, 1e300, 1e30])
def test_network_parameters_outside_the_physical_range(name, value):
    from inerterlab.suspension.network_linear import network_h2

    params = {"k": 5e4, "c": 3e3, "b": 100.0, name: value}
    _raises_own(network_h2, "k | c | b", params, name=name)


@pytest.mark.parametrize(
    "car", [{"sprung_mass": 1e-320}, {"unsprung_mass": 1e300}, {"tyre_stiffness": 1e-320},
            {"tyre_damping": 1e-320}],
)  # fmt: skip
def test_network_car_outside_the_physical_range(car):
    from inerterlab.suspension.network_linear import network_h2

    _raises_own(network_h2, "k | c", {"k": 5e4, "c": 3e3}, **car, name=next(iter(car)))


@pytest.mark.parametrize(
    "budget",
    [(d, i, s) for d in range(5) for i in range(5) for s in range(5) if d + i + s <= 5],
)
def test_count_layouts_is_exact(budget):
    """The count made without building agrees with the enumeration (without merging)."""
    from inerterlab.network_design import count_layouts
    from inerterlab.networks import _trees, enumerate_networks

    d, i, s = budget
    n = count_layouts(d, i, s)
    listed = enumerate_networks(d, i, s, merge_equivalent=False, max_layouts=max(1, n["candidates"]))
    assert n["candidates"] == len(listed)
    trees = sum(
        len(_trees(k, c, b))
        for k in range(s + 1)
        for c in range(d + 1)
        for b in range(i + 1)
        if k + c + b
    )
    assert n["trees"] == trees


def test_count_layouts_of_the_largest_budget_is_immediate():
    import time

    from inerterlab.network_design import count_layouts

    t0 = time.perf_counter()
    n = count_layouts(4, 4, 4)
    assert time.perf_counter() - t0 < 5.0
    assert n["candidates"] > 10**6 and n["trees"] > n["candidates"]


@pytest.mark.parametrize("value", [-1, 5, 1.5, True, "2", None])
def test_count_layouts_refuses_bad_budgets(value):
    from inerterlab.network_design import count_layouts

    _raises_own(count_layouts, value, 1, 1, name="dampers")


# ---------------------------------------------------------------------------------------
# vehicle optimisation


@pytest.mark.parametrize("name", ["rear_teleport", "front_dampingg", "", "front_stiffness"])
def test_optimize_vehicle_refuses_bounds_on_unknown_or_unused_names(name):
    from inerterlab.vehicles.design import optimize_vehicle

    msg = _raises_own(optimize_vehicle, bounds={name: (1.0, 2.0)}, name="bound")
    assert "front_damping, rear_damping" in msg


@pytest.mark.parametrize(
    "kw,name",
    [({"starts": 0}, "starts"), ({"starts": -3}, "starts"), ({"starts": 10**9}, "starts"),
     ({"seed": -1}, "seed"), ({"seed": 2**32}, "seed"),
     ({"parameters": ("front_damping", "front_damping")}, "parameters")],
)  # fmt: skip
def test_optimize_vehicle_refuses_bad_settings(kw, name):
    from inerterlab.vehicles.design import optimize_vehicle

    _raises_own(optimize_vehicle, **kw, name=name)


# ---------------------------------------------------------------------------------------
# the error helpers themselves


@pytest.mark.parametrize("value", [-1, 2**32, 2**64, 1.0, "1", True, None, math.nan])
def test_check_seed_refuses(value):
    _raises_own(check_seed, "seed", value, name="seed")


@pytest.mark.parametrize("value", [0, 1, 2**32 - 1, np.int64(7), np.uint32(2**32 - 1)])
def test_check_seed_accepts(value):
    assert check_seed("seed", value) == int(value)


@pytest.mark.parametrize("n", [0, 1, 79, 80, 81, 1000, 100_000])
def test_parameter_error_shortens_long_values(n):
    e = ParameterError("network", "k" * n, "a network text")
    msg = str(e)
    assert len(msg) <= MESSAGE_LIMIT and "\n" not in msg
    assert msg.startswith("invalid network=") and msg.endswith("a network text")
    assert ("…" in msg) == (n + 2 > 80)


@pytest.mark.parametrize(
    "text",
    ["a\nb", "line one\r\nline two\n\n   line three", "x" * 10_000, "\n".join(["y" * 50] * 400),
     "tab\there", ""],
)  # fmt: skip
def test_messages_are_one_short_line(text):
    for msg in (one_line(text), str(InerterlabError(text))):
        assert "\n" not in msg and "\r" not in msg and len(msg) <= MESSAGE_LIMIT


def test_shorten_keeps_both_ends():
    s = shorten("start-" + "x" * 500 + "-end", 40)
    assert len(s) == 40 and s.startswith("start-") and s.endswith("-end")
