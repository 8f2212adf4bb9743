"""Periodically forced systems M(x, x') x'' + f(x, x', t) = 0 for harmonic balance.

A system is described by its residual at the time samples,

    r(tau, x, x', x'') = M(x, x', tau) x'' + f(x, x', tau),   tau = Omega t,

and the partial derivatives dr/dx, dr/dx', dr/dx'' (exact for the built-in systems).
The residual must be affine in x'' (a mass matrix times x'' plus the rest); time
integration solves it for x''.

Built-in systems (compiled): :class:`DuffingOscillator` and :class:`InerterSuspension`
(thesis (7.1)). The harmonic balance and the brute force solve them on the one engine of
:mod:`inerterlab.frequency.first_order`, as the states (x, x') in implicit form

    x' - v = 0,    r(tau, x, v, v') = 0,

with the velocity's coefficients eliminated (V = Omega D X), so the balance is exactly
that of r (whatever the effective mass does within a cycle) on the 2H+1 coefficients of
x. Any other system is a :class:`UserSystem` built from plain numpy functions.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..errors import ParameterError, check_choice, check_nonnegative, check_positive
from ..flywheels import AdaptiveFlywheel, flywheel
from ..transmissions import Transmission, hydraulic
from ._kernels import residual_partials
from .first_order import FREQ_SLOT, RHS_SIGNATURE, TERMS_SIGNATURE, FirstOrderSystem, _borrow

__all__ = [
    "DuffingOscillator",
    "InerterSuspension",
    "UserSystem",
    "chapter7_system",
    "traditional_suspension",
    "FORCE_LAWS",
]

FORCE_LAWS = ("thesis", "momentum", "thesis-literal")


@njit(TERMS_SIGNATURE, cache=True)
def _terms(tau, omega, amp, xs, xds, itab, ftab, r, P, Q, partials):
    """The implicit form on (x, v): r_0 = x' - v, r_1 = r(tau, x, v, v') with (when
    ``partials``) their partials, at every sample; the base moves as amp sin(tau)."""
    sys_id = itab[0]
    p = _borrow(ftab)  # no reference counting per sample (see first_order._borrow)
    for k in range(tau.shape[0]):
        s = math.sin(tau[k])
        r[0, k] = xds[0, k] - xs[1, k]
        r1, g0, g1, g2 = residual_partials(
            sys_id, p, tau[k], omega, amp * s, amp * omega * math.cos(tau[k]),
            -amp * omega * omega * s, xs[0, k], xs[1, k], xds[1, k],
        )  # fmt: skip
        r[1, k] = r1
        if not partials:
            continue
        P[0, 0, k] = 0.0
        P[0, 1, k] = -1.0
        Q[0, 0, k] = 1.0
        Q[0, 1, k] = 0.0
        P[1, 0, k] = g0
        P[1, 1, k] = g1
        Q[1, 0, k] = 0.0
        Q[1, 1, k] = g2
    return True


@njit(RHS_SIGNATURE, cache=True)
def _rhs(t, y, road, itab, ftab, out):
    """x' = v, v' = -r(tau, x, v, 0) / (dr/dx'') (r is affine in x''), tau = Omega t."""
    omega = road[FREQ_SLOT]
    r0, _, _, m = residual_partials(
        itab[0], ftab, omega * t, omega, road[0], road[1], road[2], y[0], y[1], 0.0
    )
    out[0] = y[1]
    out[1] = -r0 / m
    return True


class _KernelSystem:
    """Shared behaviour of the built-in one-degree-of-freedom systems."""

    n_dof = 1
    response_dof = 0

    def parameters(self) -> tuple[int, np.ndarray]:  # pragma: no cover - overridden
        raise AttributeError

    def kernel(self) -> tuple[int, np.ndarray]:
        """(system code, parameters) of the specialised kernel (``frequency._kernels``)."""
        return self.parameters()

    @property
    def input_amplitude(self) -> float:
        """Amplitude of the base motion (0: the system is forced otherwise)."""
        return 0.0

    def evaluate(self, tau, omega, x, xd, xdd):
        """r, dr/dx, dr/dx', dr/dx'' at the samples; x has shape (1, K)."""
        sys_id, p = self.parameters()
        tau = np.asarray(tau, dtype=float)
        b = self.input_amplitude
        k = tau.shape[0]
        r = np.empty((1, k))
        g = np.empty((3, 1, 1, k))
        for i in range(k):
            s = math.sin(tau[i])
            out = residual_partials(
                sys_id, p, tau[i], omega, b * s, b * omega * math.cos(tau[i]),
                -b * omega * omega * s, x[0, i], xd[0, i], xdd[0, i],
            )  # fmt: skip
            r[0, i] = out[0]
            g[0, 0, 0, i], g[1, 0, 0, i], g[2, 0, 0, i] = out[1], out[2], out[3]
        return r, g[0], g[1], g[2]

    def first_order(self) -> FirstOrderSystem:
        """The system as the states (x, x') of the harmonic-balance engine, in implicit
        form with the velocity eliminated; its input amplitude is
        :attr:`input_amplitude`."""
        sys_id, p = self.parameters()
        scale = float(self.displacement_scale)
        return FirstOrderSystem(
            n_states=2,
            rhs=_rhs,
            terms=_terms,
            velocity_of=(1, -1),
            int_table=np.array([sys_id], dtype=np.int64),
            float_table=np.ascontiguousarray(p, dtype=float),
            state_scales=np.array([scale, scale]),
            rest_state=np.zeros(2),
            nonlinearity_degree=int(self.nonlinearity_degree),
            label=type(self).__name__,
            input_amplitude=self.input_amplitude,
        )


