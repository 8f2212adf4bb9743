"""Vehicle files: TOML with a unit on every value.

A value is a string ``"<number> <unit>"`` (``sprung_mass = "1200 kg"``) or an inline
table ``{ value = 1200, unit = "kg" }``. A bare number is refused: the file must say
what it means. Units are products of symbols separated by spaces, ``*`` or ``·``,
with ``^n`` (or a trailing digit, or ``²``) for powers and at most one ``/``:
``kg``, ``t``, ``g``; ``m``, ``mm``, ``cm``; ``N``, ``kN``; ``s``; ``kg m^2``,
``N/m``, ``kN/m``, ``N/mm``, ``N s/m``, ``kN s/m``. Each key has a dimension
(mass, length, stiffness, ...) and a value in another dimension is an error.

Layout (full car; ``model = "half"`` takes the same keys without ``roll_inertia``,
the tracks and the anti-roll bars, and its axles lump both wheels)::

    model = "full"
    sprung_mass = "1200 kg"
    pitch_inertia = "1800 kg m^2"
    roll_inertia = "450 kg m^2"
    cg_to_front = "1.15 m"
    cg_to_rear = "1.45 m"
    front_track = "1.52 m"
    rear_track = "1.50 m"

    [front]                       # one wheel
    unsprung_mass = "40 kg"
    stiffness = "28 kN/m"
    damping = "2200 N s/m"
    inertance = "0 kg"            # optional
    tyre_stiffness = "200 kN/m"
    tyre_damping = "50 N s/m"     # optional
    anti_roll = "12 kN/m"         # optional, full car only

    [rear]
    ...

    [seat]                        # optional
    x = "0.25 m"
    y = "0.37 m"
    mass = "75 kg"
    stiffness = "47 kN/m"
    damping = "1100 N s/m"

Errors name the file, the table and key, and the line.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

from ..errors import PHYSICAL_RANGES, DataFileError, ParameterError, check_physical
from .parameters import Corner, FullCar, HalfCar, NetworkStrut, Seat, Strut, Tyre

__all__ = [
    "load_vehicle",
    "loads_vehicle",
    "parse_quantity",
    "parse_unit",
    "example_vehicle_path",
    "DIMENSIONS",
]

# exponents of (kg, m, s)
DIMENSIONS = {
    "mass": (1, 0, 0),
    "length": (0, 1, 0),
    "inertia": (1, 2, 0),
    "stiffness": (1, 0, -2),
    "damping": (1, 0, -1),
    "acceleration": (0, 1, -2),
    "force": (1, 1, -2),
}
_SYMBOLS = {
    "g": (1e-3, (1, 0, 0)),
    "t": (1e3, (1, 0, 0)),
    "m": (1.0, (0, 1, 0)),
    "s": (1.0, (0, 0, 1)),
    "N": (1.0, (1, 1, -2)),
    "Hz": (1.0, (0, 0, -1)),
    "rad": (1.0, (0, 0, 0)),
    "Pa": (1.0, (1, -1, -2)),
    "bar": (1e5, (1, -1, -2)),
}
_PREFIXES = {"G": 1e9, "M": 1e6, "k": 1e3, "c": 1e-2, "m": 1e-3, "u": 1e-6, "µ": 1e-6}
_SUPERSCRIPTS = str.maketrans("²³⁻¹", "23-1")
#: largest magnitude of an exponent in a unit ("m^2", "s^-2")
MAX_EXPONENT = 6
_TOKEN = re.compile(r"^([A-Za-zµ]+)(?:\^?(-?\d+))?$")

_BODY_KEYS = {
    "sprung_mass": "mass",
    "pitch_inertia": "inertia",
    "roll_inertia": "inertia",
    "cg_to_front": "length",
    "cg_to_rear": "length",
    "front_track": "length",
    "rear_track": "length",
    "gravity": "acceleration",
}
_CORNER_KEYS = {
    "unsprung_mass": "mass",
    "stiffness": "stiffness",
    "damping": "damping",
    "inertance": "mass",
    "tyre_stiffness": "stiffness",
    "tyre_damping": "damping",
    "anti_roll": "stiffness",
}
_SEAT_KEYS = {
    "x": "length",
    "y": "length",
    "mass": "mass",
    "stiffness": "stiffness",
    "damping": "damping",
}
_HALF_ONLY_EXCLUDED = ("roll_inertia", "front_track", "rear_track")


def _symbol(token: str):
    if token in _SYMBOLS:
        return _SYMBOLS[token]
    if len(token) > 1 and token[0] in _PREFIXES and token[1:] in _SYMBOLS:
        f, d = _SYMBOLS[token[1:]]
        return _PREFIXES[token[0]] * f, d
    return None


def parse_unit(text: str) -> tuple[float, tuple[int, int, int]]:
    """(factor to SI, (kg, m, s) exponents) of a unit string; ParameterError if unknown.

    Exponents are integers of magnitude at most :data:`MAX_EXPONENT`; a unit whose
    factor to SI leaves the range of floating point numbers is refused.
    """
    if not isinstance(text, str):
        raise ParameterError("unit", text, "a unit string such as 'kg', 'N/m', 'N s/m'")
    t = text.strip().translate(_SUPERSCRIPTS).replace("·", " ").replace("*", " ")
    parts = t.split("/")
    if len(parts) > 2 or any(not p.strip() for p in parts):
        raise ParameterError("unit", text, "a unit such as 'kg', 'N/m', 'N s/m', 'kg m^2'")
    factor, dims = 1.0, [0, 0, 0]
    for side, chunk in enumerate(parts):
        sign = -1 if side else 1
        for tok in chunk.split():
            if tok == "1" and side == 0:
                continue
            if tok == "Ns":  # common shorthand for newton second
                tok_list = [("N", 1), ("s", 1)]
            else:
                m = _TOKEN.match(tok)
                if not m:
                    raise ParameterError("unit", text, "known unit symbols (kg, m, s, N, ...)")
                power = int(m.group(2)) if m.group(2) else 1
                if not -MAX_EXPONENT <= power <= MAX_EXPONENT:
                    raise ParameterError(
                        "unit", text, f"exponents from -{MAX_EXPONENT} to {MAX_EXPONENT}"
                    )
                tok_list = [(m.group(1), power)]
            for sym, power in tok_list:
                found = _symbol(sym)
                if found is None:
                    raise ParameterError(
                        "unit",
                        text,
                        f"known unit symbols (kg, t, m, mm, s, N, kN, ...), not {sym!r}",
                    )
                f, d = found
                factor *= f ** (sign * power)
                for i in range(3):
                    dims[i] += sign * power * d[i]
    if not 1e-30 <= factor <= 1e30 or any(abs(d) > MAX_EXPONENT for d in dims):
        raise ParameterError(
            "unit",
            text,
            f"a unit within 1e-30 to 1e30 of SI with exponents of at most {MAX_EXPONENT}",
        )
    return factor, tuple(dims)


def _dim_text(d) -> str:
    for name, dd in DIMENSIONS.items():
        if tuple(dd) == tuple(d):
            return name
    return "kg^{} m^{} s^{}".format(*d)


def parse_quantity(value, dimension: str) -> float:
    """SI value of ``"1200 kg"`` or ``{value=1200, unit="kg"}`` in ``dimension`` (a name
    of :data:`DIMENSIONS`, or a unit such as ``"rad/m"`` whose dimension it must have)."""
    if isinstance(value, dict):
        extra = set(value) - {"value", "unit"}
        if extra or "value" not in value or "unit" not in value:
            raise ParameterError("value", value, "a table with exactly 'value' and 'unit'")
        number, unit = value["value"], value["unit"]
        if isinstance(number, bool) or not isinstance(number, int | float):
            raise ParameterError("value", number, "a number")
        if not isinstance(unit, str):
            raise ParameterError("unit", unit, "a string")
    elif isinstance(value, str):
        m = re.match(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$", value)
        if not m or not m.group(2):
            raise ParameterError(
                "value", value, f"a number and a unit of {dimension}, e.g. '1200 kg'"
            )
        number, unit = float(m.group(1)), m.group(2)
    elif isinstance(value, int | float) and not isinstance(value, bool):
        raise ParameterError(
            "value", value, f'a value with a unit of {dimension}, e.g. "{value} <unit>"'
        )
    else:
        raise ParameterError("value", value, "a string '<number> <unit>' or {value, unit}")
    factor, dims = parse_unit(unit)
    want = DIMENSIONS[dimension] if dimension in DIMENSIONS else parse_unit(dimension)[1]
    if tuple(dims) != tuple(want):
        raise ParameterError("unit", unit, f"a unit of {dimension}, not of {_dim_text(dims)}")
    x = float(number) * factor
    if not math.isfinite(x):
        raise ParameterError("value", value, "a finite number")
    if dimension in PHYSICAL_RANGES:
        # tiny and huge magnitudes (1e-320 kg) are refused before any linear algebra
        check_physical("value", x, dimension, zero=True)
    return x


def _find_line(text: str, table: str | None, key: str | None) -> int | None:
    """Line (1-based) of ``key`` inside ``[table]`` (top level for None), else the header."""
    current = None
    header_line = None
    for i, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        m = re.match(r"^\[\s*([A-Za-z0-9_\-.]+)\s*\]", s)
        if m:
            current = m.group(1)
            if current == table:
                header_line = i
            continue
        if current == table and key is not None and re.match(rf"^{re.escape(key)}\s*=", s):
            return i
    return header_line


_ADAPTIVE_KEYS = ("flywheel", "changing_ratio", "law", "rest_inertance")


def _adaptive(table, where: str, fail):
    """An adaptive-flywheel inerter from a ``[front.adaptive]`` table: ``flywheel`` (preset),
    ``changing_ratio`` [-], ``law`` (thesis or momentum) and ``rest_inertance`` (a mass,
    r^2 I_min, which sets the transmission ratio r)."""
    import math

    from ..elements import AdaptiveFlywheelInerter
    from ..flywheels import flywheel

    if not isinstance(table, dict):
        fail(
            where.split(".")[0],
            "adaptive",
            "a table [.adaptive] of flywheel, changing_ratio, law, rest_inertance",
        )
    for k in table:
        if k not in _ADAPTIVE_KEYS:
            fail(where, k, "unknown key; expected one of " + ", ".join(_ADAPTIVE_KEYS))
    if "rest_inertance" not in table:
        fail(where, "rest_inertance", 'missing (the inertance at rest, e.g. "200 kg")')
    try:
        b = parse_quantity(table["rest_inertance"], "mass")
    except ParameterError as e:
        fail(where, "rest_inertance", f"{table['rest_inertance']!r}: expected {e.valid}")
    if not b > 0:
        fail(where, "rest_inertance", f"{b!r}: expected a mass > 0 kg")
    try:
        fw = flywheel(table.get("flywheel", "nylon"))
        x = table.get("changing_ratio")
        if x is not None:
            fw = fw.with_changing_ratio(float(x))
        return AdaptiveFlywheelInerter(
            flywheel=fw, ratio=math.sqrt(b / fw.inertia_min), law=table.get("law", "thesis")
        )
    except (ParameterError, TypeError, ValueError) as e:
        name = getattr(e, "name", "changing_ratio")
        fail(where, name, f"{getattr(e, 'value', '')!r}: expected {getattr(e, 'valid', e)}")


def _element_values(cls, table: dict, where: str, fail, skip=()) -> dict:
    """Parameters of an element of class ``cls`` from a table: physical ones with units,
    read in the unit the element declares for each (:attr:`ElementBase.PARAMETERS`,
    ``"700 kN/m"``), choices as text, dimensionless ones as numbers."""
    params = {p.name: p for p in cls.PARAMETERS}
    values = {}
    for key, value in table.items():
        if key in skip:
            continue
        if key not in params:
            fail(where, key, "unknown parameter of a " + cls.description + "; expected one of "
                 + ", ".join(params))  # fmt: skip
        p = params[key]
        if p.choices is not None or isinstance(value, str) and not p.unit:
            values[key] = value
            continue
        if not p.unit:
            if isinstance(value, bool) or not isinstance(value, int | float):
                fail(where, key, f"{value!r}: expected a number")
            values[key] = float(value)
            continue
        try:
            values[key] = parse_quantity(value, p.unit)
        except ParameterError as e:
            fail(where, key, f"{value!r}: expected {e.valid}")
    return values


def _make_element(cls, values: dict, where: str, fail):
    try:
        return cls(**values)
    except ParameterError as e:
        fail(where, e.name, f"{e.value!r}: expected {e.valid}")
    except TypeError:
        missing = [p.name for p in cls.PARAMETERS if p.name not in values]
        fail(where, missing[0] if missing else "kind", "missing (required)")


def _device(table, where: str, fail):
    """A core element from a ``[front.device]`` table: ``kind`` (an element name of
    :data:`inerterlab.elements.ELEMENTS`, e.g. ``hyd``, ``rect``, ``screw``, ``fluid``)
    and its parameters by name (:func:`_element_values`). Missing parameters take the
    element's defaults (for the thesis devices: their identified values)."""
    from ..elements import ELEMENTS

    if not isinstance(table, dict):
        fail(where.split(".")[0], "device", "a table [.device] with kind and parameters")
    kind = table.get("kind")
    if kind not in ELEMENTS:
        fail(where, "kind", f"{kind!r}: expected one of {', '.join(sorted(ELEMENTS))}")
    cls = ELEMENTS[kind]
    return _make_element(cls, _element_values(cls, table, where, fail, skip=("kind",)), where, fail)


