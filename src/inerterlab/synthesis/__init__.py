"""Positive-real synthesis of suspension admittances (docs/model.md §13).

- :mod:`.positive_real`: a parametrisation of PR functions that is PR by construction,
  numerical and closed-form (biquadratic) PR tests;
- :mod:`.optimize`: the H2-optimal Y = k/s + Y0 with Y0 PR of a given McMillan degree;
- :mod:`.realise`: networks from a PR admittance (Foster, Cauer, catalogue, Bott-Duffin,
  Brune), each checked against its target;
- :mod:`.catalogue`: the smallest enumerated layout that fits an admittance exactly;
- :mod:`.design`: the whole job of ``inerterlab network synthesize``.
"""

from .design import synthesize_design
from .optimize import SYNTH_OBJECTIVES, SynthesisResult, objective_value, synthesize
from .positive_real import biquadratic_pr_condition, is_positive_real, is_regular, pr_report
from .realise import METHODS, Realisation, RealisationError, brune, realise, realise_all

__all__ = [
    "SYNTH_OBJECTIVES",
    "SynthesisResult",
    "synthesize",
    "synthesize_design",
    "objective_value",
    "pr_report",
    "is_positive_real",
    "biquadratic_pr_condition",
    "is_regular",
    "METHODS",
    "Realisation",
    "RealisationError",
    "realise",
    "realise_all",
    "brune",
]
