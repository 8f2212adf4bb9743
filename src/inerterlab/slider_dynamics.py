"""The ``slider-dynamics`` force law: sliders as their own degree of freedom.

All ``n`` sliders move together (symmetry), so one radius ``l`` and its rate describe
them. With the flywheel speed ``omega`` [rad/s]:

    m_s l'' = m_s l omega^2 - k_s (l - l_min) - c_s l' + f_stop             (slider)
    T = d/dt[(I_rest + n m_s l^2) omega]
      = (I_rest + n m_s l^2) omega' + 2 n m_s l l' omega                   (rotor)

The end stops at ``l_min`` and ``l_max`` are stiff spring-dashpot contacts: with
penetration d >= 0, the stop pushes back with max(0, k_c d + c_c d'), a force that never
pulls. ``c_c`` follows from a coefficient of restitution ``e`` of the linear contact,
zeta = -ln e / sqrt(pi^2 + ln^2 e), c_c = 2 zeta sqrt(k_c m_s).

Energy: with E = 1/2 J omega^2 + 1/2 n m_s l'^2 + 1/2 n k_s (l - l_min)^2 + 1/2 n k_c d^2,
dE/dt = T omega - D where D = n [c_s l'^2 + (f_c - k_c d) d'] >= 0 is the dissipated power.
:func:`slider_state_derivative` returns D so an integrator can carry the dissipated
energy as a state and the energy balance can be checked to solver tolerance.

The kernels are numba-compiled scalar functions taking plain floats, so a model's
right-hand side (device, quarter car, harmonic balance) can call them from its own
compiled code.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb

from .errors import ParameterError, check_in_range, check_nonnegative, check_positive
from .flywheels import AdaptiveFlywheel

__all__ = [
    "SliderDynamics",
    "slider_state_derivative",
    "stored_energy",
]


@dataclass(frozen=True, kw_only=True)
class SliderDynamics:
    """Options of the ``slider-dynamics`` law.

    Parameters
    ----------
    damping_ratio : float
        Viscous damping of a slider in its slot as a fraction of critical,
        c_s = 2 zeta sqrt(k_s m_s) [-]. The thesis neglects slot friction; a small
        value (default 0.1) keeps the sliders from ringing forever.
    contact_stiffness : float
        k_c [N/m] of the end stops.
    restitution : float
        Coefficient of restitution e in (0, 1] of an impact on a stop.
    """

    damping_ratio: float = 0.1
    contact_stiffness: float = 1.0e5
    restitution: float = 0.5

    def __post_init__(self) -> None:
        check_nonnegative("damping_ratio", self.damping_ratio)
        check_positive("contact_stiffness", self.contact_stiffness, "N/m")
        check_in_range("restitution", self.restitution, 0.0, 1.0, low_open=True)

    def coefficients(self, fw: AdaptiveFlywheel) -> tuple[float, ...]:
        """The scalar arguments the kernels take, in order:

        (rest_inertia, n, m_s, k_s, l_min, l_max, c_s, k_c, c_c).
        """
        if fw.power != 2:
            raise ParameterError(
                "law",
                "slider-dynamics",
                "a flywheel with the physical l^2 law (not thesis-literal)",
            )
        m, k = fw.slider_mass, fw.spring_stiffness
        c_s = 2.0 * self.damping_ratio * math.sqrt(k * m)
        e = self.restitution
        zeta = 0.0 if e >= 1.0 else -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)
        c_c = 2.0 * zeta * math.sqrt(self.contact_stiffness * m)
        return (
            float(fw.rest_inertia),
            float(fw.n_sliders),
            float(m),
            float(k),
            float(fw.slider_min),
            float(fw.slider_max),
            float(c_s),
            float(self.contact_stiffness),
            float(c_c),
        )


@nb.njit(cache=True, error_model="numpy")
def _stop_force(l, ldot, l_min, l_max, k_c, c_c):
    """Force of the stops on one slider [N] (positive outwards) and its dissipation [W]."""
    if l > l_max:
        d = l - l_max
        dd = ldot
        fc = k_c * d + c_c * dd
        if fc < 0.0:
            fc = 0.0
        return -fc, (fc - k_c * d) * dd
    if l < l_min:
        d = l_min - l
        dd = -ldot
        fc = k_c * d + c_c * dd
        if fc < 0.0:
            fc = 0.0
        return fc, (fc - k_c * d) * dd
    return 0.0, 0.0


@nb.njit(cache=True, error_model="numpy")
def slider_state_derivative(l, ldot, omega, n, m_s, k_s, l_min, l_max, c_s, k_c, c_c):
    """Slider acceleration l'' [m/s^2] and the dissipated power D of all sliders [W]."""
    f_stop, p_stop = _stop_force(l, ldot, l_min, l_max, k_c, c_c)
    f = m_s * l * omega * omega - k_s * (l - l_min) - c_s * ldot + f_stop
    return f / m_s, n * (c_s * ldot * ldot + p_stop)


@nb.njit(cache=True)
def stored_energy(l, ldot, omega, rest_inertia, n, m_s, k_s, l_min, l_max, k_c):
    """Kinetic + spring + contact energy of the flywheel [J]."""
    j = rest_inertia + n * m_s * l * l
    e = 0.5 * j * omega * omega + 0.5 * n * m_s * ldot * ldot + 0.5 * n * k_s * (l - l_min) ** 2
    if l > l_max:
        e += 0.5 * n * k_c * (l - l_max) ** 2
    elif l < l_min:
        e += 0.5 * n * k_c * (l_min - l) ** 2
    return e
