"""Command options on hostile values: bounded work, user errors, no silent guesses.

The cases are generated from the command tree itself (every option that takes a seed,
every numeric option of the quarter-car, vehicle and network commands) and from the
classes of failure: budgets too large to enumerate, horizons beyond the step budget,
roads of too few samples, zero amplitudes, duplicated names, unused settings, values
outside the physical range, unknown bound names, cars without static stiffness and
very long user strings. Each command runs in-process with a fast base setting and a
time cap; it must end with exit 0 (a correct result) or exit 2 and one error line of
at most a few hundred characters naming what is wrong, never an internal error.
"""

from __future__ import annotations

import json

import pytest
import typer

from inerterlab.cli import app, main
from inerterlab.errors import MESSAGE_LIMIT

# a hang guard, not a speed limit: under pytest-xdist a worker may compile the core's
# kernels inside one of these tests (the first of its worker to simulate), 150-250 s of
# CPU on a slow machine
pytestmark = pytest.mark.timeout(900)


def _run(capsys, args):
    rc = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


def _lines(err: str) -> list[str]:
    return [
        ln
        for ln in err.splitlines()
        if ln.strip() and not ln.startswith(("inerterlab: warning:", "inerterlab: note:"))
    ]


def _error(err: str) -> str:
    lines = _lines(err)
    assert len(lines) == 1, err
    assert lines[0].startswith("inerterlab: error: "), err
    assert len(lines[0]) <= MESSAGE_LIMIT, len(lines[0])
    return lines[0]


def _ok_or_error(rc: int, err: str) -> None:
    assert "Traceback" not in err and "internal error" not in err, err
    assert rc in (0, 2), (rc, err)
    if rc == 2:
        _error(err)
    else:
        assert not _lines(err), err


def _commands():
    def walk(c, path):
        if hasattr(c, "commands"):
            for n, s in c.commands.items():
                yield from walk(s, [*path, n])
        else:
            yield tuple(path), c

    return list(walk(typer.main.get_command(app), []))