@dataclass(frozen=True, kw_only=True)
class DuffingOscillator(_KernelSystem):
    """m x'' + c x' + k x + g x^3 = P cos(Omega t).

    Parameters
    ----------
    mass : float
        m [kg] (or 1 for the dimensionless form).
    damping : float
        c [N s/m]. NLvib writes the damping coefficient as zeta directly
        (mu x'' + zeta x' + kappa x + gamma x^3 = P cos(Omega t)); its published
        example values need c = zeta = 0.05 (see inerterlab/data/errata.md).
    stiffness : float
        k [N/m].
    cubic_stiffness : float
        g [N/m^3].
    force : float
        P [N], amplitude of the cosine forcing.

    Examples
    --------
    >>> DuffingOscillator.nlvib_example().damping
    0.05
    """

    mass: float = 1.0
    damping: float = 0.05
    stiffness: float = 1.0
    cubic_stiffness: float = 0.1
    force: float = 0.18

    nonlinearity_degree = 3

    def __post_init__(self) -> None:
        check_positive("mass", self.mass, "kg")
        check_nonnegative("damping", self.damping, "N s/m")
        check_positive("stiffness", self.stiffness, "N/m")
        check_nonnegative("cubic_stiffness", self.cubic_stiffness, "N/m^3")
        check_nonnegative("force", self.force, "N")

    @classmethod
    def nlvib_example(cls) -> DuffingOscillator:
        """NLvib's first example: mu=1, zeta=0.05 (= c), kappa=1, gamma=0.1, P=0.18 (docs/model.md §10)."""
        return cls(mass=1.0, damping=0.05, stiffness=1.0, cubic_stiffness=0.1, force=0.18)

    @property
    def displacement_scale(self) -> float:
        """A typical displacement [m]: the static deflection under P."""
        return max(self.force / self.stiffness, 1e-12)

    def parameters(self) -> tuple[int, np.ndarray]:
        """(system code 0, [m, c, k, g, P]) for the compiled residual."""
        p = np.array([self.mass, self.damping, self.stiffness, self.cubic_stiffness, self.force])
        return 0, p

    def natural_frequency(self) -> float:
        """sqrt(k/m) [rad/s] of the linear part."""
        return math.sqrt(self.stiffness / self.mass)


