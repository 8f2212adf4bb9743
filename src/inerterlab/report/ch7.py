"""Chapter 7 of the reproduction: steady-state frequency response (tables 7.1-7.4).

Our curves come from :func:`inerterlab.frequency.frequency_response` on the system (7.1)
with the metal flywheel and the ``thesis`` law. The brute-force reference integrates from
rest (7.5) to a detected steady state; NRMSE is (7.16) on the brute-force grid.
"""

from __future__ import annotations

import functools
from importlib import resources

import numpy as np

from ..frequency import chapter7_system, frequency_grid, frequency_response, nrmse
from ._memo import Memo, memo
from .registry import FigureResult, ReproduceSettings, TableResult

AMPLITUDES_CM = (1, 2, 3, 5, 7, 10, 20)
QUICK_AMPLITUDES_CM = (1, 5, 20)
MHB_HARMONICS = 7
SIHB_HARMONICS = 15


@functools.lru_cache(maxsize=1)
def thesis_values():
    """Tables 7.1-7.4 as printed (long format)."""
    import pandas as pd

    with resources.files("inerterlab.data").joinpath("thesis_ch7.csv").open() as fh:
        return pd.read_csv(fh, comment="#")


def _thesis(table: str, amp_cm: int, quantity: str):
    df = thesis_values()
    sel = df[(df.table.astype(str) == table) & (df.amplitude_cm == amp_cm)]
    sel = sel[sel.quantity == quantity]
    return float(sel.value.iloc[0]) if len(sel) else None


def _grids(quick: bool):
    if quick:
        return frequency_grid(0.1, 3.0, 0.05), frequency_grid(0.25, 2.75, 0.5)
    # the thesis grid of (7.16): 0.005 i Hz, i = 1..2000; brute force on every 10th point
    hb = frequency_grid(0.005, 10.0, 0.005)
    return hb, hb[9::10]


def _settings(quick: bool) -> dict:
    hb, br = _grids(quick)
    return {
        "system": "(7.1) M=300 kg, K=90 kN/m, C=5000 N s/m, metal flywheel (3.6), r=961.66 rad/m",
        "inertia_law": "thesis (F = r^2 I(r|v|) dv/dt)",
        "hb_grid_hz": f"{hb[0]:g}..{hb[-1]:g} step {hb[1] - hb[0]:g}",
        "brute_grid_hz": f"{br[0]:g}..{br[-1]:g} step {br[1] - br[0]:g}",
        "brute": "RK4 2000+ steps/period from rest to a settled orbit (rtol 1e-9)",
        "mhb_harmonics": MHB_HARMONICS,
        "sihb_harmonics": SIHB_HARMONICS,
        "nrmse": "(7.16) on the brute grid, normalised by the method's amplitudes",
        "quick": quick,
    }


def _amplitudes(quick: bool):
    return QUICK_AMPLITUDES_CM if quick else AMPLITUDES_CM


@memo
def _curve(amp_cm: int, method: str, quick: bool, law: str = "thesis", preset: str = "metal"):
    # no Hill stability: no table or figure of the report shows it, and its eigenvalues
    # were most of the run time (the amplitudes do not depend on it)
    hb, br = _grids(quick)
    sys = chapter7_system(amp_cm / 100.0, preset=preset, law=law)
    if method == "brute":
        return frequency_response(sys, "brute", freq_hz=br)
    h = {"shb": 1, "mhb": MHB_HARMONICS, "sihb": SIHB_HARMONICS}[method]
    direction = "both" if method == "sihb" else "up"
    return frequency_response(
        sys, method, freq_hz=hb, harmonics=h, direction=direction, stability=False
    )


#: rough relative cost of one curve (for scheduling the parallel reproduction)
_CURVE_COST = {"brute": 15.0, "sihb": 1.5, "shb": 1.5, "mhb": 0.5}  # seconds, roughly
_USES = {  # item -> (method, law, preset) of the curves it reads, for every amplitude
    "7.1": [("sihb", "thesis", "metal"), ("sihb", "thesis-literal", "metal")],
    "7.2": [("brute", "thesis", "metal"), ("shb", "thesis", "metal")],
    "7.3": [("brute", "thesis", "metal"), ("mhb", "thesis", "metal"), ("sihb", "thesis", "metal")],
    "7.4": [("brute", "thesis", "metal"), ("sihb", "thesis", "metal"), ("mhb", "thesis", "metal")],
    "Fig. 7.2": [("shb", "thesis", "metal"), ("brute", "thesis", "metal")],
    "Fig. 7.4": [("mhb", "thesis", "metal"), ("brute", "thesis", "metal")],
    "Fig. 7.7": [("sihb", "thesis", "metal"), ("brute", "thesis", "metal")],
}