def _options(kinds: tuple[str, ...]):
    for path, c in _commands():
        for p in c.params:
            if p.param_type_name != "option" or p.is_flag:
                continue
            if str(p.type_descriptor.annotation).replace("<class '", "").rstrip("'>") in kinds:
                yield path, p


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A CRG road, a vehicle without static stiffness and an ordinary vehicle file."""
    from inerterlab.vehicles.config import example_vehicle_path

    d = tmp_path_factory.mktemp("options")
    assert main(["vehicle", "generate", "--output", str(d / "road.crg"), "--length", "200", "--track", "2"]) == 0
    text = example_vehicle_path().read_text(encoding="utf-8")
    zero = []
    for ln in text.splitlines():
        if ln.startswith("stiffness =") and ("28 kN/m" in ln or "25 kN/m" in ln):
            ln = 'stiffness = "0 N/m"'
        zero.append(ln)
    (d / "zero.toml").write_text("\n".join(zero) + "\n", encoding="utf-8")
    (d / "car.toml").write_text(text, encoding="utf-8")
    return d


# fast settings of each command; an option given again later overrides its setting here
BASE = {
    ("simulate",): ["--horizon", "1", "--json"],
    ("h2",): ["--json"],
    ("vehicle", "spectral"): ["--points", "100", "--json"],
    ("vehicle", "simulate"): ["--length", "200", "--json"],
    ("vehicle", "monte-carlo"): ["--roads", "2", "--length", "200", "--backend", "serial",
                                 "--quiet", "--json"],  # fmt: skip
    ("vehicle", "optimize"): ["--json"],
    ("vehicle", "road"): ["--profile", "{d}/road.crg", "--json"],
    ("vehicle", "generate"): ["--output", "{d}/out.csv", "--length", "100"],
    ("network", "enumerate"): ["--json"],
    ("network", "h2"): ["--network", "k | c", "-p", "k=50000,c=3000", "--json"],
    ("network", "optimize"): ["--network", "k | c", "--json"],
    ("network", "pareto"): ["--network", "k | c", "--points", "2", "--fix", "k=50000", "--json"],
    ("network", "truth"): ["--layout", "series", "--input", "bump", "--variant", "ideal",
                           "--horizon", "1", "--backend", "serial", "--quiet", "--json"],  # fmt: skip
    ("rig-simulate",): ["--out", "{d}/rig", "--max-duration", "1", "--json"],
}


def _argv(path, files, *extra):
    base = [a.replace("{d}", str(files)) for a in BASE.get(path, [])]
    return [*path, *base, *[str(e) for e in extra]]


# ---------------------------------------------------------------------------------------
# seeds: one definition, every command


_SEEDS = [(path, p.opts[0]) for path, p in _options(("int", "int | None")) if "seed" in p.name]


def test_every_seed_option_shares_one_definition():
    assert len(_SEEDS) >= 7, _SEEDS
    for path, p in _options(("int", "int | None")):
        if "seed" in p.name:
            cb = getattr(p.callback, "__wrapped__", p.callback)
            where = (cb.__module__, cb.__qualname__)
            assert where == ("inerterlab.cli._common", "_seed_callback"), (path, p.opts, where)


@pytest.mark.parametrize("path,opt", _SEEDS, ids=[" ".join(p) + o for p, o in _SEEDS])
@pytest.mark.parametrize("value", ["-1", "-99999999999999999999", "4294967296", str(10**30)])
def test_seed_out_of_range_is_refused(files, capsys, path, opt, value):
    rc, _, err = _run(capsys, _argv(path, files, opt, value))
    assert rc == 2
    line = _error(err)
    assert opt.lstrip("-") in line and "4294967295" in line.replace("4294967294", "4294967295")


# ---------------------------------------------------------------------------------------
# every numeric option of the new surfaces with hostile values


_SURFACES = {p for p in BASE if p != ("rig-simulate",)}
_FLOAT_VALUES = ["nan", "inf", "-inf", "-1e300", "1e300", "-1", "1e-320"]
_INT_VALUES = ["-1", str(10**30)]
_NUMERIC = [
    (path, p.opts[0], v)
    for path, p in _options(("float", "float | None", "int", "int | None"))
    if path in _SURFACES and "seed" not in p.name and p.opts[0] != "--workers"
    for v in (_FLOAT_VALUES if "float" in str(p.type_descriptor.annotation) else _INT_VALUES)
]


@pytest.mark.parametrize(
    "path,opt,value", _NUMERIC, ids=[f"{' '.join(p)} {o}={v}" for p, o, v in _NUMERIC]
)
def test_numeric_options_give_a_result_or_one_line(files, capsys, path, opt, value):
    rc, out, err = _run(capsys, _argv(path, files, opt, value))
    _ok_or_error(rc, err)
    if rc == 0 and "--json" in BASE[path]:
        json.loads(out)  # a result is finite JSON (NaN and infinities are refused)


# ---------------------------------------------------------------------------------------
# bounded work


def _big_budgets():
    from inerterlab.network_design import count_layouts

    out = []
    for d in range(5):
        for i in range(5):
            for s in range(5):
                if count_layouts(d, i, s)["candidates"] > 100:
                    out.append((d, i, s))
    return out


_BUDGETS = _big_budgets()


@pytest.mark.parametrize("command", [["network", "enumerate"], ["network", "optimize", "--all"]])
@pytest.mark.parametrize("budget", _BUDGETS, ids=[f"{d}-{i}-{s}" for d, i, s in _BUDGETS])
def test_large_budgets_are_refused_before_any_work(capsys, command, budget):
    import time

    d, i, s = budget
    t0 = time.perf_counter()
    rc, _, err = _run(capsys, [*command, "--dampers", d, "--inerters", i, "--springs", s])
    assert rc == 2 and time.perf_counter() - t0 < 10.0
    line = _error(err)
    assert f"--dampers {d} --inerters {i} --springs {s}" in line and "--max-layouts=100" in line


def test_raising_max_layouts_still_bounds_memory(capsys):
    rc, _, err = _run(
        capsys,
        ["network", "enumerate", "--dampers", 4, "--inerters", 4, "--springs", 4,
         "--max-layouts", 10**12],
    )  # fmt: skip
    assert rc == 2
    assert "fits in memory" in _error(err)


def test_max_layouts_is_the_limit_both_ways(capsys):
    rc, out, err = _run(capsys, ["network", "enumerate", "--max-layouts", 19, "--json"])
    assert rc == 0 and len(json.loads(out)) == 17  # 19 candidates, 17 after merging
    rc, _, err = _run(capsys, ["network", "enumerate", "--max-layouts", 18])
    assert rc == 2 and "this one has 19" in _error(err)
    rc, _, err = _run(capsys, ["network", "enumerate", "--max-layouts", 0])
    assert rc == 2 and "max-layouts" in _error(err)


_HORIZONS = [("iso8608", h) for h in ("1e5", "1e6", "1e9", "1e300")] + [
    ("sine", h) for h in ("5e5", "1e6", "1e9", "1e300")
]


@pytest.mark.parametrize("input_,horizon", _HORIZONS)
def test_horizons_beyond_the_step_budget_are_refused_up_front(capsys, input_, horizon):
    import time

    t0 = time.perf_counter()
    rc, _, err = _run(capsys, ["simulate", "--input", input_, "--horizon", horizon, "--json"])
    assert rc == 2 and time.perf_counter() - t0 < 10.0
    line = _error(err)
    assert "invalid horizon=" in line and "at most" in line
    assert ("at speed=20 m/s" in line) == (input_ == "iso8608")


@pytest.mark.parametrize("freq", ["0.5", "5", "50"])
def test_sine_horizon_limit_scales_with_frequency(capsys, freq):
    # the bound is 4 steps per period: just above it is refused, the message says where
    h = 1e7 / (4 * float(freq)) * 1.01
    rc, _, err = _run(capsys, ["simulate", "--input", "sine", "--freq", freq, "--horizon", h])
    assert rc == 2 and "horizon" in _error(err)


# ---------------------------------------------------------------------------------------
# internal errors that were user errors


_FEW_SAMPLES = [
    (cmd, opt, v)
    for cmd in ("simulate", "monte-carlo")
    for opt, vals in (("--speed", ["1e6", "1e9", "1e300"]), ("--dt", ["10", "100", "1e300"]))
    for v in vals
]


@pytest.mark.parametrize("cmd,opt,value", _FEW_SAMPLES)
def test_roads_of_too_few_samples_are_refused(files, capsys, cmd, opt, value):
    rc, _, err = _run(capsys, _argv(("vehicle", cmd), files, opt, value))
    assert rc == 2
    line = _error(err)
    assert "speed" in line and "dt" in line and "samples" in line


def test_a_road_file_of_too_few_samples_is_refused(files, capsys):
    args = ["vehicle", "simulate", "--road-file", files / "road.crg", "--dt", "10"]
    rc, _, err = _run(capsys, args)
    assert rc == 2 and "samples" in _error(err)


_FLAT = [
    (s, i, a)
    for s in ("afw", "traditional", "cfw")
    for i in ("drop", "bump", "sine")
    for a in ("0", "1e-300")
]


@pytest.mark.parametrize("suspension,input_,amplitude", _FLAT)
def test_a_flat_road_gives_zero_motion(capsys, suspension, input_, amplitude):
    args = ["simulate", "--suspension", suspension, "--input", input_, "--amplitude", amplitude]
    rc, out, err = _run(capsys, [*args, "--json"])
    _ok_or_error(rc, err)
    assert rc == 0
    res = json.loads(out)
    for k in ("rms_deflection", "rms_body_acc_wk", "peak_deflection"):
        assert abs(res[k]) < 1e-200, (k, res[k])


# ---------------------------------------------------------------------------------------
# silent acceptance and guesses


@pytest.mark.parametrize("value", ["0", "-3", "101", "1000000000", "-99999999999999999999"])
@pytest.mark.parametrize("where", ["--network", "--all"])
def test_starts_out_of_range_are_refused(capsys, value, where):
    target = ["--network", "k | c"] if where == "--network" else ["--all", "--springs", "0"]
    rc, _, err = _run(capsys, ["network", "optimize", *target, "--starts", value])
    assert rc == 2 and "starts" in _error(err)


@pytest.mark.parametrize("objective", ["body_acc", "tyre_deflection", "suspension_deflection"])
@pytest.mark.parametrize("weight", ["body_acc=1", "tyre_deflection=2,body_acc=1"])
def test_weights_without_the_weighted_objective_are_refused(capsys, objective, weight):
    args = ["network", "optimize", "--network", "k | c", "--objective", objective]
    rc, _, err = _run(capsys, [*args, "--weight", weight])
    assert rc == 2 and "weight" in _error(err)


_DUPLICATES = [
    ["network", "h2", "--network", "k | c", "-p", "k=1,k=90000,c=5000"],
    ["network", "h2", "--network", "k | c", "-p", "k=1", "-p", "k=90000", "-p", "c=5000"],
    ["network", "optimize", "--network", "k | c", "--fix", "k=50000", "--fix", "k=60000"],
    ["network", "optimize", "--network", "k | c", "--bound", "c=1:2,c=3:4"],
    ["network", "optimize", "--network", "k | c", "--objective", "weighted",
     "--weight", "body_acc=1,body_acc=2"],  # fmt: skip
    ["network", "pareto", "--network", "k | c", "--fix", "k=5e4", "--fix", "k=6e4"],
    ["simulate", "--network", "k | c", "-p", "k=90000,c=5000,c=6000"],
    ["vehicle", "optimize", "--bound", "front_damping=1:2", "--bound", "front_damping=3:4"],
    ["vehicle", "optimize", "--limit", "front_deflection=0.01", "--limit",
     "front_deflection=0.02"],  # fmt: skip
    ["vehicle", "optimize", "--parameter", "front_damping", "--parameter", "front_damping"],
    ["identify", "--network", "k | c", "--param", "k=1e5,c=1e3", "--free", "k,k"],
    ["identify", "--network", "k | c", "--param", "k=1e5,c=1e3", "--free", "c", "--free", "c"],
]


@pytest.mark.parametrize("args", _DUPLICATES, ids=[" ".join(a[:3]) for a in _DUPLICATES])
def test_duplicated_names_are_refused(capsys, args):
    rc, _, err = _run(capsys, args)
    assert rc == 2
    line = _error(err)
    assert "twice" in line or "each name" in line


_PHYSICAL = [
    (name, value)
    for name in ("k", "c", "b")
    for value in ("1e-320", "5e-324", "1e-30", "1e30", "1e300")
]


@pytest.mark.parametrize("name,value", _PHYSICAL)
def test_network_parameters_outside_the_physical_range_are_refused(capsys, name, value):
    params = {"k": "50000", "c": "3000", "b": "100", name: value}
    p = ",".join(f"{k}={v}" for k, v in params.items())
    rc, _, err = _run(capsys, ["network", "h2", "--network", "k | c | b", "-p", p])
    assert rc == 2
    line = _error(err)
    assert f"invalid {name}=" in line and "magnitude" in line


@pytest.mark.parametrize("option", ["--sprung-mass", "--unsprung-mass", "--tyre-stiffness"])
@pytest.mark.parametrize("value", ["1e-320", "1e300"])
def test_network_car_outside_the_physical_range_is_refused(capsys, option, value):
    rc, _, err = _run(capsys, ["network", "h2", "--network", "k | c", "-p", "k=5e4,c=3e3",
                               option, value])  # fmt: skip
    e = _error(err)
    assert rc == 2 and (option in e or option.lstrip("-").replace("-", "_") in e)


@pytest.mark.parametrize(
    "name", ["rear_teleport", "front_dampingg", "front_stiffness", "seat_damping", "x"]
)
def test_bounds_on_names_not_optimised_are_refused(capsys, name):
    rc, _, err = _run(capsys, ["vehicle", "optimize", "--bound", f"{name}=1:2"])
    assert rc == 2
    line = _error(err)
    assert name in line and "front_damping, rear_damping" in line


_VEHICLE_COMMANDS = [["spectral"], ["modes"], ["simulate", "--length", "200"],
                     ["monte-carlo", "--roads", "2", "--length", "200", "--backend", "serial"],
                     ["optimize"]]  # fmt: skip


@pytest.mark.parametrize("command", _VEHICLE_COMMANDS, ids=[c[0] for c in _VEHICLE_COMMANDS])
def test_no_static_stiffness_is_one_rule_for_every_vehicle_command(files, capsys, command):
    rc, _, err = _run(capsys, ["vehicle", *command, "--vehicle", files / "zero.toml"])
    assert rc == 2
    assert "no static stiffness" in _error(err)


# ---------------------------------------------------------------------------------------
# messages


_LONG = [
    ["network", "h2", "--network", "k" * 100_000, "-p", "k=1"],
    ["network", "h2", "--network", "k | " + "(" * 2000 + "c", "-p", "k=1"],
    ["network", "optimize", "--network", "k | c", "--objective", "x" * 100_000],
    ["network", "optimize", "--network", "k | c", "--fix", "q" * 100_000 + "=1"],
    ["network", "pareto", "--network", "k | c", "--objectives", "z" * 50_000 + ",body_acc"],
    ["simulate", "--suspension", "s" * 100_000],
    ["simulate", "--network", "k | c", "-p", "k" * 100_000 + "=1"],
    ["h2", "--suspension", "t" * 100_000],
    ["vehicle", "spectral", "--road-class", "c" * 100_000],
    ["vehicle", "spectral", "--coherence", "9" * 100_000 + "x"],
    ["vehicle", "spectral", "--vehicle", "/nonexistent/" + "d" * 3000 + ".toml"],
    ["vehicle", "optimize", "--objective", "o" * 100_000],
    ["vehicle", "optimize", "--bound", "b" * 100_000 + "=1:2"],
    ["vehicle", "simulate", "--model", "m" * 100_000],
    ["identify", "--network", "k | c", "--param", "k=1", "--free", "f" * 100_000],
    ["flywheel", "--preset", "p" * 100_000],
]


@pytest.mark.parametrize("args", _LONG, ids=[" ".join(a[:3])[:40] for a in _LONG])
def test_long_user_strings_give_one_short_line(capsys, args):
    rc, _, err = _run(capsys, args)
    assert rc == 2, err[:500]
    line = _error(err)
    assert len(line) <= MESSAGE_LIMIT


def test_a_foreign_multiline_message_is_folded(capsys, monkeypatch):
    from inerterlab.cli import network as cli_network

    def boom(*a, **k):
        raise RuntimeError("first line\nsecond line\n" + "x" * 5000)

    monkeypatch.setattr("inerterlab.networks.enumerate_networks", boom)
    assert cli_network is not None
    rc, _, err = _run(capsys, ["network", "enumerate"])
    assert rc == 1
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "first line second line" in lines[0]
    assert len(lines[0]) <= MESSAGE_LIMIT


@pytest.mark.parametrize(
    "extra", [["--objective", "bad"], ["--starts", "0"], ["--weight", "body_acc=1"]]
)
def test_no_note_precedes_an_error_of_optimize_all(capsys, extra):
    # a budget above 20 candidates prints a note, but only after every setting is checked
    args = ["network", "optimize", "--all", "--dampers", "2", "--springs", "2", *extra]
    rc, _, err = _run(capsys, args)
    assert rc == 2
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("inerterlab: error:"), err
