"""Nonlinear truth of optimised suspension layouts: does the linear prediction survive a
real inerter, and does an adaptive flywheel help in any layout?

For each layout (a network text with one ideal inerter ``b``), the linear H2 design
(:func:`inerterlab.network_design.optimize_network`, body acceleration under white road
velocity, static stiffness fixed) is simulated in the time domain by the model core
(:mod:`inerterlab.systems`) with the ideal inerter replaced by a *variant*:

``ideal``
    the optimised inerter b itself (the linear prediction on that input);
``ideal-max x=X``
    an ideal inerter of b / (1 - X), the inertance an adaptive flywheel of changing
    ratio X reaches when saturated (adaptivity against simply a larger inerter);
``afw x=X law=L``
    the adaptive-flywheel inerter (nylon flywheel, changing ratio X, force law L:
    ``thesis``, ``momentum`` or ``slider-dynamics``) whose
    transmission ratio gives a rest inertance r^2 I_min = b;
``hydraulic``, ``rectifier``
    the inertance b behind the identified series stiffness, in parallel with the
    identified damping and Coulomb friction of the device, ``(k - (c | fric | b))``
    (docs/model.md §3; the rectifier's flywheel kept coupled);
``screw``
    the inertance b in parallel with the ball screw's identified stiffness, damping and
    friction, ``(k | c | fric | b)``;
``fluid``
    a helical-channel fluid inerter of inertance b with laminar (Hagen-Poiseuille) and
    quadratic (entry/exit) losses for a stated illustrative geometry (:data:`FLUID`).

The comfort gain of each variant is measured against the optimised ``k | c`` on the
same input, in the same time simulation. The *survival* is the variant's gain divided
by the ideal inerter's gain (1: all of the linear prediction survives, 0: none,
negative: worse than having no inerter). Each (layout, variant, input) is one point of
a sweep (:mod:`inerterlab.studies`), so the study runs serially, in processes or on
Dask, is stored chunk by chunk and resumes.

The car: the thesis car (4.16) by default, or any quarter car (``car``: sprung and
unsprung mass, tyre stiffness and damping), used alike for the H2 design of every
layout, for the optimised ``k | c`` and in every simulation. ``k | c | b`` has an
infinite H2 norm of body acceleration with a damped tyre (a direct feed-through), so on
the thesis car it keeps the thesis's values and on any other car it is designed for the
Wk-weighted body acceleration (finite: the weighting rolls off), the measure the study
scores comfort by.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import ParameterError
from .studies.points import ParameterSpec, PointFunction, register_point_function

__all__ = [
    "LAYOUTS",
    "BASELINE",
    "INPUTS",
    "FLUID",
    "TRUTH_METRICS",
    "variants",
    "layout_parameters",
    "truth_point",
    "network_truth",
    "TruthResult",
]

#: the layouts studied (key: the name used in tables) -> network text with one ``b``
LAYOUTS = {
    "parallel": "k | c | b",
    "series": "k | (c - b)",
    "series-spring": "k | (b - (k1 | c))",
}
#: the reference every gain is measured against
BASELINE = "k | c"
#: road inputs: name -> description
INPUTS = {
    "drop": "both masses released from 5 cm",
    "bump": "5 cm rectangular pulse of 10 ms",
    "sine-1.5": "5 cm sine at 1.5 Hz (near the body resonance)",
    "sine-5": "5 cm sine at 5 Hz (the thesis's sine)",
    "iso-c": "ISO 8608 class C road at 20 m/s",
}
#: fluid inerter geometry (illustrative, not a measured device): hydraulic oil of
#: density 870 kg/m^3 and dynamic viscosity 0.03 Pa s, a 40 mm bore piston and a 6 mm
#: helical channel whose length gives the wanted inertance; entry plus exit loss
#: coefficient 1.5
FLUID = {
    "density": 870.0,
    "viscosity": 0.03,
    "piston_diameter": 0.040,
    "channel_diameter": 0.006,
    "loss_coefficient": 1.5,
}
#: metrics of a truth point
TRUTH_METRICS = ("rms_body_acc_wk", "vdv", "rms_tyre_grip", "rms_deflection")
RATIOS = (0.05, 0.15, 0.285, 0.45, 0.55)
LAWS = ("thesis", "momentum", "slider-dynamics")
THESIS_PARALLEL = {"c": 5000.0, "b": 206.3}  # thesis car (4.16) with the cfw inertance
#: the thesis car (4.16): the default quarter car of the study
THESIS_CAR = {
    "sprung_mass": 370.0,
    "unsprung_mass": 25.0,
    "tyre_stiffness": 120_000.0,
    "tyre_damping": 1300.0,
}

_VARIANT_RE = re.compile(
    r"^(?:(ideal)|ideal-max x=([0-9.eE+-]+)|afw x=([0-9.eE+-]+) law=([a-z-]+)"
    r"|(hydraulic)|(rectifier)|(screw)|(fluid))$"
)


def variants(ratios=RATIOS, laws=LAWS, devices=True) -> list[str]:
    """The variant names of the study (see the module docstring)."""
    out = ["ideal"]
    out += [f"ideal-max x={x:g}" for x in ratios]
    out += [f"afw x={x:g} law={law}" for law in laws for x in ratios]
    if devices:
        out += ["hydraulic", "rectifier", "screw", "fluid"]
    return out


def _parse_variant(text: str):
    m = _VARIANT_RE.match(text.strip())
    if not m:
        raise ParameterError(
            "variant",
            text,
            "ideal, 'ideal-max x=X', 'afw x=X law=thesis|momentum|slider-dynamics', "
            "hydraulic, rectifier, screw or fluid",
        )
    g = m.groups()
    if g[0]:
        return ("ideal", None, None)
    if g[1]:
        return ("ideal-max", _ratio(g[1]), None)
    if g[2]:
        law = g[3]
        if law not in ("thesis", "momentum", "slider-dynamics"):
            raise ParameterError("variant", text, "law thesis, momentum or slider-dynamics")
        return ("afw", _ratio(g[2]), law)
    return (next(x for x in g[4:] if x), None, None)


def _ratio(s: str) -> float:
    try:
        x = float(s)
    except ValueError:
        raise ParameterError("variant", s, "a changing ratio x in (0, 1)") from None
    if not 0.0 < x < 1.0:
        raise ParameterError("variant", s, "a changing ratio x in (0, 1)")
    return x


def _car(car: Mapping[str, Any] | None) -> dict:
    """The study's quarter car: the thesis car with the values of ``car`` in place."""
    out = dict(THESIS_CAR)
    for k, v in (car or {}).items():
        if k not in out:
            raise ParameterError("car", k, "one of " + ", ".join(THESIS_CAR))
        out[k] = float(v)
    return out


