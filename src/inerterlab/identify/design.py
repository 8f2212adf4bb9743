"""Campaign design: which rig tests to run when only a few can be (:func:`design_campaign`).

Each candidate test g of an Appendix A matrix is run on the model (noise-free, the
simulator's motion) and the Jacobian J_g of its residuals with respect to the free
parameters is formed exactly as the fit forms it (same preparation, same reversal
window, same residual function and differencing). With white force noise of standard
deviation sigma a test contributes the Fisher information F_g = J_g^T J_g / sigma^2,
and a campaign S the sum F_S. D-optimal design picks the S of the given size that
maximises det F_S, i.e. minimises the volume of the joint confidence ellipsoid of
the parameters; it does not depend on the units of the parameters.

Search: greedy (add the test that raises log det most; a ridge of 1e-9 of the full
campaign's diagonal keeps the first steps defined) followed by exchange (swap a
chosen test for an unchosen one while that raises log det), which finds the best
subset or one very close to it for three parameters.

The predicted standard errors sqrt(diag F_S^-1) are those of plain least squares with
white noise; the fit's intervals can be wider when noise is correlated in time or
the model misses something within a test (see "Coverage" in the guide).
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from ..errors import ParameterError, check_positive
from .fit import PARAMETERS, RTOL, _prepare, _raw_jacobian, _residuals, default_reversal_window
from .simulator import TestSpec, simulate_rig, test_matrix

__all__ = ["CampaignDesign", "campaign_information", "design_campaign"]


@dataclasses.dataclass(frozen=True, eq=False)
class CampaignDesign:
    """A chosen campaign and what it predicts.

    Attributes
    ----------
    chosen : list of TestSpec
        The tests to run, in the order of the candidates.
    candidates : list of TestSpec
    information : ndarray
        Fisher information of each candidate (G x p x p), parameters ``names``.
    names : tuple of str
    noise : float
        The force-noise standard deviation [N] the information assumes.
    """

    chosen: list
    candidates: list
    information: np.ndarray
    names: tuple
    noise: float

    def _info(self, idx) -> np.ndarray:
        return self.information[list(idx)].sum(axis=0)

    @property
    def indices(self) -> list:
        return [self.candidates.index(t) for t in self.chosen]

    def standard_errors(self, which: str = "chosen") -> np.ndarray:
        """Predicted standard errors of the chosen (``"chosen"``) or of the whole
        candidate campaign (``"full"``), in ``names`` order."""
        idx = self.indices if which == "chosen" else range(len(self.candidates))
        F = self._info(idx)
        return np.sqrt(np.diag(np.linalg.inv(F)))

    def efficiency(self) -> float:
        """(det F_chosen / det F_full)^(1/p): the fraction of the full campaign's
        information per parameter that the chosen tests keep."""
        p = len(self.names)
        a = np.linalg.slogdet(self._info(self.indices))[1]
        b = np.linalg.slogdet(self._info(range(len(self.candidates))))[1]
        return float(math.exp((a - b) / p))

    def to_pandas(self):
        """Predicted standard errors, chosen against full campaign, per parameter."""
        import pandas as pd

        from ..devices import PARAMETER_UNITS

        se_c, se_f = self.standard_errors("chosen"), self.standard_errors("full")
        return pd.DataFrame(
            {
                "parameter": list(self.names),
                "unit": [PARAMETER_UNITS[n] for n in self.names],
                "se_chosen": se_c,
                "se_full": se_f,
                "ratio": se_c / se_f,
            }
        )

    def tests_frame(self):
        """The chosen tests (number, signal, frequency, amplitude, duration)."""
        import pandas as pd

        return pd.DataFrame(
            [
                {
                    "test": t.number,
                    "signal": t.signal,
                    "frequency_hz": t.frequency,
                    "amplitude_m": t.amplitude,
                    "duration_s": t.duration,
                    "purpose_in_matrix": t.purpose,
                }
                for t in self.chosen
            ]
        )


def campaign_information(
    device,
    tests: list,
    *,
    noise: float = 5.0,
    sample_rate: float = 500.0,
    max_duration: float | None = None,
    reversal_window: float | None = None,
    fixed: tuple = (),
    rtol: float = RTOL,
) -> np.ndarray:
    """Fisher information J_g^T J_g / noise^2 of each test of ``tests`` for the free
    parameters of ``device`` (the fit's Jacobian on a noise-free run of the test)."""
    check_positive("noise", noise, "N")
    if reversal_window is None:
        reversal_window = default_reversal_window(device)
    names = [n for n in PARAMETERS if n not in fixed]
    data = simulate_rig(
        device,
        matrix=list(tests),
        sample_rate=sample_rate,
        noise=0.0,
        displacement_noise=0.0,
        velocity_noise=0.0,
        spikes=False,
        max_duration=max_duration,
    )
    from .fit import _affine_terms, _is_affine

    out = []
    for t in data.tests:
        prep = _prepare(t, window=0.02, detrend="constant", reversal_window=reversal_window)
        if not prep.mask.any():
            out.append(np.zeros((len(names), len(names))))
            continue
        affine = None
        if _is_affine(device):
            affine = {id(prep): _affine_terms(device, prep)}
        fun, jac = _residuals(device, names, [prep], rtol, affine)
        x = np.array([getattr(device, n) for n in names], dtype=float)
        lb = np.zeros_like(x)
        ub = np.full_like(x, np.inf)
        J = _raw_jacobian(fun, x, fun(x), lb, ub, jac)
        out.append(J.T @ J / noise**2)
    return np.array(out)


def _logdet(F) -> float:
    sign, val = np.linalg.slogdet(F)
    return val if sign > 0 else -np.inf


def _d_optimal(info: np.ndarray, budget: int) -> list:
    G = info.shape[0]
    full = info.sum(axis=0)
    ridge = 1e-9 * np.diag(np.diag(full))
    chosen: list = []
    for _ in range(budget):
        base = ridge + info[chosen].sum(axis=0) if chosen else ridge
        best = max((g for g in range(G) if g not in chosen), key=lambda g: _logdet(base + info[g]))
        chosen.append(best)
    cur = _logdet(ridge + info[chosen].sum(axis=0))
    improved = True
    while improved:
        improved = False
        for i, j in itertools.product(range(budget), range(G)):
            if j in chosen:
                continue
            trial = chosen.copy()
            trial[i] = j
            val = _logdet(ridge + info[trial].sum(axis=0))
            if val > cur + 1e-12 * abs(cur):
                chosen, cur, improved = trial, val, True
    return sorted(chosen)


def design_campaign(
    device,
    budget: int,
    *,
    matrix: str | list = "appendix-a1",
    noise: float = 5.0,
    sample_rate: float = 500.0,
    max_duration: float | None = None,
    reversal_window: float | None = None,
    fixed: tuple = (),
    information: np.ndarray | None = None,
) -> CampaignDesign:
    """Choose ``budget`` tests of ``matrix`` that maximise det of the Fisher information.

    Parameters
    ----------
    device : HydraulicDevice, ScrewDevice or RectifierDevice
        The model at the parameters to design for (e.g. ``fit.device`` of a previous
        identification, or the thesis values).
    budget : int
        Number of tests that can be run (>= number of free parameters).
    matrix : str or list of TestSpec
        The candidates: ``appendix-a1``, ``appendix-a2`` (every test, whatever its
        purpose in the thesis) or an explicit list.
    noise : float
        Force-noise standard deviation [N] (scales every standard error alike).
    sample_rate, max_duration, reversal_window
        As for the rig and the fit (``reversal_window`` None: the device's default);
        ``max_duration`` shortens every candidate (quick designs; the information then
        is that of the shortened tests).
    information : ndarray, optional
        Precomputed :func:`campaign_information` of the candidates.
    """
    cands = test_matrix(matrix) if isinstance(matrix, str) else list(matrix)
    if not cands or not all(isinstance(t, TestSpec) for t in cands):
        raise ParameterError("matrix", matrix, "a matrix name or a non-empty list of TestSpec")
    names = tuple(n for n in PARAMETERS if n not in fixed)
    budget = int(budget)
    if not len(names) <= budget <= len(cands):
        raise ParameterError(
            "budget", budget, f"between {len(names)} (free parameters) and {len(cands)} tests"
        )
    if information is None:
        information = campaign_information(
            device,
            cands,
            noise=noise,
            sample_rate=sample_rate,
            max_duration=max_duration,
            reversal_window=reversal_window,
            fixed=fixed,
        )
    chosen = _d_optimal(information, budget)
    return CampaignDesign(
        chosen=[cands[i] for i in chosen],
        candidates=cands,
        information=information,
        names=names,
        noise=float(noise),
    )
