"""Beyond the thesis: in which layout does an inerter, adaptive or real, pay?

One figure: the H2-optimal series layouts of docs/guide/networks.md with the ideal
inerter replaced by adaptive flywheels and by the thesis's real devices, simulated by
the model core on a bump and an ISO 8608 road (:mod:`inerterlab.network_truth`). The
report runs a reduced version (5 s of simulated time) of ``inerterlab network truth`` (two layouts, eight
variants, two inputs); its caption and verdict are computed from the numbers. The
bump is one deterministic input; the ISO 8608 road is a random one, so its gains are
expected values over :data:`ROADS` realisations (seeds 1..ROADS, each gain taken against
``k | c`` on the same road) with the 95 % interval of the expected value.
"""

from __future__ import annotations

import pandas as pd

from ..network_truth import LAYOUTS as LAYOUTS_TEXT
from .registry import FigureResult, ReproduceSettings

VARIANTS = (
    "ideal",
    "ideal-max x=0.285",
    "afw x=0.285 law=thesis",
    "ideal-max x=0.55",
    "afw x=0.55 law=thesis",
    "hydraulic",
    "screw",
    "fluid",
)
#: comfort gain [points of %] over the better bracketing constant inerter from which
#: adaptivity counts as helping
HELPS_POINTS = 0.5
LAYOUT_NAMES = ("series", "series-spring")
INPUT_NAMES = ("bump", "iso-c")
#: road realisations of the ISO 8608 input (quick report: QUICK_ROADS)
ROADS, QUICK_ROADS = 8, 3


def figure_layouts(settings: ReproduceSettings) -> FigureResult:
    from matplotlib.figure import Figure

    from ..network_truth import network_truth

    LAYOUTS = LAYOUTS_TEXT

    from ..design.scoring import expected

    horizon = 2.0 if settings.quick else 5.0
    roads = QUICK_ROADS if settings.quick else ROADS
    common = dict(layouts=LAYOUT_NAMES, variant_list=list(VARIANTS), horizon=horizon,
                  backend="serial")  # fmt: skip
    bump = network_truth(inputs=("bump",), **common).gains["rms_body_acc_wk"]
    road = [network_truth(inputs=("iso-c",), seed=s, **common).gains["rms_body_acc_wk"]
            for s in range(1, roads + 1)]  # fmt: skip
    rows = []
    for lay in LAYOUT_NAMES:
        for v in VARIANTS:
            for inp in INPUT_NAMES:
                if inp == "bump":
                    g, half = float(bump.sel(layout=lay, variant=v, input=inp)), 0.0
                else:
                    e = expected([float(x.sel(layout=lay, variant=v, input=inp)) for x in road])
                    g, half = e["mean"], e["half_width"]
                rows.append(
                    {
                        "layout": lay,
                        "network": LAYOUTS[lay],
                        "variant": v,
                        "input": inp,
                        "comfort_gain_percent": g,
                        "comfort_gain_interval95": half,
                        "roads": 1 if inp == "bump" else roads,
                    }
                )
    data = pd.DataFrame(rows)
    ideal = data[data.variant == "ideal"].set_index(["layout", "input"]).comfort_gain_percent
    data["survival"] = [
        r.comfort_gain_percent / ideal[(r.layout, r.input)] for r in data.itertuples()
    ]
    fig = Figure(figsize=(9.0, 3.8), layout="constrained")
    axes = fig.subplots(1, len(INPUT_NAMES), sharey=True)
    width = 0.8 / len(LAYOUT_NAMES)
    for ax, inp in zip(axes, INPUT_NAMES, strict=True):
        for i, lay in enumerate(LAYOUT_NAMES):
            sel = data[(data.layout == lay) & (data.input == inp)]
            xs = [j + (i - 0.5 * (len(LAYOUT_NAMES) - 1)) * width for j in range(len(VARIANTS))]
            ax.bar(xs, sel.comfort_gain_percent, width, label=f"{lay}: {LAYOUTS[lay]}",
                   yerr=sel.comfort_gain_interval95 if inp != "bump" else None, capsize=2)  # fmt: skip
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xticks(range(len(VARIANTS)))
        ax.set_xticklabels(
            [v.replace(" law=thesis", "") for v in VARIANTS], rotation=30, ha="right"
        )
        ax.set_title(
            f"input: {inp}" + ("" if inp == "bump" else
                               f", expected value over {roads} roads, 95 % interval"),
            fontsize=9,
        )  # fmt: skip
        ax.grid(axis="y", alpha=0.3)
    axes[0].set_ylabel("comfort gain vs optimised k | c [%]\n(ISO 2631 Wk RMS, + is better)")
    axes[0].legend(fontsize=7)
    caption, margin = _caption(data)
    caption += (f" The iso-c gains are expected values over {roads} road realisations of "
                f"{horizon:g} s with the 95 % interval of the expected value.")  # fmt: skip
    holds = bool(margin >= HELPS_POINTS)
    verdict = adaptivity_verdict(margin)
    return FigureResult(
        figure_id="Layouts",
        title="Which layout lets an inerter pay: ideal, adaptive and real inerters in the "
        "H2-optimal series layouts",
        figure=fig,
        data=data,
        caption=caption,
        statement="an adaptive flywheel improves ride comfort (the thesis's premise), tested "
        "here beyond the thesis's layout, in the H2-optimal series layouts",
        verdict=verdict,
        holds=holds,
        judges=f"whether an adaptive flywheel beats the better of the two constant inerters "
        f"that bracket its inertance by at least {HELPS_POINTS:g} points of comfort",
    )