def layout_parameters(network: str, stiffness: float = 90_000.0, car=None) -> dict:
    """The H2 comfort design of ``network`` (static stiffness fixed) in the quarter car
    ``car`` (default the thesis car).

    ``k | c | b`` has an infinite body-acceleration H2 norm with a damped tyre (the
    inerter passes the tyre damper's impulse to the body): on the thesis car it keeps
    the thesis's values (c = 5000 N s/m, b = the ``cfw`` inertance 206.3 kg), on any
    other car it is designed for the Wk-weighted body acceleration."""
    c = _car(car)
    return _layout_parameters(network, float(stiffness), tuple(sorted(c.items())))


@functools.lru_cache(maxsize=64)
def _layout_parameters(network: str, stiffness: float, car: tuple) -> dict:
    from .network_design import optimize_network

    c = dict(car)
    objective = "body_acc"
    if network == LAYOUTS["parallel"]:
        if c == THESIS_CAR:
            return {"k": stiffness, **THESIS_PARALLEL}
        objective = "body_acc_wk"
    res = optimize_network(
        network, objective, fixed={"k": stiffness}, compare=False, simplify=False, **c
    )
    return {k: float(v) for k, v in res.parameters.items()}


def _replace_b(network: str, text: str) -> str:
    out, n = re.subn(r"(?<![A-Za-z0-9_])b(?![A-Za-z0-9_])", text, network)
    if n != 1:
        raise ParameterError("layout", network, "a network with exactly one inerter named b")
    return out


