"""The ``quarter-car`` point function: build the quarter car from the swept parameters,
simulate one input and return the metrics of :meth:`SimulationResult.metrics`.

Importing this module registers the point function. The simulator modules are imported
inside the function, so workers pay for them once and the sweep description can be
validated without them.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import Any

from .points import QUARTER_CAR_METRICS, ParameterSpec, PointFunction, register_point_function

__all__ = ["quarter_car_point", "QUARTER_CAR"]

_POS = {"low": 0.0, "low_open": True}


#: the parameters of each road input (keys of a point)
_INPUT_KEYS = {
    "drop": ("input_height",),
    "bump": ("input_height", "bump_duration", "bump_shape", "bump_edge", "bump_edge_width"),
    "sine": ("input_height", "sine_frequency"),
    "iso8608": ("road_class", "road_speed", "seed"),
}
#: the parameters of the car (the keywords of describe_quarter_car)
_CAR_KEYS = (
    "suspension", "sprung_mass", "unsprung_mass", "stiffness", "damping", "tyre_stiffness",
    "tyre_damping", "flywheel", "flywheel_law", "changing_ratio", "law",
)  # fmt: skip
_INPUT_DEFAULTS = {"bump_edge": "step", "bump_edge_width": 0.0}


def _excitation(params: Mapping[str, Any]):
    name = params["input"]
    keys = _INPUT_KEYS.get(name, _INPUT_KEYS["iso8608"])
    return _excitation_of(name, tuple(params.get(k, _INPUT_DEFAULTS.get(k)) for k in keys))


@functools.lru_cache(maxsize=64)
def _excitation_of(name: str, values: tuple):
    """The road input (immutable), kept for the last few: a worker's points share few."""
    from .. import excitation as ex

    if name == "drop":
        return ex.drop(*values)
    if name == "bump":
        height, duration, shape, edge, width = values
        return ex.bump(height, duration=duration, shape=shape, edge=edge, edge_width=width)
    if name == "sine":
        return ex.sine(*values)
    road_class, speed, seed = values
    return ex.iso8608(road_class, speed, seed=int(seed))


@functools.lru_cache(maxsize=64)
def _model(values: tuple):
    """The car's description (immutable) from the values of :data:`_CAR_KEYS`, kept for
    the last few: a sweep over the inputs of one car describes it once."""
    from ..suspension.model import describe_quarter_car

    p = dict(zip(_CAR_KEYS, values, strict=True))
    if p["suspension"] not in ("afw", "device-afw"):
        p["changing_ratio"] = None  # applies to the adaptive flywheel only
    return describe_quarter_car(p.pop("suspension"), **p)


def quarter_car_point(params: Mapping[str, Any]) -> dict[str, float]:
    """Simulate the quarter car described by ``params`` and return its metrics.

    Keys: see :data:`QUARTER_CAR`. ``changing_ratio`` applies to ``afw`` and
    ``device-afw`` only (the other suspensions ignore it).
    """
    from .. import simulate as sim

    # the description alone (simulate_metrics builds the core system from it, once per
    # car: systems.quarter_car.system_of), metrics only: no sampled series
    model = _model(tuple(params[k] for k in _CAR_KEYS))
    metrics = sim.simulate_metrics(model, _excitation(params), params["horizon"])
    # None stays None: not finite across a road step (SimulationResult.not_finite)
    return {
        k: (None if metrics[k] is None else float(metrics[k])) for k in QUARTER_CAR_METRICS
    }


QUARTER_CAR = register_point_function(
    PointFunction(
        name="quarter-car",
        function=quarter_car_point,
        parameters={
            "suspension": ParameterSpec(
                kind="choice",
                choices=("traditional", "cfw", "afw", "device", "device-afw"),
                doc="suspension layout (docs/model.md §5)",
            ),
            "input": ParameterSpec(
                kind="choice", choices=("drop", "bump", "sine", "iso8608"), doc="road input"
            ),
            "sprung_mass": ParameterSpec(**_POS, unit="kg", doc="body mass M_v"),
            "unsprung_mass": ParameterSpec(**_POS, unit="kg", doc="wheel mass M_t"),
            "stiffness": ParameterSpec(**_POS, unit="N/m", doc="suspension spring K"),
            "damping": ParameterSpec(low=0.0, unit="N s/m", doc="suspension damper C"),
            "tyre_stiffness": ParameterSpec(**_POS, unit="N/m", doc="tyre K_t"),
            "tyre_damping": ParameterSpec(low=0.0, unit="N s/m", doc="tyre C_t"),
            "changing_ratio": ParameterSpec(
                low=0.0, high=1.0, low_open=True, high_open=True, doc="changing ratio x"
            ),
            "flywheel": ParameterSpec(
                kind="choice", choices=("metal", "nylon", "nylon-large"), doc="flywheel preset"
            ),
            "flywheel_law": ParameterSpec(
                kind="choice", choices=("published", "geometry", "thesis-literal")
            ),
            "law": ParameterSpec(
                kind="choice", choices=("thesis", "momentum", "slider-dynamics"), doc="inertia law"
            ),
            "horizon": ParameterSpec(**_POS, high=3600.0, unit="s", doc="simulated time"),
            "input_height": ParameterSpec(**_POS, high=1.0, unit="m", doc="drop/bump/sine size"),
            "bump_duration": ParameterSpec(**_POS, high=10.0, unit="s"),
            "bump_shape": ParameterSpec(kind="choice", choices=("rectangular", "1-cos")),
            "bump_edge": ParameterSpec(
                kind="choice", choices=("step", "ramp", "half-cosine"), doc="bump edge shape"
            ),
            "bump_edge_width": ParameterSpec(
                low=0.0, high=10.0, unit="s", doc="width of each smoothed bump edge"
            ),
            "sine_frequency": ParameterSpec(**_POS, high=1000.0, unit="Hz"),
            "road_class": ParameterSpec(kind="choice", choices=tuple("ABCDEFGH")),
            "road_speed": ParameterSpec(**_POS, high=100.0, unit="m/s"),
            "seed": ParameterSpec(kind="int", low=0.0, doc="random-road seed"),
        },
        defaults={
            "suspension": "afw",
            "input": "drop",
            "sprung_mass": 370.0,
            "unsprung_mass": 25.0,
            "stiffness": 90_000.0,
            "damping": 5000.0,
            "tyre_stiffness": 120_000.0,
            "tyre_damping": 1300.0,
            "changing_ratio": None,  # None: the preset's own ratio (nylon: 28.5 %)
            "flywheel": "nylon",
            "flywheel_law": "published",
            "law": "thesis",
            "horizon": 10.0,
            "input_height": 0.05,
            "bump_duration": 0.01,
            "bump_shape": "rectangular",
            "bump_edge": "step",
            "bump_edge_width": 0.0,
            "sine_frequency": 5.0,
            "road_class": "C",
            "road_speed": 20.0,
            "seed": 0,
        },
        metrics=QUARTER_CAR_METRICS,
    )
)