@dataclass(frozen=True, kw_only=True)
class InerterSuspension(_KernelSystem):
    """Body on spring, damper and flywheel inerter over a moving base, thesis (7.1).

        M X1'' + F_in + K (X1 - X0) + C (X1' - X0') = 0,   X0 = B sin(Omega t)  (7.6)

    with the inerter force F_in = m(v) (X1'' - X0''), v = X1' - X0' and, by ``force_law``,
    m(v) = r^2 I(r|v|) (``thesis``, (7.2)-(7.4) with l^2) or
    m(v) = r^2 (I + w dI/dw), w = r|v| (``momentum``). With ``flywheel=None`` the
    inerter is absent (the traditional suspension of Fig. 7.9).

    Parameters
    ----------
    body_mass : float
        M [kg] (300 in ch. 7).
    stiffness : float
        K [N/m] (90e3).
    damping : float
        C [N s/m] (5000).
    base_amplitude : float
        B [m], amplitude of the base displacement (7.6).
    flywheel : AdaptiveFlywheel or None
        The flywheel (default: metal preset, Table 3.1, published law (3.6)).
    transmission : Transmission
        Terminal velocity to flywheel speed, w = r v (default hydraulic, r = 961.66 rad/m).
    force_law : {"thesis", "momentum"}
        How the speed-dependent inertia produces force (docs/model.md §2).
    """

    body_mass: float = 300.0
    stiffness: float = 90e3
    damping: float = 5000.0
    base_amplitude: float = 0.01
    flywheel: AdaptiveFlywheel | None = field(default_factory=lambda: flywheel("metal"))
    transmission: Transmission = field(default_factory=hydraulic)
    force_law: str = "thesis"

    nonlinearity_degree = 3

    def __post_init__(self) -> None:
        check_positive("body_mass", self.body_mass, "kg")
        check_positive("stiffness", self.stiffness, "N/m")
        check_nonnegative("damping", self.damping, "N s/m")
        check_positive("base_amplitude", self.base_amplitude, "m")
        check_choice("force_law", self.force_law, ("thesis", "momentum"))
        if self.flywheel is not None and not isinstance(self.flywheel, AdaptiveFlywheel):
            raise ParameterError("flywheel", self.flywheel, "an AdaptiveFlywheel or None")

    @property
    def displacement_scale(self) -> float:
        """The base amplitude B [m]."""
        return self.base_amplitude

    @property
    def input_amplitude(self) -> float:
        """B [m]: the base moves as B sin(Omega t)."""
        return self.base_amplitude

    def parameters(self) -> tuple[int, np.ndarray]:
        """(system code 1, the parameter vector of the compiled residual)."""
        fw = self.flywheel
        if fw is None:
            extra = [1.0, 0.0, 0.0, 1.0, 1.0, 0.01, 0.02, 1.0, 2.0, 0.0, 0.0]
        else:
            extra = [
                self.transmission.ratio,
                fw.rest_inertia,
                fw.inertia_coefficient,
                fw.spring_stiffness,
                fw.slider_mass,
                fw.slider_min,
                fw.slider_max,
                fw.saturation_speed,
                float(fw.power),
                0.0 if self.force_law == "thesis" else 1.0,
                1.0,
            ]
        p = [self.body_mass, self.stiffness, self.damping, self.base_amplitude, *extra]
        return 1, np.array(p, dtype=float)

    def equivalent_mass_range(self) -> tuple[float, float]:
        """r^2 I_min and r^2 I_max [kg] (0, 0 without inerter)."""
        if self.flywheel is None:
            return 0.0, 0.0
        r2 = self.transmission.ratio**2
        return r2 * self.flywheel.inertia_min, r2 * self.flywheel.inertia_max

    def linear_amplitude(self, omega, inertance: float | None = None):
        """|X1| [m] of the linear system with a constant inertance b [kg].

        X1/X0 = (K + i C w - b w^2) / (K + i C w - (M + b) w^2); default b = r^2 I_min.
        Exact when the flywheel is constant.
        """
        b = self.equivalent_mass_range()[0] if inertance is None else inertance
        w = np.asarray(omega, dtype=float)
        num = self.stiffness + 1j * self.damping * w - b * w**2
        den = self.stiffness + 1j * self.damping * w - (self.body_mass + b) * w**2
        return self.base_amplitude * np.abs(num / den)


def chapter7_system(
    base_amplitude: float = 0.01, *, preset: str = "metal", law: str = "thesis"
) -> InerterSuspension:
    """The thesis ch. 7 system (7.1) with a flywheel preset and an inertia law.

    Parameters
    ----------
    base_amplitude : float
        B [m] (thesis: 0.01, 0.02, 0.03, 0.05, 0.07, 0.10, 0.20).
    preset : {"metal", "nylon", "nylon-large", "none"}
        Flywheel preset; ``none`` gives the traditional suspension (no inerter).
    law : {"thesis", "momentum", "thesis-literal"}
        ``thesis``: F = r^2 I(r|v|) v' with I from the published law (default);
        ``momentum``: F = r^2 (I + w dI/dw) v'; ``thesis-literal``: the thesis law with
        the flywheel inertia as printed in (7.2)-(7.7) (l in place of l^2).

    Examples
    --------
    >>> sys = chapter7_system(0.03)
    >>> [round(m, 1) for m in sys.equivalent_mass_range()]
    [882.1, 998.7]
    """
    check_choice("law", law, FORCE_LAWS)
    check_choice("flywheel", preset, ("metal", "nylon", "nylon-large", "none"))
    if preset == "none":
        return traditional_suspension(base_amplitude)
    fw = flywheel(preset, law="thesis-literal" if law == "thesis-literal" else "published")
    force_law = "momentum" if law == "momentum" else "thesis"
    return InerterSuspension(base_amplitude=base_amplitude, flywheel=fw, force_law=force_law)