def prefetch(settings: ReproduceSettings, ids) -> list[tuple[Memo, tuple, float]]:
    """The curves the items ``ids`` read: (memo, key, cost), for parallel computation."""
    keys = {}
    for i in ids:
        for method, law, preset in _USES.get(i, ()):
            for a in _amplitudes(settings.quick):
                keys[_curve.key(a, method, settings.quick, law, preset)] = _CURVE_COST[method]
        if i == "Fig. 7.9":
            for a in (1, 20) if settings.quick else (1, 5, 10, 20):
                for preset in ("metal", "none"):
                    keys[_curve.key(a, "sihb", settings.quick, "thesis", preset)] = 1.5
    # brute force costs more at small amplitudes (slower settling)
    return [(_curve, k, c * (2.0 if k[1] == "brute" and k[0] <= 3 else 1.0))
            for k, c in keys.items()]  # fmt: skip


def table_7_1(settings: ReproduceSettings) -> TableResult:
    """Resonance frequency and peak response per input amplitude (Table 7.1)."""
    import pandas as pd

    rows = []
    for a in _amplitudes(settings.quick):
        pk = _curve(a, "sihb", settings.quick).resonance("down")
        lit = _curve(a, "sihb", settings.quick, "thesis-literal").resonance("down")
        tf, ta = _thesis("7.1", a, "resonance_frequency"), _thesis("7.1", a, "max_amplitude")
        rows.append(
            {
                "amplitude_cm": a,
                "resonance_hz_ours": pk["freq_hz"],
                "resonance_hz_thesis": tf,
                "resonance_hz_diff": None if tf is None else pk["freq_hz"] - tf,
                "max_amplitude_cm_ours": 100 * pk["amplitude_m"],
                "max_amplitude_cm_thesis": ta,
                "max_amplitude_cm_diff": None if ta is None else 100 * pk["amplitude_m"] - ta,
                "resonance_hz_thesis_literal_law": lit["freq_hz"],
                "max_amplitude_cm_thesis_literal_law": 100 * lit["amplitude_m"],
            }
        )
    frame = pd.DataFrame(rows)
    f = frame.resonance_hz_ours.to_numpy()
    ratio = frame.max_amplitude_cm_ours.to_numpy() / np.array(_amplitudes(settings.quick))
    falls = bool(np.all(np.diff(f) < 0))
    grows = bool(np.all(np.diff(ratio) > 0))
    return TableResult(
        table_id="7.1",
        title="Resonance frequency and peak of X1 (half peak-to-peak) per base amplitude B",
        frame=frame,
        claim="The resonance frequency falls and the peak transmissibility grows as the input "
        "amplitude grows.",
        claim_holds=falls and grows,
        reason=f"Resonance falls with B: {'yes' if falls else 'no'}; peak X1/B grows with B: "
        f"{'yes' if grows else 'no'} (ours {', '.join(f'{x:.3f}' for x in ratio)}). Our "
        "resonances sit near 1.1-1.2 Hz, not 0.35-0.68 Hz: with m_e = r^2 I between 882 and "
        "999 kg the undamped natural frequency lies between 1.32 and 1.38 Hz, so 0.68 Hz is "
        "out of reach of (7.1) with l^2. The printed law with l in place of l^2 "
        "(thesis-literal columns) gives m_e of 3.7-5.7 t and lands much closer to the thesis.",
        settings=_settings(settings.quick),
    )