def _network_values(network, values: dict, axle: str, fail):
    """The strut of ``network = "..."`` in table ``[axle]`` and the keys it used. Each
    element's value is under its own name: a quantity in the unit of the element's first
    parameter (``k = "28 kN/m"``, ``b = "150 kg"``), or a table of its parameters by name
    (``hyd = { stiffness = "700 kN/m", flywheel = "none" }``), or nothing for an element
    whose parameters all have defaults. The units are those the elements declare. A
    network of springs, linear dampers and inerters is a
    :class:`~inerterlab.vehicles.parameters.NetworkStrut`; any other (devices, adaptive
    flywheels, friction, free play, fluid inerters) a strut whose device is the network."""
    from ..elements import kernel_law
    from ..networks import NetworkError, parse_network

    if not isinstance(network, str):
        fail(axle, "network", f"{network!r}: expected a network text such as 'k | (c - b)'")
    try:
        net = parse_network(network)
    except NetworkError as e:
        fail(axle, "network", str(e))
    elements = {}
    for e in net.tree.elements():
        name, cls = e.name, e.cls
        where = f"{axle}.{name}"
        value = values.get(name)
        if value is None:
            if any(p.name not in _defaults(cls) for p in cls.PARAMETERS):
                fail(axle, name, f"missing: the value of {cls.description} {name!r} of "
                     f"network {net.text!r}")  # fmt: skip
            elements[name] = _make_element(cls, {}, where, fail)
        elif isinstance(value, dict) and set(value) != {"value", "unit"}:
            elements[name] = _make_element(cls, _element_values(cls, value, where, fail), where, fail)
        else:
            first = cls.PARAMETERS[0]
            try:
                x = parse_quantity(value, first.unit)
            except ParameterError as err:
                fail(axle, name, f"{value!r}: expected {err.valid} ({cls.description} {first.name})")
            elements[name] = _make_element(cls, {first.name: x}, where, fail)
    linear = all(  # a spring, damper or inerter law (no friction, flywheel or contact)
        el.code is not None and el.is_linear and len(el.PARAMETERS) <= 2
        and not (kernel_law(el).bounded or kernel_law(el).contact)
        for el in elements.values()
    )  # fmt: skip
    if linear:
        vals = {n: float(el.rest_network()[1].popitem()[1]) for n, el in elements.items()}
        return NetworkStrut(net.text, vals), set(elements)
    return (Strut(stiffness=0.0, damping=0.0, device=net.text, device_parameters=elements),
            set(elements))  # fmt: skip


