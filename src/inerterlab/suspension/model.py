"""Quarter-car models: which suspension, which device, which inertia law.

States (docs/model.md §5): the road X1 is an input; X2 is the unsprung mass, X3 the sprung
mass, both measured from static equilibrium (gravity only enters the tyre grip index
and the lift-off test). Every model carries the core states ``[X2, V2, X3, V3]``
followed by the states of its device:

========================= ======================================================
suspension                extra states
========================= ======================================================
``traditional`` (4.1)     none
``cfw`` (4.4)             none (constant inertance r^2 I)
``afw`` (4.8)             none; ``slider-dynamics`` law: slider radius l, rate l'
``device`` (6.1)          x_k, deflection of the device's series spring k_h
``device-afw`` (6.2)      x_k and the branch velocity u; plus l, l' for
                          ``slider-dynamics``
========================= ======================================================

Forces (suspension deflection z = X3 - X2, its rate v = V3 - V2):

* suspension spring and damper, F_s = K z + C v, pushes the masses apart;
* ideal inerter (``cfw``, ``afw``): F_b = m_e (a3 - a2) with the law's inertance
  m_e = r^2 I(r|v|) (``thesis``, (4.8)-(4.11) with the r^2 that (4.10), (4.11) omit),
  r^2 (I + |omega| dI/d|omega|) (``momentum``) or r^2 (I_rest + n m_s l^2) plus the
  Coriolis term 2 n m_s r^2 l l' v (``slider-dynamics``). The accelerations are then
  implicit; the 2x2 system reduces to one scalar equation for a3 - a2;
* real device (``device``, ``device-afw``): the series spring carries
  F_d = k_h x_k = m_e(u) u' + b_ah u + F_fh tanh(u / v_eps) with u = v - x_k' the
  velocity through the branch ((6.1), (6.2); system A has no inertance). The thesis
  writes the friction of (6.1) with sgn(X3 - X2) and drops the sign in (6.2); both
  use the sign of the branch velocity u here (docs/model.md §5);
* tyre, F_t = K_t (X2 - X1) + C_t (V2 - X1'). With ``tyre_lift_off=True`` the tyre
  cannot pull: F_t is capped at the static load (M + M_t) g, where the contact force
  reaches zero.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..errors import ParameterError, check_choice, check_positive
from ..flywheels import AdaptiveFlywheel, constant_flywheel
from ..flywheels import flywheel as make_flywheel
from ..slider_dynamics import SliderDynamics
from ..transmissions import Transmission
from ..transmissions import transmission as make_transmission
from .parameters import GRAVITY, HydraulicDeviceParameters, QuarterCarParameters

__all__ = [
    "QuarterCar",
    "describe_quarter_car",
    "SUSPENSIONS",
    "LAWS",
    "CFW_INERTIA",
    "model_of",
]

SUSPENSIONS = ("traditional", "cfw", "afw", "device", "device-afw")
LAWS = ("thesis", "momentum", "slider-dynamics")
CFW_INERTIA = 2.231e-4  # [kg m^2], I_afn,min of ch. 4.2.1, the constant flywheel



@dataclass(frozen=True, kw_only=True)
class QuarterCar:
    """A quarter car with one of the suspensions of docs/model.md §5.

    Build it with :func:`inerterlab.quarter_car` (its ``info["model"]``) or
    :func:`describe_quarter_car`; derive variants with ``dataclasses.replace``.

    Parameters
    ----------
    suspension : {"traditional", "cfw", "afw", "device", "device-afw"}
    parameters : QuarterCarParameters
        Masses, suspension spring and damper, tyre.
    flywheel : AdaptiveFlywheel or None
        Needed by ``cfw``, ``afw`` and ``device-afw``. For ``cfw`` its minimum inertia is
        used as a constant.
    transmission : Transmission or None
        Linear-to-rotary ratio r [rad/m] of the device (hydraulic, 961.66 rad/m).
    law : {"thesis", "momentum", "slider-dynamics"}
        How the speed-dependent inertia makes a force (docs/model.md §2). Irrelevant for
        ``traditional``, ``cfw`` and ``device``.
    device : HydraulicDeviceParameters or None
        Needed by ``device`` and ``device-afw``.
    slider : SliderDynamics or None
        Options of the ``slider-dynamics`` law (default options if None).
    tyre_lift_off : bool
        If True the tyre cannot pull on the road (off by default, as in the thesis).
    """

    suspension: str
    parameters: QuarterCarParameters = QuarterCarParameters()
    flywheel: AdaptiveFlywheel | None = None
    transmission: Transmission | None = None
    law: str = "thesis"
    device: HydraulicDeviceParameters | None = None
    slider: SliderDynamics | None = None
    tyre_lift_off: bool = False

    def __post_init__(self) -> None:
        check_choice("suspension", self.suspension, SUSPENSIONS)
        check_choice("law", self.law, LAWS)
        if not isinstance(self.parameters, QuarterCarParameters):
            raise ParameterError("parameters", self.parameters, "a QuarterCarParameters")
        if self.uses_flywheel:
            if not isinstance(self.flywheel, AdaptiveFlywheel):
                raise ParameterError(
                    "flywheel",
                    self.flywheel,
                    f"an AdaptiveFlywheel for suspension {self.suspension!r}",
                )
            if not isinstance(self.transmission, Transmission):
                raise ParameterError(
                    "transmission",
                    self.transmission,
                    f"a Transmission for suspension {self.suspension!r}",
                )
        if self.suspension in ("device", "device-afw") and not isinstance(
            self.device, HydraulicDeviceParameters
        ):
            raise ParameterError(
                "device", self.device, f"HydraulicDeviceParameters for {self.suspension!r}"
            )
        if self.effective_law == "slider-dynamics" and self.flywheel.power != 2:
            raise ParameterError(
                "law", self.law, "'thesis' or 'momentum' for a thesis-literal (power 1) flywheel"
            )
        if not isinstance(self.tyre_lift_off, bool):
            raise ParameterError("tyre_lift_off", self.tyre_lift_off, "True or False")

    # -- structure ---------------------------------------------------------------
    @property
    def uses_flywheel(self) -> bool:
        """True for the suspensions with an inerter (cfw, afw, device-afw)."""
        return self.suspension in ("cfw", "afw", "device-afw")

    @property
    def effective_law(self) -> str:
        """The law actually integrated: ``constant`` for cfw, ``none`` without flywheel."""
        if self.suspension == "cfw":
            return "constant"
        if not self.uses_flywheel:
            return "none"
        return self.law

    @property
    def is_linear(self) -> bool:
        """True if the equations are linear (traditional, cfw, no lift-off)."""
        return self.suspension in ("traditional", "cfw") and not self.tyre_lift_off

    @property
    def inertance(self) -> float | None:
        """r^2 I_min [kg]: the constant inertance (cfw) or the rest inertance."""
        if not self.uses_flywheel:
            return None
        return self.transmission.ratio**2 * self.flywheel.inertia_min

    def describe(self) -> dict:
        """Settings as a plain dict (for reports and file headers)."""
        out = {"suspension": self.suspension, **dataclasses.asdict(self.parameters)}
        if self.uses_flywheel:
            out.update(
                flywheel=self.flywheel.name,
                law=self.effective_law,
                inertance_min=self.inertance,
                changing_ratio=self.flywheel.changing_ratio,
                transmission_ratio=self.transmission.ratio,
            )
        if self.device is not None:
            out.update({f"device_{k}": v for k, v in dataclasses.asdict(self.device).items()})
        out["tyre_lift_off"] = self.tyre_lift_off
        return out


def describe_quarter_car(
    suspension: str = "afw",
    *,
    sprung_mass: float = 370.0,
    unsprung_mass: float = 25.0,
    stiffness: float = 90_000.0,
    damping: float = 5000.0,
    tyre_stiffness: float = 120_000.0,
    tyre_damping: float = 1300.0,
    gravity: float = GRAVITY,
    flywheel: str | AdaptiveFlywheel = "nylon",
    flywheel_law: str = "published",
    changing_ratio: float | None = None,
    law: str = "thesis",
    inertia: float | None = None,
    inertance: float | None = None,
    transmission: str | Transmission = "hydraulic",
    device: HydraulicDeviceParameters | None = None,
    friction_velocity: float | None = None,
    slider: SliderDynamics | None = None,
    tyre_lift_off: bool = False,
    parameters: QuarterCarParameters | None = None,
) -> QuarterCar:
    """The description of a named thesis quarter car (docs/model.md §5, base values
    (4.16)): what :func:`inerterlab.quarter_car` builds its network from.

    Parameters
    ----------
    suspension : {"traditional", "cfw", "afw", "device", "device-afw"}
        ``traditional`` (4.1); ``cfw``, constant flywheel on the ideal hydraulic device
        (4.4); ``afw``, adaptive flywheel on the ideal device (4.8); ``device``, system
        A (6.1); ``device-afw``, system B (6.2).
    sprung_mass, unsprung_mass : float
        M and M_t [kg] (ignored if ``parameters`` is given).
    stiffness, damping, tyre_stiffness, tyre_damping : float
        K [N/m], C [N s/m], K_t [N/m], C_t [N s/m].
    gravity : float
        g [m/s^2].
    flywheel : str or AdaptiveFlywheel
        Preset name (``nylon`` in the thesis) or a flywheel.
    flywheel_law : str
        Inertia law of a preset (``published``, ``geometry``, ``thesis-literal``).
    changing_ratio : float, optional
        Use the variant with this changing ratio x in (0, 1) (docs/model.md §1).
    law : {"thesis", "momentum", "slider-dynamics"}
        Force law of a speed-dependent inertia (docs/model.md §2); ``thesis`` by default.
    inertia : float, optional
        ``cfw`` only: the constant inertia [kg m^2], default 2.231e-4 (ch. 4.2.1).
    inertance : float, optional
        ``cfw`` only: the constant inertance b = r^2 I [kg] instead of ``inertia``.
    transmission : str or Transmission
        ``hydraulic`` (r = 961.66 rad/m) by default.
    device : HydraulicDeviceParameters, optional
        Real-device parameters for ``device`` / ``device-afw`` (identified values by
        default).
    friction_velocity : float, optional
        Shortcut for the device's friction smoothing velocity v_eps [m/s].
    slider : SliderDynamics, optional
        Options of the ``slider-dynamics`` law.
    tyre_lift_off : bool
        Let the tyre leave the road instead of pulling on it.
    parameters : QuarterCarParameters, optional
        Use these instead of the individual values.

    Examples
    --------
    >>> car = describe_quarter_car("afw", sprung_mass=370, changing_ratio=0.3)
    >>> round(car.flywheel.changing_ratio, 3), round(car.inertance, 1)
    (0.3, 206.2)
    >>> describe_quarter_car("cfw").inertance > 206
    True
    """
    check_choice("suspension", suspension, SUSPENSIONS)
    if parameters is None:
        parameters = QuarterCarParameters(
            sprung_mass=sprung_mass,
            unsprung_mass=unsprung_mass,
            stiffness=stiffness,
            damping=damping,
            tyre_stiffness=tyre_stiffness,
            tyre_damping=tyre_damping,
            gravity=gravity,
        )
    fw = tr = dev = None
    if suspension in ("cfw", "afw", "device-afw"):
        tr = make_transmission(transmission) if isinstance(transmission, str) else transmission
        if suspension == "cfw":
            if inertance is not None:
                b = check_positive("inertance", inertance, "kg")
                fw = constant_flywheel(b / tr.ratio**2, name="constant")
            else:
                i = CFW_INERTIA if inertia is None else inertia
                fw = constant_flywheel(i, name="constant")
        else:
            fw = (
                make_flywheel(flywheel, law=flywheel_law) if isinstance(flywheel, str) else flywheel
            )
            if changing_ratio is not None:
                fw = fw.with_changing_ratio(changing_ratio)
    if (inertia is not None or inertance is not None) and suspension != "cfw":
        raise ParameterError(
            "inertance" if inertance is not None else "inertia",
            inertance if inertance is not None else inertia,
            "no value: only the cfw suspension has a constant inertance",
        )
    if changing_ratio is not None and suspension not in ("afw", "device-afw"):
        raise ParameterError(
            "changing_ratio", changing_ratio, "no value: only afw and device-afw adapt"
        )
    if suspension in ("device", "device-afw"):
        dev = device or HydraulicDeviceParameters()
        if friction_velocity is not None:
            dev = dataclasses.replace(dev, friction_velocity=friction_velocity)
    elif friction_velocity is not None:
        raise ParameterError(
            "friction_velocity",
            friction_velocity,
            "no value: only device suspensions have friction",
        )
    return QuarterCar(
        suspension=suspension,
        parameters=parameters,
        flywheel=fw,
        transmission=tr,
        law=law,
        device=dev,
        slider=slider,
        tyre_lift_off=tyre_lift_off,
    )


def model_of(model) -> QuarterCar:
    """The description of a named quarter car: from the core system
    :func:`inerterlab.quarter_car` builds (its ``info["model"]``) or given as is."""
    from ..systems import System

    if isinstance(model, System) and isinstance(model.info.get("model"), QuarterCar):
        return model.info["model"]
    if isinstance(model, QuarterCar):
        return model
    if isinstance(model, System) and model.kind == "quarter_car":
        raise ParameterError(
            "model", model.description, "a named suspension (inerterlab.quarter_car('afw', "
            "...)); a quarter car with a network text runs on its own simulate(...)",
        )  # fmt: skip
    raise ParameterError("model", model, "a quarter car (see inerterlab.quarter_car)")