def _nrmse_table(table_id: str, method: str, quantity: str, title: str, claim: str):
    def table(settings: ReproduceSettings) -> TableResult:
        import pandas as pd

        rows = []
        for a in _amplitudes(settings.quick):
            ref = _curve(a, "brute", settings.quick)
            ours = 100 * nrmse(_curve(a, method, settings.quick), ref)
            th = _thesis(table_id, a, quantity)
            row = {
                "amplitude_cm": a,
                f"{quantity}_%_ours": ours,
                f"{quantity}_%_thesis": th,
                f"{quantity}_%_diff": None if th is None else ours - th,
            }
            if method != "shb":
                row["nrmse_other_hb_method_%_ours"] = 100 * nrmse(
                    _curve(a, "mhb" if method == "sihb" else "sihb", settings.quick), ref
                )
            rows.append(row)
        frame = pd.DataFrame(rows)
        e = frame[f"{quantity}_%_ours"].to_numpy()
        if method == "shb":
            holds = bool(np.all(np.diff(e) > 0))
            reason = (
                f"Error grows with B in ours: {'yes' if holds else 'no'}. One harmonic misses "
                "the higher harmonics from the kink of m_e(v) at the saturation speed; once "
                "the sliders sit on their stops for most of the cycle (large B) the system is "
                "nearly linear again and the error falls. Our errors are far below the "
                "thesis's, whose inertance is several times larger (see Table 7.1)."
            )
        elif method == "mhb":
            holds = bool(np.all(e < 15.0))
            reason = (
                f"With H = {MHB_HARMONICS} our error stays far below the thesis's: harmonic "
                "balance with an exact Jacobian converges to the brute-force orbit, the "
                "remaining error is the truncation at H (see Fig. 7.C)."
            )
        else:
            other = frame["nrmse_other_hb_method_%_ours"].to_numpy()
            holds = bool(np.all(e <= other * (1 + 1e-6)))
            reason = (
                f"SIHB (H = {SIHB_HARMONICS}) is at least as accurate as MHB (H = "
                f"{MHB_HARMONICS}); at equal H the two solve the same equations and agree to "
                "round-off where both converge, so the thesis's gain comes from its settings, "
                "not from the scanning itself."
            )
        return TableResult(
            table_id=table_id,
            title=title,
            frame=frame,
            claim=claim,
            claim_holds=holds,
            reason=reason,
            settings=_settings(settings.quick),
        )

    return table


table_7_2 = _nrmse_table(
    "7.2", "shb", "nrmse_shb", "NRMSE (7.16) of single harmonic balance against brute force",
    "The error of single harmonic balance grows with the input amplitude.",
)  # fmt: skip
table_7_3 = _nrmse_table(
    "7.3", "mhb", "nrmse_mhb", "NRMSE (7.16) of multi-harmonic balance against brute force",
    "Multi-harmonic balance stays accurate: below 15 % even at 20 cm.",
)  # fmt: skip
table_7_4 = _nrmse_table(
    "7.4", "sihb", "nrmse_sihb",
    "NRMSE (7.16) of the scanning iterative multi-harmonic method against brute force",
    "The scanning iterative method is at least as accurate as multi-harmonic balance.",
)  # fmt: skip


def _comparison_figure(fig_id: str, method: str, title: str):
    def figure(settings: ReproduceSettings) -> FigureResult:
        import pandas as pd

        from ..plotting import _plt

        plt = _plt()
        amps = _amplitudes(settings.quick)
        fig, axes = plt.subplots(1, len(amps), figsize=(4.2 * len(amps), 3.6), squeeze=False)
        frames = []
        for ax, a in zip(axes[0], amps, strict=True):
            hb, br = _curve(a, method, settings.quick), _curve(a, "brute", settings.quick)
            hbd = hb.branch("down") if "down" in hb.direction else hb
            ax.plot(hbd.freq_hz, 100 * hbd.amplitude_m, "-", label=method)
            ax.plot(br.freq_hz, 100 * br.amplitude_m, "o", ms=3, label="brute force")
            ax.set_title(f"B = {a} cm")
            ax.set_xlabel("frequency [Hz]")
            ax.set_ylabel("X1 amplitude [cm]")
            ax.set_xlim(0, min(4.0, hb.freq_hz.max()))
            ax.legend(fontsize=8)
            for r in (hbd, br):
                df = r.to_pandas()[["freq_hz", "amplitude_m", "converged"]]
                df.insert(0, "method", r.method)
                df.insert(0, "amplitude_cm", a)
                frames.append(df)
        fig.tight_layout()
        return FigureResult(
            figure_id=fig_id,
            title=title,
            figure=fig,
            data=pd.concat(frames, ignore_index=True),
            caption=f"{method} (line) against brute force from rest (dots), metal flywheel, "
            "thesis law.",
        )

    return figure