def _fluid_parameters(b: float) -> dict:
    """The fluid inerter of :data:`FLUID`'s geometry with inertance ``b`` [kg]: its
    channel length and losses as the element resolves them (laminar loss from the
    viscosity, entry and exit losses from the loss coefficient)."""
    from .elements.fluid_inerter import FluidInerter

    g = FLUID
    el = FluidInerter(
        density=g["density"],
        inertance=b,
        piston_area=math.pi * g["piston_diameter"] ** 2 / 4,
        channel_area=math.pi * g["channel_diameter"] ** 2 / 4,
        viscosity=g["viscosity"],
        loss_coefficient=g["loss_coefficient"],
    )
    return dict(
        density=el.density, length=el.length, piston_area=el.piston_area,
        channel_area=el.channel_area, damping=el.damping, quadratic=el.quadratic,
    )  # fmt: skip


def _network_for(layout_text: str, params: dict, variant: str, car=None):
    """(network text, element parameters) of ``layout_text`` with ``variant`` for b."""
    from .devices.models import HydraulicDevice, RectifierDevice, ScrewDevice
    from .flywheels import flywheel

    kind, x, law = _parse_variant(variant)
    p = dict(params)
    b = p.pop("b")
    if kind == "ideal":
        return layout_text, {**p, "b": b}
    if kind == "ideal-max":
        return layout_text, {**p, "b": b / (1.0 - x)}
    if kind == "afw":
        fw = flywheel("nylon").with_changing_ratio(x)
        r = math.sqrt(b / fw.inertia_min)
        text = _replace_b(layout_text, "afw")
        return text, {
            **p,
            "afw": {"flywheel": "nylon", "changing_ratio": x, "ratio": r, "law": law},
        }
    if kind == "fluid":
        return _replace_b(layout_text, "fluid"), {**p, "fluid": _fluid_parameters(b)}
    dev = {"hydraulic": HydraulicDevice, "rectifier": RectifierDevice, "screw": ScrewDevice}[kind]()
    parts = {
        "k_dev": dev.stiffness,
        "c_dev": dev.damping,
        "fric_dev": {"force": dev.friction, "velocity": dev.friction_velocity},
        "b": b,
    }
    if kind == "screw":
        return _replace_b(layout_text, "(k_dev | c_dev | fric_dev | b)"), {**p, **parts}
    # a series device: its spring on either side of the branch (the same admittance);
    # the model core needs one end of the inertance on a node that has a mass or
    # another inertance, so take the order that gives that
    from .networks import NetworkError
    from .systems import quarter_car

    texts = [
        _replace_b(layout_text, "(k_dev - (c_dev | fric_dev | b))"),
        _replace_b(layout_text, "((c_dev | fric_dev | b) - k_dev)"),
    ]
    for text in texts:
        try:
            quarter_car(text, {**p, **parts}, **(car or {}))
        except NetworkError:
            continue
        return text, {**p, **parts}
    return texts[0], {**p, **parts}


def _excitation(name: str, seed: int):
    from . import excitation as ex

    if name == "drop":
        return ex.drop(0.05)
    if name == "bump":
        return ex.bump(0.05)
    if name == "sine-1.5":
        return ex.sine(0.05, 1.5)
    if name == "sine-5":
        return ex.sine(0.05, 5.0)
    return ex.iso8608("C", 20.0, seed=seed)


def _truth_metrics(net: str, elp: dict, car: dict, params: Mapping[str, Any]) -> dict:
    """:data:`TRUTH_METRICS` of the quarter car ``car`` with the network ``net`` on the
    point's input: integrated as observer states, with one output sample (at the
    horizon) instead of one every millisecond, which nothing here reads."""
    from .systems import quarter_car

    res = quarter_car(net, elp, **car).simulate(
        _excitation(params["input"], int(params["seed"])),
        horizon=float(params["horizon"]),
        metrics_only=True,
    )
    return {k: float(res.metrics[k]) for k in TRUTH_METRICS}


