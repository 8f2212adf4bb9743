"""The quarter car: sprung and unsprung masses, a tyre spring and damper to the road (the
tyre element, which lifts off, with ``tyre_lift_off=True``), and any network between
wheel and body (docs/model.md §5 and §11).

:func:`quarter_car` is the one way to build one. A named suspension of the thesis
(:data:`SUSPENSIONS`) is a network of the model core (:data:`QUARTER_CAR_PRESETS`) whose
element values come from the suspension's description
(:class:`~inerterlab.suspension.model.QuarterCar`: masses, spring, damper, flywheel,
transmission, force law, device); any other text is read as a network.
"""

from __future__ import annotations

import re
from functools import lru_cache
from typing import Any

from ..elements.damper import Damper
from ..elements.spring import Spring
from ..elements.tyre import Tyre
from ..errors import NetworkError, ParameterError
from ..suspension.model import SUSPENSIONS
from ._network import Layout, elements_of

__all__ = ["quarter_car", "SUSPENSIONS", "QUARTER_CAR_PRESETS", "preset_network", "system_of"]


#: the network of each named suspension between body (top) and wheel (bottom): ``k`` the
#: suspension spring, ``c`` its damper, ``b`` the constant-flywheel inerter, ``afw`` the
#: adaptive flywheel on the ideal device, ``hyd`` the real hydraulic device (system A
#: without flywheel, system B with it)
QUARTER_CAR_PRESETS = {
    "traditional": "k | c",
    "cfw": "k | c | b",
    "afw": "k | c | afw",
    "device": "k | c | hyd",
    "device-afw": "k | c | hyd",
}

#: the car's own values (keywords of :func:`quarter_car`)
CAR_VALUES = (
    "sprung_mass", "unsprung_mass", "stiffness", "damping", "tyre_stiffness", "tyre_damping",
    "gravity",
)  # fmt: skip


#: options of a named suspension (keywords of :func:`quarter_car`)
PRESET_OPTIONS = (
    "flywheel", "flywheel_law", "changing_ratio", "law", "inertia", "inertance",
    "transmission", "device", "friction_velocity", "slider", "tyre_lift_off",
)  # fmt: skip


def preset_network(model) -> tuple[str, dict]:
    """(network text, element objects by name) of a named suspension's description
    (:class:`~inerterlab.suspension.model.QuarterCar`)."""
    from ..elements import AdaptiveFlywheelInerter, HydraulicElement, Inerter

    q = model.parameters
    els: dict[str, Any] = {"k": q.stiffness, "c": q.damping}
    s = model.suspension
    if s == "cfw":
        els["b"] = Inerter(inertance=model.inertance)
    elif s == "afw":
        els["afw"] = AdaptiveFlywheelInerter(
            flywheel=model.flywheel, ratio=model.transmission.ratio, law=model.law,
            slider=model.slider or AdaptiveFlywheelInerter().slider,
        )  # fmt: skip
    elif s in ("device", "device-afw"):
        d = model.device
        kw: dict[str, Any] = {"flywheel": "none"}
        if s == "device-afw":
            if model.slider is not None and model.slider != AdaptiveFlywheelInerter().slider:
                raise ParameterError(
                    "slider", model.slider, "the default SliderDynamics for device-afw"
                )
            kw = {"flywheel": model.flywheel, "ratio": model.transmission.ratio, "law": model.law}
        els["hyd"] = HydraulicElement(
            stiffness=d.stiffness, damping=d.damping, friction=d.friction,
            friction_velocity=d.friction_velocity, **kw,
        )  # fmt: skip
    return QUARTER_CAR_PRESETS[s], els