def _defaults(cls) -> set:
    """Names of the parameters of ``cls`` that have defaults."""
    import dataclasses

    return {
        f.name for f in dataclasses.fields(cls)
        if f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING
    }  # fmt: skip


def loads_vehicle(text: str, source: str = "<string>") -> HalfCar | FullCar:
    """Vehicle parameters from TOML text (``source`` names it in errors)."""
    if not isinstance(text, str):
        raise ParameterError("text", text, "the TOML text of a vehicle file (a str)")
    if not isinstance(source, str):
        raise ParameterError("source", source, "a str naming the text in messages")
    from ..io import loads_toml

    data = loads_toml(text, source, "vehicle file")

    def fail(table, key, msg):
        where = f"[{table}] {key}" if table and key else (f"[{table}]" if table else key)
        raise DataFileError(source, f"{where}: {msg}", _find_line(text, table, key))

    model = data.get("model", "full")
    if model not in ("half", "full"):
        fail(None, "model", f"{model!r} is not 'half' or 'full'")
    body_keys = dict(_BODY_KEYS)
    if model == "half":
        for k in _HALF_ONLY_EXCLUDED:
            body_keys.pop(k)
    tables = {"front", "rear", "seat"}

    def quantities(table, values, keys):
        out = {}
        for k, v in values.items():
            if k not in keys:
                fail(table, k, "unknown key; expected one of " + ", ".join(sorted(keys)))
            try:
                out[k] = parse_quantity(v, keys[k])
            except ParameterError as e:
                fail(table, k, f"{v!r}: expected {e.valid}")
        return out

    top = {k: v for k, v in data.items() if k != "model" and k not in tables}
    body = quantities(None, top, body_keys)
    for k in body_keys:
        if k not in body and k != "gravity":
            fail(None, k, "missing")
    corners = {}
    for axle in ("front", "rear"):
        if axle not in data or not isinstance(data[axle], dict):
            fail(None, axle, f"missing table [{axle}]")
        keys = dict(_CORNER_KEYS)
        if model == "half":
            keys.pop("anti_roll")
        values = dict(data[axle])
        adaptive_table = values.pop("adaptive", None)
        device_table = values.pop("device", None)
        network = values.pop("network", None)
        used: set = set()
        if network is not None:
            try:
                net_strut, used = _network_values(network, values, axle, fail)
            except ParameterError as e:
                fail(axle, "network", f"{e.value!r}: {e.valid}")
            for k in ("stiffness", "damping", "inertance"):
                if k in values:
                    fail(axle, k, f"not with network = {network!r}: give each element's "
                         "value under its own name")  # fmt: skip
            if adaptive_table is not None:
                fail(axle, "adaptive", "not with a network (an adaptive inerter is a Strut's)")
            if device_table is not None:
                fail(axle, "device", "not with a network (a device is a Strut's)")
            values = {k: v for k, v in values.items() if k not in used}
        q = quantities(axle, values, keys)
        adaptive = None
        if adaptive_table is not None:
            adaptive = _adaptive(adaptive_table, f"{axle}.adaptive", fail)
        device = None
        if device_table is not None:
            device = _device(device_table, f"{axle}.device", fail)
        required = ("unsprung_mass", "tyre_stiffness")
        if network is None:
            required += ("stiffness", "damping")
        for k in required:
            if k not in q:
                fail(axle, k, "missing")
        try:
            if network is not None:
                strut = net_strut
            else:
                strut = Strut(
                    stiffness=q["stiffness"],
                    damping=q["damping"],
                    inertance=q.get("inertance", 0.0),
                    adaptive=adaptive,
                    device=device,
                )
            corners[axle] = Corner(
                unsprung_mass=q["unsprung_mass"],
                strut=strut,
                tyre=Tyre(stiffness=q["tyre_stiffness"], damping=q.get("tyre_damping", 0.0)),
            )
        except ParameterError as e:
            fail(axle, e.name, f"{e.value!r}: expected {e.valid}")  # names match the keys
        corners[f"{axle}_anti_roll"] = q.get("anti_roll", 0.0)
    seat = None
    if "seat" in data:
        q = quantities("seat", data["seat"], _SEAT_KEYS)
        for k in ("mass", "stiffness", "damping"):
            if k not in q:
                fail("seat", k, "missing")
        try:
            seat = Seat(**q)
        except ParameterError as e:
            fail("seat", e.name.removeprefix("seat."), f"{e.value!r}: expected {e.valid}")
    try:
        common = dict(
            sprung_mass=body["sprung_mass"],
            pitch_inertia=body["pitch_inertia"],
            cg_to_front=body["cg_to_front"],
            cg_to_rear=body["cg_to_rear"],
            front=corners["front"],
            rear=corners["rear"],
            seat=seat,
        )
        if "gravity" in body:
            common["gravity"] = body["gravity"]
        if model == "half":
            return HalfCar(**common)
        return FullCar(
            roll_inertia=body["roll_inertia"],
            front_track=body["front_track"],
            rear_track=body["rear_track"],
            front_anti_roll=corners["front_anti_roll"],
            rear_anti_roll=corners["rear_anti_roll"],
            **common,
        )
    except ParameterError as e:
        name = e.name
        for axle in ("front", "rear"):
            if name == f"{axle}_anti_roll":
                fail(axle, "anti_roll", f"{e.value!r}: expected {e.valid}")
        fail(None, name, f"{e.value!r}: expected {e.valid}")


def load_vehicle(path) -> HalfCar | FullCar:
    """Vehicle parameters from a TOML file (see the module documentation)."""
    from ..io import CONFIG_SIZE_LIMIT, read_text_limited

    if not isinstance(path, str | os.PathLike) or not str(path):
        raise ParameterError("path", path, "the path of a vehicle TOML file (str or Path)")
    p = Path(path)
    # size-capped, UTF-8 only; a device or FIFO is read up to the cap and a time limit
    text = read_text_limited(p, "vehicle file", limit=CONFIG_SIZE_LIMIT)
    return loads_vehicle(text, str(p))


def example_vehicle_path() -> Path:
    """Path of the example full car shipped with the package."""
    from importlib.resources import files

    return Path(str(files("inerterlab") / "data" / "vehicle_sedan.toml"))
