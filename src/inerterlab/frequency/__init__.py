"""Steady-state frequency response: brute force, harmonic balance (AFT), continuation.

The chapter-7 system and the Duffing oscillator (templates of
:mod:`inerterlab.systems.oscillators`), the quarter car and every model-core system on
the one engine of :mod:`inerterlab.frequency.first_order`; a user's residual given as
Python functions (:class:`UserSystem`) in numpy. See docs/guide/frequency.md.
Thesis ch. 7; docs/model.md §7.
"""

from .brute import SteadyState as SteadyState
from .brute import floquet_multipliers as floquet_multipliers
from .brute import steady_state as steady_state
from .continuation import ContinuationPath as ContinuationPath
from .continuation import continue_branch as continue_branch
from .first_order import RHS_SIGNATURE as RHS_SIGNATURE
from .first_order import TERMS_SIGNATURE as TERMS_SIGNATURE
from .first_order import FirstOrderSystem as FirstOrderSystem
from .harmonic import FourierBasis as FourierBasis
from .harmonic import fourier_basis as fourier_basis
from .harmonic import hill_exponents as hill_exponents
from .harmonic import make_engine as make_engine
from .quarter_car import from_core_system as from_core_system
from .quarter_car import quarter_car_system as quarter_car_system
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
    "FirstOrderSystem",
    "FourierBasis",
    "FrequencyResponse",
    "InerterSuspension",
    "METHODS",
    "RHS_SIGNATURE",
    "TERMS_SIGNATURE",
    "SteadyState",
    "UserSystem",
    "chapter7_system",
    "continue_branch",
    "floquet_multipliers",
    "fourier_basis",
    "frequency_grid",
    "frequency_response",
    "from_core_system",
    "hill_exponents",
    "make_engine",
    "nrmse",
    "quarter_car_system",
    "steady_state",
    "traditional_suspension",
]
