"""Steady-state frequency response: brute force, harmonic balance (AFT), continuation.

See docs/guide/frequency.md. Thesis ch. 7; docs/model.md §7.
"""

from .brute import SteadyState as SteadyState
from .brute import floquet_multipliers as floquet_multipliers
from .brute import steady_state as steady_state
from .continuation import ContinuationPath as ContinuationPath
from .continuation import continue_branch as continue_branch
from .harmonic import FourierBasis as FourierBasis
from .harmonic import fourier_basis as fourier_basis
from .harmonic import hill_exponents as hill_exponents
from .harmonic import make_engine as make_engine
from .response import METHODS as METHODS
from .response import FrequencyResponse as FrequencyResponse
from .response import frequency_grid as frequency_grid
from .response import frequency_response as frequency_response
from .response import nrmse as nrmse
from .systems import DuffingOscillator as DuffingOscillator
from .systems import InerterSuspension as InerterSuspension
from .systems import UserSystem as UserSystem
from .systems import chapter7_system as chapter7_system
from .systems import traditional_suspension as traditional_suspension

__all__ = [
    "ContinuationPath",
    "DuffingOscillator",
    "FourierBasis",
    "FrequencyResponse",
    "InerterSuspension",
    "METHODS",
    "SteadyState",
    "UserSystem",
    "chapter7_system",
    "continue_branch",
    "floquet_multipliers",
    "fourier_basis",
    "frequency_grid",
    "frequency_response",
    "hill_exponents",
    "make_engine",
    "nrmse",
    "steady_state",
    "traditional_suspension",
]