def figure_7_9(settings: ReproduceSettings) -> FigureResult:
    """Traditional suspension against the adaptive-flywheel suspension (Fig. 7.9)."""
    import pandas as pd

    from ..plotting import _plt

    plt = _plt()
    amps = (1, 20) if settings.quick else (1, 5, 10, 20)
    fig, axes = plt.subplots(1, len(amps), figsize=(4.2 * len(amps), 3.6), squeeze=False)
    frames = []
    for ax, a in zip(axes[0], amps, strict=True):
        for preset, label in (("metal", "adaptive flywheel"), ("none", "traditional")):
            r = _curve(a, "sihb", settings.quick, "thesis", preset).branch("down")
            ax.plot(r.freq_hz, r.amplitude_m / (a / 100.0), label=label)
            df = r.to_pandas()[["freq_hz", "amplitude_m"]]
            df.insert(0, "suspension", label)
            df.insert(0, "amplitude_cm", a)
            frames.append(df)
        ax.set_xlim(0, 4)
        ax.set_title(f"B = {a} cm")
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("X1 / B [-]")
        ax.legend(fontsize=8)
    fig.tight_layout()
    return FigureResult(
        figure_id="Fig. 7.9",
        title="Displacement transmissibility: traditional suspension and adaptive flywheel",
        figure=fig,
        data=pd.concat(frames, ignore_index=True),
        caption="Scan down, H = 15. The inerter lowers the resonance and raises its peak.",
    )


def figure_convergence(settings: ReproduceSettings) -> FigureResult:
    """NRMSE against brute force as H and the number of time samples N grow (B = 3 cm)."""
    import pandas as pd

    from ..plotting import _plt

    plt = _plt()
    sys = chapter7_system(0.03)
    grid = frequency_grid(0.25, 2.75, 0.5 if settings.quick else 0.05)
    ref = frequency_response(sys, "brute", freq_hz=grid)
    rows = []
    hs = (1, 3, 5, 7, 11, 15) if settings.quick else (1, 3, 5, 7, 11, 15, 21, 31)
    for h in hs:
        r = frequency_response(sys, "mhb", freq_hz=grid, harmonics=h, stability=False)
        rows.append({"study": "harmonics", "harmonics": h, "n_samples": r.settings["n_samples"],
                     "nrmse": nrmse(r, ref)})  # fmt: skip
    # N from the smallest power of two free of aliasing for the cubic-order terms,
    # (d+1)H+1 = 61 at H = 15: fewer samples alias (and frequency_response warns)
    n_min = 4 * 15 + 1
    for n in (m for m in (32, 64, 128, 256, 512) if m >= n_min):
        r = frequency_response(sys, "mhb", freq_hz=grid, harmonics=15, n_samples=n, stability=False)
        rows.append({"study": "samples", "harmonics": 15, "n_samples": n, "nrmse": nrmse(r, ref)})
    df = pd.DataFrame(rows)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.6))
    h = df[df.study == "harmonics"]
    a1.semilogy(h.harmonics, h.nrmse, "o-")
    a1.set_xlabel("harmonics H")
    a1.set_ylabel("NRMSE vs brute force [-]")
    s = df[df.study == "samples"]
    a2.loglog(s.n_samples, s.nrmse, "o-", base=2)
    a2.set_xlabel("time samples per period N (H = 15)")
    for ax in (a1, a2):
        ax.grid(True, which="both", lw=0.3)
    fig.tight_layout()
    return FigureResult(
        figure_id="Fig. 7.C",
        title="Convergence of harmonic balance in H and in N (B = 3 cm, metal, thesis law)",
        figure=fig,
        data=df,
        caption="The error falls with H until it meets the brute-force accuracy; N starts at "
        "the first power of two above (d+1)H+1 = 61, below which the nonlinear terms alias.",
    )


TABLES = {"7.1": table_7_1, "7.2": table_7_2, "7.3": table_7_3, "7.4": table_7_4}
FIGURES = {
    "Fig. 7.2": _comparison_figure("Fig. 7.2", "shb", "Single harmonic balance and brute force"),
    "Fig. 7.4": _comparison_figure("Fig. 7.4", "mhb", "Multi-harmonic balance and brute force"),
    "Fig. 7.7": _comparison_figure(
        "Fig. 7.7", "sihb", "Scanning iterative multi-harmonic balance and brute force"
    ),
    "Fig. 7.9": figure_7_9,
    "Fig. 7.C": figure_convergence,
}
