"""The car file of ``inerterlab identify --propagate car.toml``: a quarter car that uses
the identified device, the road to drive it over and how to propagate.

Layout (every dimensional value a string "number unit"; a bare number is refused so a
value in the wrong unit cannot pass silently)::

    suspension = "device"            # "device" (system A) or "device-afw" (system B)
    flywheel = "nylon"               # device-afw: flywheel preset
    changing_ratio = 0.3             # device-afw, optional, dimensionless
    friction_velocity = "1 mm/s"     # optional: v_eps of the smoothed friction

    [car]                            # optional; thesis values (4.16) for missing keys
    sprung_mass = "370 kg"
    unsprung_mass = "25 kg"
    stiffness = "90 kN/m"
    damping = "5000 N s/m"
    tyre_stiffness = "120 kN/m"
    tyre_damping = "1300 N s/m"

    [road]                           # optional; default: a 50 mm drop over 3 s
    type = "drop"                    # drop, sine, iso8608 or none (linear metrics only)
    height = "50 mm"                 # drop
    amplitude = "20 mm"              # sine
    frequency = "2 Hz"               # sine
    class = "C"                      # iso8608
    speed = "20 m/s"                 # iso8608 (also the road of the linearisation)
    seed = 1                         # iso8608
    horizon = "3 s"

    [propagation]                    # optional
    method = "delta"                 # or "monte-carlo"
    draws = 200                      # Monte Carlo
    seed = 0
    linear = true                    # H2 norms and body resonance of the linearised car

The identified stiffness, damping and friction replace the device's k_h, b_ah and F_fh.
Problems raise :class:`~inerterlab.errors.DataFileError` naming the file, the key and
its line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import DataFileError, InerterlabError

__all__ = ["CarFile", "load_car_file"]

_UNITS = {
    "mass": {"kg": 1.0, "g": 1e-3, "t": 1e3},
    "stiffness": {"N/m": 1.0, "kN/m": 1e3, "N/mm": 1e3, "MN/m": 1e6},
    "damping": {"N s/m": 1.0, "Ns/m": 1.0, "N*s/m": 1.0, "kN s/m": 1e3, "kNs/m": 1e3},
    "length": {"m": 1.0, "mm": 1e-3, "cm": 1e-2},
    "velocity": {"m/s": 1.0, "mm/s": 1e-3, "km/h": 1.0 / 3.6},
    "frequency": {"Hz": 1.0},
    "time": {"s": 1.0, "ms": 1e-3},
}
_CAR_KEYS = {
    "sprung_mass": "mass",
    "unsprung_mass": "mass",
    "stiffness": "stiffness",
    "damping": "damping",
    "tyre_stiffness": "stiffness",
    "tyre_damping": "damping",
}
_ROAD_KEYS = {
    "type": None,
    "height": "length",
    "amplitude": "length",
    "frequency": "frequency",
    "class": None,
    "speed": "velocity",
    "seed": None,
    "horizon": "time",
}
_TOP = {
    "suspension",
    "flywheel",
    "changing_ratio",
    "friction_velocity",
    "car",
    "road",
    "propagation",
}
_PROP = {"method", "draws", "seed", "linear"}


@dataclass(frozen=True)
class CarFile:
    """What a car file describes: the car, the road (``None``: linear metrics only),
    the simulated horizon [s] and the propagation settings."""

    car: object
    excitation: object
    horizon: float
    method: str
    draws: int
    seed: int
    linear: bool
    road_class: str
    speed: float


def _lines(text: str) -> dict:
    out, table = {}, ""
    for i, ln in enumerate(text.splitlines(), 1):
        m = re.match(r"\s*\[([^\]]+)\]", ln)
        if m:
            table = m.group(1).strip() + "."
            out.setdefault(table[:-1], i)
            continue
        m = re.match(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*=", ln)
        if m:
            out.setdefault(table + m.group(1), i)
    return out


def load_car_file(path) -> CarFile:
    """Read and check a car file (layout in the module docstring)."""
    from ..io import read_toml

    p = Path(path)
    text, doc = read_toml(p, "car file")
    lines = _lines(text)

    def fail(key, msg):
        raise DataFileError(p, f"{key}: {msg}", lines.get(key))

    def quantity(key, value, kind):
        units = _UNITS[kind]
        if isinstance(value, bool) or not isinstance(value, str):
            fail(
                key,
                f"{value!r} has no unit; write it as a string such as "
                f'"{1} {next(iter(units))}" (units: {", ".join(units)})',
            )
        m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*(.*?)\s*", value)
        unit = m.group(2) if m else ""
        if not m or unit not in units:
            fail(key, f"{value!r} is not 'number unit' with a unit among {', '.join(units)}")
        try:
            x = float(m.group(1))
        except ValueError:
            fail(key, f"{value!r}: {m.group(1)!r} is not a number")
        return x * units[unit]

    def table(name, allowed):
        t = doc.get(name, {})
        if not isinstance(t, dict):
            fail(name, f"must be a table [{name}]")
        for k in t:
            if k not in allowed:
                fail(f"{name}.{k}", "unknown key; expected one of " + ", ".join(sorted(allowed)))
        return t

    for k in doc:
        if k not in _TOP:
            fail(k, "unknown key; expected one of " + ", ".join(sorted(_TOP)))
    suspension = doc.get("suspension")
    if suspension not in ("device", "device-afw"):
        fail("suspension", f'{suspension!r}: expected "device" or "device-afw"')
    car_t = table("car", _CAR_KEYS)
    road_t = table("road", _ROAD_KEYS)
    prop_t = table("propagation", _PROP)
    kw = {k: quantity(f"car.{k}", v, _CAR_KEYS[k]) for k, v in car_t.items()}
    if "friction_velocity" in doc:
        kw["friction_velocity"] = quantity(
            "friction_velocity", doc["friction_velocity"], "velocity"
        )
    if suspension == "device-afw":
        fw = doc.get("flywheel", "nylon")
        if not isinstance(fw, str):
            fail("flywheel", f"{fw!r}: a flywheel preset name")
        kw["flywheel"] = fw
        if "changing_ratio" in doc:
            x = doc["changing_ratio"]
            if isinstance(x, bool) or not isinstance(x, int | float):
                fail("changing_ratio", f"{x!r}: a number in (0, 1)")
            kw["changing_ratio"] = float(x)
    else:
        for k in ("flywheel", "changing_ratio"):
            if k in doc:
                fail(k, "only a device-afw car has a flywheel")
    from ..systems import quarter_car

    try:
        car = quarter_car(suspension, **kw).info["model"]
    except InerterlabError as exc:
        key = getattr(exc, "name", "car")
        key = key if key in ("flywheel", "changing_ratio", "friction_velocity") else f"car.{key}"
        fail(key, str(exc))
    # road
    from ..excitation import drop, iso8608, sine

    rtype = road_t.get("type", "drop")
    road_class = "C"
    speed = 20.0
    horizon = quantity("road.horizon", road_t["horizon"], "time") if "horizon" in road_t else 3.0
    if horizon <= 0:
        fail("road.horizon", "must be > 0 s")
    allowed = {
        "drop": {"height"},
        "sine": {"amplitude", "frequency"},
        "iso8608": {"class", "speed", "seed"},
        "none": {"class", "speed"},
    }
    if rtype not in allowed:
        fail("road.type", f"{rtype!r}: expected one of drop, sine, iso8608, none")
    for k in road_t:
        if k not in allowed[rtype] | {"type", "horizon"}:
            fail(f"road.{k}", f"not a setting of a {rtype} road")
    if "class" in road_t:
        road_class = road_t["class"]
        if road_class not in tuple("ABCDEFGH"):
            fail("road.class", f"{road_class!r}: an ISO 8608 class A-H")
    if "speed" in road_t:
        speed = quantity("road.speed", road_t["speed"], "velocity")
        if speed <= 0:
            fail("road.speed", "must be > 0")
    try:
        if rtype == "drop":
            ex = drop(quantity("road.height", road_t.get("height", "50 mm"), "length"))
        elif rtype == "sine":
            ex = sine(
                quantity("road.amplitude", road_t.get("amplitude", "20 mm"), "length"),
                quantity("road.frequency", road_t.get("frequency", "2 Hz"), "frequency"),
            )
        elif rtype == "iso8608":
            seed = road_t.get("seed", 1)
            if isinstance(seed, bool) or not isinstance(seed, int):
                fail("road.seed", f"{seed!r}: an integer")
            ex = iso8608(road_class, speed, seed=seed)
        else:
            ex = None
    except InerterlabError as exc:
        fail("road", str(exc))
    method = prop_t.get("method", "delta")
    if method not in ("delta", "monte-carlo"):
        fail("propagation.method", f'{method!r}: expected "delta" or "monte-carlo"')
    draws = prop_t.get("draws", 200)
    if isinstance(draws, bool) or not isinstance(draws, int) or draws < 2:
        fail("propagation.draws", f"{draws!r}: an integer >= 2")
    pseed = prop_t.get("seed", 0)
    if isinstance(pseed, bool) or not isinstance(pseed, int):
        fail("propagation.seed", f"{pseed!r}: an integer")
    linear = prop_t.get("linear", True)
    if not isinstance(linear, bool):
        fail("propagation.linear", f"{linear!r}: true or false")
    if ex is None and not linear:
        fail("propagation.linear", "false with road type none leaves nothing to compute")
    return CarFile(
        car=car,
        excitation=ex,
        horizon=horizon,
        method=method,
        draws=draws,
        seed=pseed,
        linear=linear,
        road_class=road_class,
        speed=speed,
    )