def quarter_car(
    suspension: str = "afw",
    params: dict | None = None,
    *,
    sprung_mass: float | None = None,
    unsprung_mass: float | None = None,
    stiffness: float | None = None,
    damping: float | None = None,
    tyre_stiffness: float | None = None,
    tyre_damping: float | None = None,
    gravity: float | None = None,
    parameters=None,
    **preset: Any,
):
    """A quarter car with a named suspension or any network between body and wheel.

    Parameters
    ----------
    suspension : str
        A named suspension of :data:`SUSPENSIONS` (``traditional`` (4.1); ``cfw``,
        constant flywheel on the ideal hydraulic device (4.4); ``afw``, adaptive
        flywheel on the ideal device (4.8); ``device``, system A (6.1);
        ``device-afw``, system B (6.2)), or a network text such as
        ``"k | (c - afw)"`` (docs/model.md §11).
    params : dict, optional
        Element values by name: those of a network text, or values that replace a
        named suspension's (``{"c": 4000}``).
    sprung_mass, unsprung_mass : float
        M and M_t [kg] (defaults 370 and 25, thesis (4.16)).
    stiffness, damping : float
        K [N/m] and C [N s/m] of a named suspension (defaults 90 000 and 5000); a
        network gives its own elements' values.
    tyre_stiffness, tyre_damping : float
        K_t [N/m] and C_t [N s/m] (defaults 120 000 and 1300; C_t may be 0).
    gravity : float
        g [m/s^2] (tyre grip index and static load), default 9.81.
    parameters : QuarterCarParameters, optional
        All the car values at once instead of the keywords above.
    **preset
        Options of a named suspension: ``flywheel`` (preset name or
        :class:`~inerterlab.flywheels.AdaptiveFlywheel`), ``flywheel_law``,
        ``changing_ratio``, ``law`` (``thesis``, ``momentum``, ``slider-dynamics``),
        ``inertia`` / ``inertance`` (cfw), ``transmission``, ``device``
        (:class:`~inerterlab.suspension.parameters.HydraulicDeviceParameters`),
        ``friction_velocity``, ``slider``, ``tyre_lift_off``.

    Returns
    -------
    System
        A core system (:class:`inerterlab.systems.System`, kind ``quarter_car``);
        ``system.info["model"]`` holds the description of a named suspension.

    Examples
    --------
    >>> car = quarter_car("afw", sprung_mass=370, changing_ratio=0.3)
    >>> car.state_names
    ('wheel.x', 'wheel.v', 'body.x', 'body.v')
    >>> round(car.info["model"].inertance, 1)
    206.2
    >>> quarter_car("k | (c - b)", {"k": 9e4, "c": 5e3, "b": 200}, sprung_mass=340).linear
    True
    """
    from ..suspension.model import describe_quarter_car
    from ..suspension.parameters import QuarterCarParameters

    given = dict(
        sprung_mass=sprung_mass, unsprung_mass=unsprung_mass, stiffness=stiffness,
        damping=damping, tyre_stiffness=tyre_stiffness, tyre_damping=tyre_damping,
        gravity=gravity,
    )  # fmt: skip
    given = {k: v for k, v in given.items() if v is not None}
    if parameters is not None:
        if given:
            k = next(iter(given))
            raise ParameterError(k, given[k], "no value with parameters= (give one or the other)")
        if not isinstance(parameters, QuarterCarParameters):
            raise ParameterError("parameters", parameters, "a QuarterCarParameters")
    if not isinstance(suspension, str):
        raise ParameterError(
            "suspension", suspension, f"one of {', '.join(SUSPENSIONS)} or a network text"
        )
    unknown = sorted(set(preset) - set(PRESET_OPTIONS))
    if unknown:
        raise ParameterError(unknown[0], preset[unknown[0]], f"one of {', '.join(PRESET_OPTIONS)}")
    if suspension in SUSPENSIONS:
        model = describe_quarter_car(suspension, parameters=parameters, **given, **preset)
        text, els = preset_network(model)
        for key, v in (params or {}).items():
            els[key] = v
        info = {"model": model}
    else:
        given_preset = {k: v for k, v in preset.items() if v is not None}
        if given_preset:
            k = next(iter(given_preset))
            if re.fullmatch(r"\s*[A-Za-z_][\w.-]*\s*", suspension) and not params:
                raise ParameterError(
                    "suspension", suspension, f"one of {', '.join(SUSPENSIONS)} or a network text"
                )
            raise ParameterError(k, preset[k], "no value: only the named suspensions take it")
        for k in ("stiffness", "damping"):
            if k in given:
                raise ParameterError(
                    k, given[k], "no value with a network (give its elements' values in params)"
                )
        model = None
        text, els = suspension, params
        info = {}
    car = parameters if parameters is not None else QuarterCarParameters(**given)
    try:
        return _build(text, els, car, f"quarter car with {suspension!r}", info)
    except NetworkError as exc:
        if model is None and re.fullmatch(r"\s*[A-Za-z_][\w.-]*\s*", text) and not params:
            # one bare word with no values: most likely a misspelt suspension name
            raise ParameterError(
                "suspension", suspension, f"one of {', '.join(SUSPENSIONS)} or a network text "
                f"with its element values ({exc})",
            ) from None  # fmt: skip
        raise


def _build(text: str, params, car, description: str, info: dict):
    """The core system of ``text`` between body and wheel on the car values ``car``."""
    from .core import _laid_out

    c = dict(
        sprung_mass=car.sprung_mass, unsprung_mass=car.unsprung_mass,
        tyre_stiffness=car.tyre_stiffness, tyre_damping=car.tyre_damping, gravity=car.gravity,
    )  # fmt: skip
    tree, els = elements_of(text, params)

    model = info.get("model")
    lift_off = model is not None and model.tyre_lift_off

    def make(arrange):
        lay = Layout(arrange)
        road = lay.node("road", "road")
        wheel = lay.node("wheel", "mass", c["unsprung_mass"])
        body = lay.node("body", "mass", c["sprung_mass"])
        if lift_off:  # the tyre that cannot pull: its kink is an event
            load = (c["sprung_mass"] + c["unsprung_mass"]) * c["gravity"]
            tyre = Tyre(stiffness=c["tyre_stiffness"], damping=c["tyre_damping"], static_load=load)
            lay.edges.append(("tyre", tyre, wheel, road))
        else:
            lay.edges.append(("tyre_k", Spring(stiffness=c["tyre_stiffness"]), wheel, road))
            if c["tyre_damping"] > 0:
                lay.edges.append(("tyre_c", Damper(damping=c["tyre_damping"]), wheel, road))
        lay.place(tree, body, wheel, els)
        return lay

    # whether the tyre can pull the wheel with a damper force (a Dirac at a road step down)
    pulls = c["tyre_damping"] > 0 and not lift_off
    return _laid_out(
        "quarter_car", description, make, {"network": text, "car": c, "tyre_pulls": pulls, **info}
    )[0]


@lru_cache(maxsize=64)
def system_of(model):
    """The core system of a named suspension's description
    (:class:`~inerterlab.suspension.model.QuarterCar`), as :func:`quarter_car` builds it;
    kept for the last few descriptions (a sweep over inputs or seeds builds it once)."""
    text, els = preset_network(model)
    return _build(text, els, model.parameters, f"quarter car with {model.suspension!r}",
                  {"model": model})  # fmt: skip