def truth_point(params: Mapping[str, Any]) -> dict[str, float]:
    """Simulate one (layout, variant, input) and return :data:`TRUTH_METRICS`."""
    layout = params["layout"]
    text = BASELINE if layout == "baseline" else LAYOUTS[layout]
    c = _car({k: params[k] for k in THESIS_CAR if k in params})
    design = layout_parameters(text, float(params["stiffness"]), c)
    if layout == "baseline":
        net, elp = text, design
    else:
        net, elp = _network_for(text, design, params["variant"], c)
    return _truth_metrics(net, elp, c, params)


def truth_inputs() -> dict:
    """What a truth point reads besides its parameters: the layouts' network texts, the
    baseline, the fluid inerter's geometry, the devices' identified values and the
    flywheel: a store of the study is keyed on them (a change is computed into a new
    store, never resumed into the old one)."""
    import dataclasses

    from .devices.models import HydraulicDevice, RectifierDevice, ScrewDevice
    from .flywheels import flywheel

    def plain(obj):
        if dataclasses.is_dataclass(obj):
            return {f.name: repr(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
        return repr(obj)

    return {
        "layouts": dict(LAYOUTS),
        "design": "H2 body_acc (k | c | b off the thesis car: body_acc_wk)",
        "baseline": BASELINE,
        "thesis_parallel": dict(THESIS_PARALLEL),
        "fluid": dict(FLUID),
        "devices": {
            "hydraulic": plain(HydraulicDevice()),
            "rectifier": plain(RectifierDevice()),
            "screw": plain(ScrewDevice()),
        },
        "flywheel": plain(flywheel("nylon")),
    }


#: the parameters every truth point takes besides its layout (or network)
_PARAMETERS = {
    "variant": ParameterSpec(kind="text", doc="ideal, afw x=X law=L, a device, fluid"),
    "input": ParameterSpec(kind="choice", choices=tuple(INPUTS)),
    "stiffness": ParameterSpec(low=0.0, low_open=True, unit="N/m", doc="static k"),
    "horizon": ParameterSpec(low=0.0, low_open=True, high=600.0, unit="s"),
    "seed": ParameterSpec(kind="int", low=0.0, doc="ISO 8608 road seed"),
    "sprung_mass": ParameterSpec(low=0.0, low_open=True, unit="kg", doc="quarter car m_s"),
    "unsprung_mass": ParameterSpec(low=0.0, low_open=True, unit="kg", doc="quarter car m_u"),
    "tyre_stiffness": ParameterSpec(low=0.0, low_open=True, unit="N/m", doc="tyre k_t"),
    "tyre_damping": ParameterSpec(low=0.0, unit="N s/m", doc="tyre c_t"),
}
_DEFAULTS = {
    "variant": "ideal",
    "input": "bump",
    "stiffness": 90_000.0,
    "horizon": 10.0,
    "seed": 1,
    **THESIS_CAR,
}

TRUTH = register_point_function(
    PointFunction(
        name="network-truth",
        function=truth_point,
        inputs=truth_inputs,
        parameters={
            "layout": ParameterSpec(kind="choice", choices=(*LAYOUTS, "baseline")),
            **_PARAMETERS,
        },
        defaults={
            "layout": "series",
            **_DEFAULTS,
        },
        metrics=TRUTH_METRICS,
    )
)


def _parse_design(text: str) -> dict:
    """``name=value,...`` -> element values (the form ``network synthesize`` prints)."""
    out = {}
    for item in str(text).split(","):
        name, eq, value = item.strip().partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise ParameterError("network parameter", item, "name=number") from None
        if not eq:
            raise ParameterError("network parameter", item, "name=number")
    return out


def custom_truth_point(params: Mapping[str, Any]) -> dict[str, float]:
    """:func:`truth_point` for a given network text and element values (``custom``)."""
    c = _car({k: params[k] for k in THESIS_CAR if k in params})
    net, elp = _network_for(
        str(params["network"]), _parse_design(params["design"]), params["variant"], c
    )
    return _truth_metrics(net, elp, c, params)


#: a user's network (e.g. printed by ``inerterlab network synthesize``) as layout
#: ``custom``: its own point function, so the stored layouts keep their keys
CUSTOM_TRUTH = register_point_function(
    PointFunction(
        name="network-truth-custom",
        function=custom_truth_point,
        parameters={
            "network": ParameterSpec(kind="text", doc="network text with an inerter b"),
            "design": ParameterSpec(kind="text", doc="element values name=value,..."),
            **_PARAMETERS,
        },
        defaults={
            "network": "k | (c - b)",
            "design": "k=90000,c=4647,b=641",
            **_DEFAULTS,
        },
        metrics=TRUTH_METRICS,
    )
)


@dataclass(frozen=True)
class TruthResult:
    """The study: the raw dataset and the gains.

    Attributes
    ----------
    dataset : xarray.Dataset
        Metrics over (layout, variant, input) with the baseline in ``baseline``.
    gains : xarray.Dataset
        Percent improvement over the optimised ``k | c`` on the same input (positive:
        better) of every metric.
    survival : xarray.DataArray
        Comfort (Wk RMS) gain of each variant / the ideal inerter's gain in that layout
        and input.
    parameters : dict
        Layout -> the designed element values.
    unread_stores : list of str
        The stores in the study's folder it did not read (of earlier options, layouts or
        code; left in place).
    """

    dataset: Any
    gains: Any
    survival: Any
    parameters: dict
    texts: dict = dataclasses.field(default_factory=dict)
    car: dict = dataclasses.field(default_factory=lambda: dict(THESIS_CAR))
    unread_stores: list = dataclasses.field(default_factory=list)

    def layout_text(self, layout: str) -> str:
        """Network text of a layout (a name of :data:`LAYOUTS` or ``custom``)."""
        return self.texts.get(str(layout), LAYOUTS.get(str(layout), str(layout)))

    def findings(self) -> list[str]:
        """Plain-language conclusions computed from the gains (comfort, Wk RMS)."""
        return _findings(self)

    def to_dict(self) -> dict:
        g = self.gains["rms_body_acc_wk"]
        return {
            "car": self.car,
            "parameters": self.parameters,
            "comfort_gain_percent": {
                lay: {
                    var: {
                        inp: float(g.sel(layout=lay, variant=var, input=inp))
                        for inp in g.input.values
                    }
                    for var in g.variant.values
                }
                for lay in g.layout.values
            },
            "findings": self.findings(),
            "unread_stores": list(self.unread_stores),
        }


def network_truth(
    *,
    layouts=tuple(LAYOUTS),
    variant_list=None,
    inputs=tuple(INPUTS),
    stiffness: float = 90_000.0,
    horizon: float = 10.0,
    seed: int = 1,
    store=None,
    backend: str | None = "serial",
    workers: int | None = None,
    progress=False,
    custom: tuple[str, str] | None = None,
    car: Mapping[str, float] | None = None,
) -> TruthResult:
    """Run the study (see the module docstring) and compute gains and survival.

    ``store``: a folder for the study's sweeps, one Zarr store each
    (``baseline-<key>.zarr``, ``layouts-<key>.zarr``, ``custom-<key>.zarr``), named by a
    digest of the sweep and of the code (:func:`inerterlab.studies.sweep.keyed_store`):
    a rerun resumes them; a changed option, car or code computes the sweeps it changes
    into new stores and leaves the old ones in place. What a point reads besides its
    parameters (:func:`truth_inputs`) is part of the key.

    ``car``: sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping of the quarter
    car (default the thesis car's; any not given keeps the thesis's value).

    ``custom``: (network text, "name=value,...") studied as the layout ``custom`` in
    addition to ``layouts`` (which may then be empty), e.g. a network printed by
    ``inerterlab network synthesize``; its inerter named ``b`` is the one replaced.
    """
    import xarray as xr

    from .studies import sweep, sweep_spec
    from .studies.sweep import keyed_store, unread_stores

    if custom is not None:
        from .networks import parse_network

        net = parse_network(custom[0])
        design = _parse_design(custom[1])
        net.parameter_vector(design)  # every element has a valid value
        if "b" not in design:
            raise ParameterError("network", custom[0], "a network with an inerter named b")
        if not layouts:
            layouts = ()
    for lay in layouts:
        if lay not in LAYOUTS:
            raise ParameterError("layout", lay, f"one of {', '.join(LAYOUTS)}")
    vlist = list(variant_list) if variant_list is not None else variants()
    for v in vlist:
        _parse_variant(v)
    for i in inputs:
        if i not in INPUTS:
            raise ParameterError("input", i, f"one of {', '.join(INPUTS)}")
    c = _car(car)
    from .suspension.network_linear import network_quarter_car

    network_quarter_car("k | c", **c)  # the values checked (positive, physical range)
    settings = {
        "stiffness": float(stiffness),
        "horizon": float(horizon),
        "seed": int(seed),
        **c,
    }
    common = dict(backend=backend, workers=workers, progress=progress)
    if store is not None:
        from pathlib import Path

        from .studies.sweep import claim_store_folder

        # the same rule as every --out of a sweep: only a folder this study made; each
        # sweep's store is keyed on the sweep and the code (as a design study's stages)
        claim_store_folder(
            Path(store), ("layouts.zarr", "custom.zarr", "baseline.zarr"), keyed=True
        )
    # the designs first, in this process: worker processes forked from it inherit them
    # instead of each repeating the H2 optimisations
    params = {lay: layout_parameters(LAYOUTS[lay], float(stiffness), c) for lay in layouts}
    params["baseline"] = layout_parameters(BASELINE, float(stiffness), c)
    # the optimised k | c on each input (one point per input, linear: exact steps), here
    # too: it loads the compiled integrator once for the workers forked after it, and
    # the study starts its worker processes once, not a second time for five points
    read = set()

    def at(name, spec):  # the store of one of the study's sweeps
        if store is None:
            return None
        path = keyed_store(f"{store}/{name}.zarr", spec)
        read.add(path.name)
        return path

    spec = sweep_spec(
        "network-truth",
        parameters={"input": list(inputs)},
        settings={**settings, "layout": "baseline", "variant": "ideal"},
    )
    base = sweep(spec, store=at("baseline", spec), backend="serial")
    parts = []
    if layouts:
        spec = sweep_spec(
            "network-truth",
            parameters={"layout": list(layouts), "variant": vlist, "input": list(inputs)},
            settings=settings,
        )
        parts.append(sweep(spec, store=at("layouts", spec), **common))
    if custom is not None:
        spec = sweep_spec(
            "network-truth-custom",
            parameters={"variant": vlist, "input": list(inputs)},
            settings={**settings, "network": net.text, "design": custom[1]},
        )
        one = sweep(spec, store=at("custom", spec), **common)
        parts.append(one.expand_dims(layout=["custom"]))
    if not parts:
        raise ParameterError("layout", "none", "at least one layout or a custom network")
    ds = parts[0] if len(parts) == 1 else xr.concat(parts, dim="layout")
    failed = int((ds.status != 1).sum()) + int((base.status != 1).sum())
    if failed:
        reasons = sorted({str(r) for r in np.ravel(ds.reason.values) if str(r)})[:3]
        raise ParameterError("study", f"{failed} failed points", f"none failing: {reasons}")
    gains = xr.Dataset({m: 100.0 * (1.0 - ds[m] / base[m]) for m in TRUTH_METRICS})
    ideal = gains["rms_body_acc_wk"].sel(variant="ideal")
    survival = gains["rms_body_acc_wk"] / ideal
    texts = {}
    if custom is not None:
        params["custom"] = design
        texts["custom"] = net.text
    params["baseline"] = params.pop("baseline")  # last, as the tables show it
    ds = ds.assign(baseline=xr.Dataset({m: base[m] for m in TRUTH_METRICS}).to_array("metric"))
    return TruthResult(
        dataset=ds, gains=gains, survival=survival, parameters=params, texts=texts, car=c,
        unread_stores=[] if store is None else unread_stores(store, read),
    )  # fmt: skip


def adaptivity_margin(gains) -> Any:
    """Comfort gain of each adaptive variant minus the better of the two constant
    inerters that bracket its inertance (rest b and saturated b/(1 - x)) [points].

    Positive only where adaptivity itself helps: a flywheel that merely adds inertance
    does no better than the larger constant inerter."""
    g = gains["rms_body_acc_wk"] if hasattr(gains, "data_vars") else gains
    out = {}
    for v in g.variant.values:
        kind, x, _ = _parse_variant(str(v))
        if kind != "afw":
            continue
        big = f"ideal-max x={x:g}"
        if big not in g.variant.values:
            continue
        ref = np.maximum(g.sel(variant="ideal"), g.sel(variant=big))
        out[str(v)] = g.sel(variant=v) - ref
    import xarray as xr

    return xr.concat(list(out.values()), dim="variant").assign_coords(variant=list(out))


def _findings(res: TruthResult) -> list[str]:
    g = res.gains["rms_body_acc_wk"]
    out = []
    has_margin = any(
        str(v).startswith("afw")
        and f"ideal-max x={_parse_variant(str(v))[1]:g}" in g.variant.values
        for v in g.variant.values
    )
    margin = adaptivity_margin(g) if has_margin else None
    for lay in g.layout.values:
        lay = str(lay)
        gi = g.sel(layout=lay, variant="ideal")
        out.append(
            f"{lay} ({res.layout_text(lay)}): the ideal inerter changes comfort by "
            + ", ".join(f"{inp} {float(gi.sel(input=inp)):+.1f} %" for inp in gi.input.values)
            + " against the optimised k | c."
        )
        if margin is not None:
            m = margin.sel(layout=lay)
            flat = int(np.nanargmax(m.values))
            iv, ii = np.unravel_index(flat, m.shape)
            best = float(m.values[iv, ii])
            where = f"{m.variant.values[iv]}, {m.input.values[ii]}"
            if best < 0.5:
                out.append(
                    f"{lay}: adaptivity never helps: every adaptive flywheel is at most "
                    f"{best:+.2f} points better than the better of the two constant "
                    f"inerters bracketing its inertance ({where})."
                )
            else:
                out.append(
                    f"{lay}: adaptivity helps by up to {best:.2f} points over the better "
                    f"bracketing constant inerter ({where}); elsewhere by less."
                )
        for dev in ("hydraulic", "rectifier", "screw", "fluid"):
            if dev not in g.variant.values:
                continue
            gd = g.sel(layout=lay, variant=dev)
            text = ", ".join(f"{inp} {float(gd.sel(input=inp)):+.1f} %" for inp in gd.input.values)
            good = [str(i) for i in gi.input.values if float(gi.sel(input=i)) >= 1.0]
            if good:
                surv = ", ".join(
                    f"{i} {float(res.survival.sel(layout=lay, variant=dev, input=i)):+.2f}"
                    for i in good
                )
                text += f"; share of the ideal gain kept where there is one: {surv}"
            out.append(f"{lay}: the {dev} device gives {text}.")
    return out


def truth_figure(res: TruthResult):
    """Comfort gain [%] against the optimised k | c, one panel per layout: lines over the
    changing ratio for each adaptive-flywheel law, markers for the other variants."""
    from matplotlib.figure import Figure

    g = res.gains["rms_body_acc_wk"]
    lays = [str(v) for v in g.layout.values]
    fig = Figure(figsize=(4.2 * len(lays), 3.6), layout="constrained")
    axes = fig.subplots(1, len(lays), squeeze=False)[0]
    for ax, lay in zip(axes, lays, strict=True):
        for inp in g.input.values:
            gi = g.sel(layout=lay, input=inp)
            line = None
            for law in LAWS:
                names = [v for v in gi.variant.values if str(v).endswith(f"law={law}")]
                if not names:
                    continue
                xs = [float(str(v).split("x=")[1].split()[0]) for v in names]
                style = {"thesis": "-", "momentum": "--"}.get(law, ":")
                kw = {"color": line.get_color()} if line is not None else {}
                (line,) = ax.plot(xs, gi.sel(variant=names).values, style, marker="o", ms=3,
                                  label=f"{inp} afw {law}", **kw)  # fmt: skip
            color = line.get_color() if line is not None else None
            ax.axhline(float(gi.sel(variant="ideal")), color=color, lw=0.8, ls=":")
        ax.set_title(f"{lay}: {res.layout_text(lay)}", fontsize=9)
        ax.set_xlabel("changing ratio x [-]")
        ax.set_ylabel("comfort gain vs k | c [%]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=6)
    return fig
