"""The ``quarter-car`` point function: build the quarter car from the swept parameters,
simulate one input and return the metrics of :meth:`SimulationResult.metrics`.

Importing this module registers the point function. The simulator modules are imported
inside the function, so workers pay for them once and the sweep description can be
validated without them.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .points import QUARTER_CAR_METRICS, ParameterSpec, PointFunction, register_point_function

__all__ = ["quarter_car_point", "QUARTER_CAR"]

_POS = {"low": 0.0, "low_open": True}


def _excitation(params: Mapping[str, Any]):
    from .. import excitation as ex

    name = params["input"]
    if name == "drop":
        return ex.drop(params["input_height"])
    if name == "bump":
        return ex.bump(
            params["input_height"],
            duration=params["bump_duration"],
            shape=params["bump_shape"],
            edge=params.get("bump_edge", "step"),
            edge_width=params.get("bump_edge_width", 0.0),
        )
    if name == "sine":
        return ex.sine(params["input_height"], params["sine_frequency"])
    return ex.iso8608(params["road_class"], params["road_speed"], seed=int(params["seed"]))


def quarter_car_point(params: Mapping[str, Any]) -> dict[str, float]:
    """Simulate the quarter car described by ``params`` and return its metrics.

    Keys: see :data:`QUARTER_CAR`. ``changing_ratio`` applies to ``afw`` and
    ``device-afw`` only (the other suspensions ignore it).
    """
    from .. import simulate as sim
    from ..suspension.model import describe_quarter_car

    suspension = params["suspension"]
    adaptive = suspension in ("afw", "device-afw")
    # the description alone: simulate() integrates a named suspension from it, and a
    # sweep point should not pay for the core system (0.5-1 ms to build)
    model = describe_quarter_car(
        suspension,
        sprung_mass=params["sprung_mass"],
        unsprung_mass=params["unsprung_mass"],
        stiffness=params["stiffness"],
        damping=params["damping"],
        tyre_stiffness=params["tyre_stiffness"],
        tyre_damping=params["tyre_damping"],
        flywheel=params["flywheel"],
        flywheel_law=params["flywheel_law"],
        changing_ratio=params["changing_ratio"] if adaptive else None,
        law=params["law"],
    )
    fast = getattr(sim, "simulate_metrics", None)  # metrics-only path, no stored series
    if fast is not None:
        metrics = fast(model, _excitation(params), params["horizon"])
    else:
        metrics = sim.simulate(model, _excitation(params), params["horizon"]).metrics()
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
