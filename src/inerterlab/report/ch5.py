"""Chapter 5 of the reproduction: identification of the real devices from rig data.

The thesis's rig measurements are not public. Every number and figure here comes from
SIMULATED rig data: the thesis's Appendix A test matrices run on our device models with
the thesis's identified parameters ((5.4), (5.8), (5.11), (5.14)), seeded sensor noise
and direction-reversal spikes, then identified back. The table therefore checks the
identification workflow (does it recover what generated the data?), not the thesis's
measurements; the figures are the counterparts of Figs. 5.5/5.8 (hydraulic),
5.12/5.13 (screw) and 5.20 (rectifier) on simulated data.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..devices import device_preset
from ..identify import identify, simulate_rig, test_matrix
from ..identify.fit import default_reversal_window
from ._memo import Memo, memo
from .registry import FigureResult, ReproduceSettings, TableResult

_THESIS = {  # identified values and their equations
    "hydraulic": ((7.76e5, "(5.8)"), (8100.0, "(5.4)"), (190.0, "(5.4)")),
    "screw": ((1.97e6, "(5.11)"), (7600.0, "(5.11)"), (80.0, "(5.11)")),
    "rectifier": ((9.89e5, "(5.14)"), (8100.0, "(5.14)"), (240.0, "(5.14)")),
}
#: a validation test is "predicted" when its RMS error is below this % of its force range
FIGURE_NRMSE_LIMIT = 5.0
_MATRIX = {"hydraulic": "appendix-a1", "screw": "appendix-a2", "rectifier": "appendix-a2"}
_NOTE = (
    "SIMULATED rig data (the thesis's measurements are not public): Appendix A matrix on "
    "our model with the thesis's identified values, 5 N force noise, 300 N reversal spikes."
)


def _settings(quick: bool) -> dict:
    if quick:
        return {"sample_rate": 200.0, "max_duration": 1.0, "every": 6}
    return {"sample_rate": 500.0, "max_duration": 10.0, "every": 1}


@memo
def _fit(device: str, quick: bool):
    s = _settings(quick)
    dev = device_preset(device)
    tests = test_matrix(_MATRIX[device])
    if s["every"] > 1:
        ident = [t for t in tests if t.purpose == "identification"][:: s["every"]]
        valid = [t for t in tests if t.purpose == "validation"][:: s["every"]]
        tests = ident + valid
    data = simulate_rig(
        dev,
        matrix=tests,
        sample_rate=s["sample_rate"],
        max_duration=s["max_duration"],
        noise=5.0,
        spikes=True,
        seed=5,
    )
    start = dataclasses.replace(
        dev, stiffness=dev.stiffness * 1.2, damping=dev.damping * 0.9, friction=dev.friction * 1.1
    )
    # the library's defaults: each device's reversal window and the sandwich intervals,
    # the pair the coverage study calibrated (docs/decisions.md)
    fit = identify(data, start, method="joint")
    return fit, s, len(tests)


def table_identified(settings: ReproduceSettings) -> TableResult:
    """Identified stiffness, damping and friction of the three devices vs the thesis."""
    import pandas as pd

    rows = []
    holds = True
    for device, vals in _THESIS.items():
        fit, s, n = _fit(device, settings.quick)
        for (name, p), (thesis, eq) in zip(fit.parameters.items(), vals, strict=True):
            inside = p.ci95[0] <= thesis <= p.ci95[1]
            holds &= abs(p.value - thesis) <= 0.02 * thesis
            rows.append(
                {
                    "device": device,
                    "parameter": name,
                    "unit": p.unit,
                    "equation": eq,
                    "thesis": thesis,
                    "ours": p.value,
                    "ci95_low": p.ci95[0],
                    "ci95_high": p.ci95[1],
                    "diff_rel_%": 100 * (p.value - thesis) / thesis,
                    "thesis_inside_ci": inside,
                    "validation_nrmse_%": 100 * fit.validation()["nrmse"],
                }
            )
    s = _settings(settings.quick)
    return TableResult(
        table_id="5.A",
        title="Identified device parameters (5.4), (5.8), (5.11), (5.14) recovered from "
        "simulated rig data",
        frame=pd.DataFrame(rows),
        claim="The staged/joint least-squares identification of ch. 5 determines stiffness, "
        "damping and friction of each device, and the identified model predicts the "
        "validation tests closely.",
        claim_holds=bool(holds),
        judges="every identified parameter within 2 % of the value that made the simulated "
        "rig data (the procedure, not the thesis's measurement)",
        reason=_NOTE + " 'ours' is what the identification recovers from that data, so the "
        "comparison tests the procedure, not the thesis's numbers. The claim is judged as: "
        "every value within 2 %; a 95 % interval misses its true value in about 1 of 20 "
        "cases, so with nine parameters one miss is common and is shown, not hidden.",
        settings={
            **s,
            "method": "joint",
            "loss": "cauchy",
            "reversal_window_s": {
                d: default_reversal_window(device_preset(d)) for d in _THESIS
            },
            "interval": "sandwich",
            "seed": 5,
            "quick": settings.quick,
        },
    )


def _figure(device: str, fig_id: str, thesis_fig: str):
    def make(settings: ReproduceSettings) -> FigureResult:
        import pandas as pd

        from ..plotting import _plt

        plt = _plt()
        fit, _, _ = _fit(device, settings.quick)
        val = [t for t in fit.tests if t.purpose == "validation"]
        pick = val[:2] if len(val) >= 2 else fit.tests[:2]
        fig, axes = plt.subplots(2, len(pick), figsize=(5 * len(pick), 5), squeeze=False)
        frames = []
        for j, tv in enumerate(pick):
            a1, a2 = axes[0, j], axes[1, j]
            a1.plot(tv.t, tv.measured, lw=0.7, label="simulated measurement")
            a1.plot(tv.t, tv.predicted, lw=1.0, ls="--", label="identified model")
            a1.set_title(f"{tv.signal} {tv.frequency:g} Hz, {tv.amplitude:g} m", fontsize=9)
            a1.set_ylabel("force [N]")
            a2.plot(tv.t, tv.residual, lw=0.7, c="C3")
            a2.set_ylabel("residual [N]")
            a2.set_xlabel("time [s]")
            frames.append(
                pd.DataFrame(
                    {
                        "test": tv.name,
                        "t": tv.t,
                        "measured": tv.measured,
                        "predicted": tv.predicted,
                    }
                )
            )
        axes[0, 0].legend(fontsize=8)
        fig.suptitle(f"{device}: validation tests (simulated rig data)", fontsize=10)
        fig.tight_layout()
        data = pd.concat(frames, ignore_index=True)
        shown = {}
        for name, g in data.groupby("test", sort=False):
            m, p = g.measured.to_numpy(), g.predicted.to_numpy()
            shown[name] = 100 * float(np.sqrt(np.mean((p - m) ** 2)) / (m.max() - m.min()))
        worst = max(shown.values())
        holds = worst < FIGURE_NRMSE_LIMIT
        return FigureResult(
            figure_id=fig_id,
            title=f"{device} device: measured vs predicted force and residual ({thesis_fig})",
            figure=fig,
            data=data,
            statement="The identified model predicts the force of validation tests it was not "
            f"fitted to ({thesis_fig}).",
            verdict="RMS error of the prediction over the measured force range: "
            + ", ".join(f"{v:.2g} %" for v in shown.values())
            + f" on the {len(shown)} validation tests shown, "
            + ("below" if holds else "not below")
            + f" {FIGURE_NRMSE_LIMIT:g} % (on simulated rig data).",
            holds=holds,
            judges=f"the prediction's RMS error over the measured force range, below "
            f"{FIGURE_NRMSE_LIMIT:g} % on every validation test shown",
            caption=_NOTE + f" Counterpart of thesis {thesis_fig}; residual spikes sit at the "
            "velocity reversals, as in the thesis's figures. RMS and NRMSE per test in "
            f"table 5.A; pooled validation NRMSE {100 * fit.validation()['nrmse']:.3g} %.",
        )

    return make


TABLES = {"5.A": table_identified}
FIGURES = {
    "Fig. 5.5/5.8": _figure("hydraulic", "Fig. 5.5/5.8", "Figs. 5.5, 5.8, 5.9"),
    "Fig. 5.12/5.13": _figure("screw", "Fig. 5.12/5.13", "Figs. 5.12, 5.13"),
    "Fig. 5.20": _figure("rectifier", "Fig. 5.20", "Fig. 5.20"),
}

_FIG_DEVICE = {"Fig. 5.5/5.8": "hydraulic", "Fig. 5.12/5.13": "screw", "Fig. 5.20": "rectifier"}


def prefetch(settings: ReproduceSettings, ids) -> list[tuple[Memo, tuple, float]]:
    """The identifications the items ``ids`` read: (memo, key, cost), for parallel runs."""
    devices = set()
    for i in ids:
        if i == "5.A":
            devices.update(_MATRIX)
        elif i in _FIG_DEVICE:
            devices.add(_FIG_DEVICE[i])
    # measured on two free cores: hydraulic about 30 s, rectifier 21 s, screw 2.6 s
    # (a 200-point brute-force curve, cost 15, takes about 6 s)
    cost = {"hydraulic": 73.0, "rectifier": 51.0, "screw": 6.0}
    return [(_fit, _fit.key(d, settings.quick), cost[d]) for d in sorted(devices)]


__all__ = ["TABLES", "FIGURES", "table_identified"]