def traditional_suspension(base_amplitude: float = 0.01) -> InerterSuspension:
    """Body on spring and damper only (Fig. 7.9's traditional suspension)."""
    return InerterSuspension(base_amplitude=base_amplitude, flywheel=None)


@dataclass(frozen=True, kw_only=True)
class UserSystem:
    """A system given by Python functions (numpy path, no compilation).

    Parameters
    ----------
    residual : callable
        ``residual(tau, omega, x, xd, xdd) -> r``; ``tau`` has shape (K,) (phase
        Omega t [rad]), ``omega`` is the forcing frequency [rad/s], ``x``, ``xd``,
        ``xdd`` have shape (n_dof, K); returns r of shape (n_dof, K). Must be affine in
        ``xdd`` (r = M xdd + f).
    n_dof : int
        Number of degrees of freedom.
    partials : callable, optional
        ``partials(tau, omega, x, xd, xdd) -> (dr_dx, dr_dxd, dr_dxdd)``, each of
        shape (n_dof, n_dof, K) with [i, j, k] = d r_i / d x_j at sample k. Without it
        the partials come from central differences per degree of freedom (all samples at
        once, since r at one sample depends only on the state at that sample).
    nonlinearity_degree : int
        Polynomial degree of the nonlinearity for the aliasing rule (3 for cubic).
    displacement_scale : float
        A typical displacement [m] for tolerances.
    response_dof : int
        Degree of freedom whose amplitude is reported.

    Examples
    --------
    >>> import numpy as np
    >>> def duffing(tau, omega, x, xd, xdd):
    ...     return xdd + 0.1 * xd + x + 0.1 * x**3 - 0.18 * np.cos(tau)
    >>> UserSystem(residual=duffing).n_dof
    1
    """

    residual: Callable
    n_dof: int = 1
    partials: Callable | None = None
    nonlinearity_degree: int = 3
    displacement_scale: float = 1.0
    response_dof: int = 0

    def __post_init__(self) -> None:
        if not callable(self.residual):
            raise ParameterError("residual", self.residual, "a callable")
        if not isinstance(self.n_dof, int) or self.n_dof < 1:
            raise ParameterError("n_dof", self.n_dof, "an integer >= 1")
        if not isinstance(self.nonlinearity_degree, int) or self.nonlinearity_degree < 1:
            raise ParameterError("nonlinearity_degree", self.nonlinearity_degree, "an integer >= 1")
        check_positive("displacement_scale", self.displacement_scale, "m")
        if not 0 <= self.response_dof < self.n_dof:
            raise ParameterError("response_dof", self.response_dof, f"0 .. {self.n_dof - 1}")

    def evaluate(self, tau, omega, x, xd, xdd):
        """r and its partials at the samples (see the class docstring for shapes)."""
        r = np.asarray(self.residual(tau, omega, x, xd, xdd), dtype=float).reshape(x.shape)
        if self.partials is not None:
            gx, gv, ga = (np.asarray(g, dtype=float) for g in self.partials(tau, omega, x, xd, xdd))
            return r, gx, gv, ga
        n, k = x.shape
        out = []
        for which, base in enumerate((x, xd, xdd)):
            g = np.empty((n, n, k))
            scale = (self.displacement_scale * max(omega, 1e-12) ** which) * 1e-6
            for j in range(n):
                h = scale + 1e-7 * np.abs(base[j])
                args_p = [x.copy(), xd.copy(), xdd.copy()]
                args_m = [x.copy(), xd.copy(), xdd.copy()]
                args_p[which][j] += h
                args_m[which][j] -= h
                rp = np.asarray(self.residual(tau, omega, *args_p), dtype=float).reshape(x.shape)
                rm = np.asarray(self.residual(tau, omega, *args_m), dtype=float).reshape(x.shape)
                g[:, j, :] = (rp - rm) / (2.0 * h)
            out.append(g)
        return r, out[0], out[1], out[2]