def adaptivity_verdict(margin: float) -> str:
    """The verdict on the best comfort margin [points] of an adaptive flywheel over the
    better of its two bracketing constant inerters, worded for its sign."""
    where = (
        "the better of the two constant inerters that bracket its inertance, in both "
        "optimised layouts and on both inputs"
    )
    if margin < 0:
        return (
            f"Adaptivity never beats {where}: at best it is {-margin:.2f} points of comfort "
            "behind; it does not help."
        )
    if margin < HELPS_POINTS:
        return (
            f"Adaptivity adds at most {margin:.2f} points of comfort over {where}, less than "
            f"the {HELPS_POINTS:g} points counted as a gain; it does not help."
        )
    return f"Adaptivity adds up to {margin:.2f} points of comfort over {where}: it helps somewhere."


def _caption(data: pd.DataFrame) -> tuple[str, float]:
    parts = []
    overall = -float("inf")
    for lay in LAYOUT_NAMES:
        d = data[data.layout == lay].set_index(["variant", "input"]).comfort_gain_percent
        ideal = {i: d[("ideal", i)] for i in INPUT_NAMES}
        margins = []
        for v in VARIANTS:
            if not v.startswith("afw"):
                continue
            x = v.split("x=")[1].split()[0]
            for i in INPUT_NAMES:
                ref = max(ideal[i], d[(f"ideal-max x={x}", i)])
                margins.append((d[(v, i)] - ref, v, i))
        best = max(margins)
        overall = max(overall, best[0])
        if best[0] < HELPS_POINTS:
            verdict = (
                "no adaptive flywheel beats the better of the two constant inerters that "
                f"bracket its inertance (best {best[0]:+.2f} points, {best[1]}, {best[2]})"
            )
        else:
            verdict = (
                f"an adaptive flywheel beats both bracketing constant inerters by up to "
                f"{best[0]:.2f} points ({best[1]}, {best[2]})"
            )
        half = data[data.layout == lay].set_index(["variant", "input"]).comfort_gain_interval95
        devices = ", ".join(
            f"{v} {d[(v, 'iso-c')]:+.1f} ± {half[(v, 'iso-c')]:.1f} %"
            for v in ("hydraulic", "screw", "fluid")
        )
        parts.append(
            f"In {lay} ({LAYOUTS_TEXT[lay]}) the ideal inerter gains "
            + " and ".join(f"{ideal[i]:+.1f} % on {i}" for i in INPUT_NAMES)
            + f" (iso-c ± {half[('ideal', 'iso-c')]:.1f})"
            + f" against the optimised k | c; {verdict}; with the real devices the gain on "
            f"the ISO road becomes {devices}."
        )
    return " ".join(parts), overall


FIGURES = {"Layouts": figure_layouts}
