"""The HTML design report: one self-contained file (figures embedded as PNG).

Figures: every candidate's expected value and gain over ``k | c`` with their 95 %
intervals; for the quarter car the H2 Pareto fronts of the best layouts and ``k | c``
(comfort against road holding, :func:`inerterlab.network_design.pareto_front`), |H(f)|
of body acceleration per unit road velocity of the linear winners against ``k | c``, the
PSDs of body acceleration and of its ISO 2631-1 Wk-weighted version on one long ISO
8608 road (Welch) and the body acceleration after a 5 cm bump; for a half or full car
the PSD of the Wk-weighted seat (or bounce) acceleration of the linear winners by the
spectral method, the linear Pareto fronts of the objective against the axles' RMS
suspension deflection (H2) of ``k | c`` and the best layouts, and the seat (or bounce)
acceleration after a bump under the front then the rear wheels. Tables: the ranking (expected values with intervals), the layouts'
linear optima and the device requirements.
"""

from __future__ import annotations

import base64
import html
import io
import math

import numpy as np

__all__ = ["figures", "render_html"]


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _winners(result: dict, n: int = 3) -> list[dict]:
    """k | c, the best linear candidates and the best device candidate."""
    rows = result["ranking"]
    out = [r for r in rows if r["label"] == "k | c"]
    out += [r for r in rows if r["kind"] in ("layout", "synthesis")][:n]
    out += [r for r in rows if r["kind"] == "device"][:1]
    return out


def figures(result: dict) -> dict:
    """{title: base64 PNG} of the report's figures (from :func:`run_design`'s result)."""
    from matplotlib.figure import Figure
    from scipy.signal import welch

    from .. import excitation as ex
    from ..metrics import weighted_acceleration
    from ..network_design import pareto_figure, pareto_front
    from ..systems import quarter_car
    from .scoring import SCORE_RTOL

    st = result["settings"]
    win = _winners(result)
    out = {"Expected values with their 95 % intervals (time domain, road realisations)":
           _png(_ranking_figure(result))}  # fmt: skip
    if st.get("model", "quarter") in ("half", "full"):
        out.update(_vehicle_figures(result, win))
        return out
    car = {k: st[k] for k in ("sprung_mass", "unsprung_mass", "tyre_stiffness", "tyre_damping")}

    # Pareto fronts (H2, linear)
    lin = [r["network"] for r in win if r["kind"] in ("reference", "layout")][:3]
    try:
        ds = pareto_front(lin, ("body_acc", "tyre_deflection"), points=6,
                          fixed={"k": st["stiffness"]}, seed=st["seed"], **car)  # fmt: skip
        fig = pareto_figure(ds)
        fig.axes[0].set_xlabel("tyre deflection H2 norm [m per m/s road velocity], linear")
        fig.axes[0].set_ylabel("body acceleration H2 norm [m/s^2 per m/s], linear")
        out["Pareto fronts: comfort against road holding (H2, linear)"] = _png(fig)
    except Exception as e:  # noqa: BLE001 - a figure that cannot be drawn is said, not fatal
        out["Pareto fronts"] = f"not drawn: {e}"

    # |H(f)|
    f = np.geomspace(0.3, 30.0, 300)
    fig = Figure(figsize=(6.4, 4.2))
    ax = fig.add_subplot(1, 1, 1)
    for r in win:
        if r["kind"] == "device":
            continue
        net, par = r["core"]["network"], r["core"]["params"]
        h = quarter_car(net, par, **dict(car or {})).transfer(2 * np.pi * f, "body_acc")
        ax.loglog(f, np.abs(h), label=r["label"], lw=2.0 if r["label"] == "k | c" else 1.2)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|H| body acceleration per road velocity [m/s^2 per m/s]")
    ax.set_title("|H(f)| of the linear winners against k | c (linear)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    out["|H(f)|: body acceleration per unit road velocity (linear)"] = _png(fig)

    # PSDs on one long road, and a bump
    horizon = 30.0
    road = ex.iso8608(st["road_class"], st["speed"], seed=st["seed"] + 999_999)
    fig = Figure(figsize=(9.0, 3.8), layout="constrained")
    a1, a2 = fig.subplots(1, 2)
    fig_b = Figure(figsize=(6.4, 3.8))
    ab = fig_b.add_subplot(1, 1, 1)
    for r in win:
        net, par = r["core"]["network"], r["core"]["params"]
        sys = quarter_car(net, par, **dict(car or {}))
        res = sys.simulate(road, horizon=horizon, rtol=st.get("rtol", SCORE_RTOL))
        acc = res.outputs["body_acc"]
        aw = weighted_acceleration(res.time, acc)
        fs = 1.0 / (res.time[1] - res.time[0])
        fr, p = welch(acc, fs=fs, nperseg=4096)
        _, pw = welch(aw, fs=fs, nperseg=4096)
        keep = (fr > 0.2) & (fr < 40)
        a1.loglog(fr[keep], p[keep], label=r["label"], lw=0.9)
        a2.loglog(fr[keep], pw[keep], label=r["label"], lw=0.9)
        rb = sys.simulate(ex.bump(0.05), horizon=3.0)
        ab.plot(rb.time, rb.outputs["body_acc"], label=r["label"], lw=0.9)
    for a, t in ((a1, "body acceleration"), (a2, "Wk-weighted body acceleration")):
        a.set_xlabel("frequency [Hz]")
        a.set_ylabel("PSD [(m/s^2)^2/Hz]")
        a.set_title(f"{t}, one {horizon:g} s road", fontsize=9)
        a.grid(True, which="both", alpha=0.3)
    a1.legend(fontsize=6)
    out[
        f"PSD of body acceleration, plain and ISO 2631-1 Wk weighted (one {horizon:g} s ISO 8608 road, time domain)"
    ] = _png(fig)
    ab.set_xlabel("time [s]")
    ab.set_ylabel("body acceleration [m/s^2]")
    ab.set_title("5 cm, 10 ms bump (time domain)")
    ab.grid(True, alpha=0.3)
    ab.legend(fontsize=7)
    out["Bump: body acceleration after a 5 cm, 10 ms bump (time domain)"] = _png(fig_b)
    return out


def _ranking_figure(result: dict):
    """Every candidate's expected value with its 95 % interval, and its gain over
    k | c on the same roads with that interval."""
    from matplotlib.figure import Figure

    rows = result["ranking"]
    obj = result["objective"]
    fig = Figure(figsize=(9.0, 0.35 * len(rows) + 1.6), layout="constrained")
    a1, a2 = fig.subplots(1, 2, sharey=True)
    y = np.arange(len(rows))[::-1]
    a1.errorbar([r["expected"] for r in rows], y, xerr=[r["interval95"] for r in rows],
                fmt="o", capsize=3)  # fmt: skip
    a2.errorbar([r["gain_percent"] for r in rows], y, xerr=[r["gain_interval95"] for r in rows],
                fmt="o", capsize=3, color="C1")  # fmt: skip
    a2.axvline(0.0, color="k", lw=0.8)
    a1.set_yticks(y)
    a1.set_yticklabels([r["label"] for r in rows], fontsize=7)
    a1.set_xlabel(f"{obj['name']} [{obj['unit']}], expected value and 95 % interval")
    a2.set_xlabel("gain vs k | c on the same roads [%] (+ is better), 95 % interval")
    for a in (a1, a2):
        a.grid(True, alpha=0.3)
    fig.suptitle(obj["time_domain"], fontsize=8)
    return fig


def _vehicle_figures(result: dict, win: list) -> dict:
    """PSDs of the Wk-weighted seat (or bounce) acceleration of the linear winners on
    the band-limited ISO 8608 road (spectral method, linear)."""
    from matplotlib.figure import Figure

    from ..vehicles import linear_vehicle, road_spectrum, spectral_response
    from .vehicle import candidate_vehicle

    st = result["settings"]
    car = {"vehicle": st["vehicle"], "model": st["model"]}
    fig = Figure(figsize=(6.4, 4.2))
    ax = fig.add_subplot(1, 1, 1)
    fig_h = Figure(figsize=(6.4, 4.2))
    ax_h = fig_h.add_subplot(1, 1, 1)
    f = np.geomspace(0.3, 30.0, 300)
    name = "?"
    for r in win:
        if r["kind"] == "device":
            continue
        veh = linear_vehicle(candidate_vehicle(car, r["core"]))
        out = "seat_acc" if "seat_acc" in veh.outputs else "bounce_acc"
        h = veh.frequency_response(f, [out])[out][:, 0]  # from the front (left) wheel's road
        ax_h.loglog(f, np.abs(h), label=r["label"], lw=1.2)
        res = spectral_response(veh, road_spectrum(st["road_class"]), st["speed"], points=1500)
        name = "seat_acc_wk" if "seat_acc_wk" in res.psd else "bounce_acc_wk"
        ax.loglog(res.freq, res.psd[name],
                  label=f"{r['label']} (RMS {res.rms[name]:.3g} m/s^2)", lw=1.2)  # fmt: skip
    ax.set_xlim(0.3, 40.0)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"PSD of {name} [(m/s^2)^2/Hz]")
    ax.set_title("Wk-weighted acceleration, linear, spectral method (ISO 8608 band)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax_h.set_xlabel("frequency [Hz]")
    ax_h.set_ylabel(f"|H| of {out} per m of road height under the front (left) wheel [(m/s^2)/m]")
    ax_h.set_title("Transfer from one front wheel's road height (linear)", fontsize=9)
    ax_h.grid(True, which="both", alpha=0.3)
    ax_h.legend(fontsize=7)
    figs = {
        f"|H(f)| of {out}: the linear winners against k | c (linear)": _png(fig_h),
        f"PSD of {name}: the linear winners against k | c (linear, spectral method)": _png(fig),
    }
    figs.update(_vehicle_pareto(result, win))
    figs.update(_vehicle_bump(result, win))
    return figs


def _vehicle_pareto(result: dict, win: list) -> dict:
    """The linear fronts of the study's objective against the axles' RMS suspension
    deflection (:func:`inerterlab.design.vehicle.linear_pareto_front`) of k | c and the
    best linear layouts, each from its own optimum (four weighted sums, at most 30
    L-BFGS-B iterations each)."""
    from matplotlib.figure import Figure

    from .vehicle import linear_pareto_front

    st = result["settings"]
    car = {"vehicle": st["vehicle"], "model": st["model"]}
    obj = result["objective"]["name"]
    rows = {r["network"]: r for r in result["layouts"] if r.get("objective") is not None}
    title = (f"Pareto fronts: {obj} against suspension deflection (H2, linear, white road "
             f"velocity scaled to ISO 8608 class {st['road_class']} at {st['speed']:g} m/s)")  # fmt: skip
    fig = Figure(figsize=(6.4, 4.2))
    ax = fig.add_subplot(1, 1, 1)
    why = []
    for r in win:
        if r["kind"] not in ("reference", "layout"):
            continue
        lay = rows.get(r["network"])
        if lay is None:
            why.append(f"{r['label']}: no linear optimum of its layout")
            continue
        bounds = {n: [min(lo, st["max_inertance"] / 10), st["max_inertance"]]
                  for n, (lo, _) in _inertance_design(r["network"]).items()}  # fmt: skip
        try:
            front = linear_pareto_front(car, r["network"], obj, lay["parameters"], bounds=bounds,
                                        road_class=st["road_class"], speed=st["speed"],
                                        weights=(1.0, 0.7, 0.5, 0.3), maxiter=30)  # fmt: skip
        except Exception as e:  # noqa: BLE001 - a front that cannot be drawn is said
            why.append(f"{r['label']}: {str(e).splitlines()[0]}")
            continue
        ax.loglog([1e3 * q["deflection"] for q in front], [q["objective"] for q in front], "o-",
                label=r["label"], lw=2.0 if r["label"] == "k | c" else 1.2, ms=4)  # fmt: skip
    if not ax.lines:
        return {title: "not drawn: " + "; ".join(why or ["no linear layout"])}
    half = " of the pitch-plane half car" if st["model"] == "full" else ""
    ax.set_xlabel(f"RMS suspension deflection of the axles{half} [mm], H2, linear")
    ax.set_ylabel(f"RMS {obj} [m/s^2], H2, linear")
    ax.set_title("Weighted sums of the two, each layout from its own optimum (right end)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    out = {title: _png(fig)}
    for w in why:
        out[f"Pareto front not drawn for {w.split(':')[0]}"] = "not drawn: " + w
    return out


def _inertance_design(network: str) -> dict:
    """Inerter name -> its design range (the design's bounds raise the upper end to the
    inertance limit)."""
    from ..network_design import design_parameters
    from ..networks import parse_network

    net = parse_network(network)
    dp = design_parameters(network)
    return {n: dp[n].design for n, k in zip(net.names, net.kinds, strict=True) if k == "b"}


#: the vehicle bump: height [m], length of the pulse [s], time the front wheels reach it [s]
BUMP = (0.05, 0.01, 0.1)


def _vehicle_bump(result: dict, win: list) -> dict:
    """Seat (or bounce) acceleration after a 5 cm, 10 ms bump under both front wheels,
    the rear wheels reaching it a wheelbase later at the study's speed (time domain,
    the core's simulation with one-sided tyres)."""
    from matplotlib.figure import Figure

    from ..vehicles.simulation import simulate_vehicle
    from .vehicle import candidate_vehicle

    st = result["settings"]
    car = {"vehicle": st["vehicle"], "model": st["model"]}
    h, dur, t0 = BUMP
    dt, horizon = 1e-3, 3.0
    t = np.arange(int(round(horizon / dt)) + 1) * dt
    title = (f"Bump: acceleration after a {100 * h:g} cm, {1e3 * dur:g} ms bump under the front "
             f"wheels, the rear wheels a wheelbase later at {st['speed']:g} m/s (time domain)")  # fmt: skip
    fig = Figure(figsize=(6.4, 4.2))
    ax = fig.add_subplot(1, 1, 1)
    why, sig = [], "?"
    for r in win:
        try:
            p = candidate_vehicle(car, r["core"])
            delay = p.wheelbase / float(st["speed"])
            front = np.where((t >= t0) & (t < t0 + dur), h, 0.0)
            rear = np.where((t >= t0 + delay) & (t < t0 + delay + dur), h, 0.0)
            n = 4 if type(p).__name__ == "FullCar" else 2
            cols = [front] * (n // 2) + [rear] * (n // 2)
            res = simulate_vehicle(p, np.column_stack(cols), dt, lift_off=True)
        except Exception as e:  # noqa: BLE001 - a run that cannot be drawn is said
            why.append(f"{r['label']}: {str(e).splitlines()[0]}")
            continue
        sig = res.comfort["signal"]
        ax.plot(res.time, res.outputs[sig], label=r["label"],
                lw=1.6 if r["label"] == "k | c" else 0.9)  # fmt: skip
    if not ax.lines:
        return {title: "not drawn: " + "; ".join(why)}
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"{sig} [m/s^2]")
    ax.set_title(f"{sig}, one-sided tyres, road heights linear between 1 ms samples", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    out = {title: _png(fig)}
    for w in why:
        out[f"Bump not drawn for {w.split(':')[0]}"] = "not drawn: " + w
    return out


def _fmt(x, spec=".4g") -> str:
    if x is None:
        return "-"
    if isinstance(x, float) and not math.isfinite(x):
        return "-"
    return format(x, spec) if isinstance(x, int | float) else html.escape(str(x))


def _params(p: dict) -> str:
    return ", ".join(
        f"{k}={v:.4g}" if isinstance(v, int | float) else f"{k}={v}" for k, v in p.items()
    )


def render_html(result: dict, figs: dict) -> str:
    """The report as one HTML text."""
    st = result["settings"]
    obj = result["objective"]
    e = html.escape
    rows = []
    for r in result["ranking"]:
        params = _params(r["parameters"])
        rows.append(
            f"<tr><td>{r['rank']}</td><td>{e(r['label'])}</td><td>{e(r['kind'])}</td>"
            f"<td>{_fmt(r['expected'])} &plusmn; {_fmt(r['interval95'], '.2g')}</td>"
            f"<td>{_fmt(r['gain_percent'], '+.2f')} &plusmn; {_fmt(r['gain_interval95'], '.2f')}</td>"
            f"<td>{_fmt(r['rms_deflection'])}</td><td>{_fmt(r['rms_tyre_load'])}</td>"
            f"<td>{'yes' if r['limits_met'] else 'no'}</td><td>{e(params)}</td></tr>"
        )
    lay = []
    for r in result["layouts"]:
        if r.get("objective") is None:
            lay.append(
                f"<tr><td>{e(r['network'])}</td><td colspan=4>{e(r.get('reason', ''))}</td></tr>"
            )
            continue
        params = _params(r["parameters"])
        lay.append(
            f"<tr><td>{e(r['network'])}</td><td>{_fmt(r['objective'])}</td>"
            f"<td>{_fmt(r.get('h2_improvement'), '+.2f')}</td><td>{e(r.get('simpler') or '')}</td>"
            f"<td>{e(params)}</td></tr>"
        )
    req = "".join(
        f"<li>{e(q['device'])} in {e(q['layout'])}: {e(q.get('text') or q.get('reason', ''))}"
        + (f" (identified: {q['identified']:.4g} {e(q['unit'])})" if q.get("identified") else "")
        + "</li>"
        for q in result["requirements"]
    )
    dl = "".join(
        f"<tr><td>{e(q['device'])}</td><td>{e(q['layout'])}</td><td>{_fmt(q['h2'])}</td>"
        f"<td>{_fmt(q['h2_improvement'], '+.2f')}</td><td>{e(q.get('simpler') or '')}</td></tr>"
        for q in sorted(result.get("device_linear", []), key=lambda q: (q["device"], q["h2"]))
    )
    figs_html = "".join(
        f"<h3>{e(t)}</h3>"
        + (
            f'<img alt="{e(t)}" src="data:image/png;base64,{b}">'
            if not b.startswith("not drawn")
            else f"<p>{e(b)}</p>"
        )
        for t, b in figs.items()
    )
    notes = "".join(f"<li>{e(n)}</li>" for n in result["notes"])
    if st.get("model", "quarter") in ("half", "full"):
        car = (
            f"the {st['model']} car of {e(st['source'])}, the same layout at every corner with "
            f"its values per axle, main springs held at the file's wheel rates (front "
            f"{st['stiffness']['front']:g} N/m, rear {st['stiffness']['rear']:g} N/m)"
        )
    else:
        car = (
            f"sprung mass {st['sprung_mass']:g} kg, unsprung mass {st['unsprung_mass']:g} kg, "
            f"tyre {st['tyre_stiffness']:g} N/m and {st['tyre_damping']:g} N s/m, main spring "
            f"{st['stiffness']:g} N/m ({e(st['source'])})"
        )
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>inerterlab design report</title>
<style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto;}}
table{{border-collapse:collapse;font-size:90%}}td,th{{border:1px solid #bbb;padding:3px 6px}}
img{{max-width:100%}}</style></head><body>
<h1>Suspension design report</h1>
<p>Car: {car}. Road: ISO 8608 class {e(st["road_class"])} at {st["speed"]:g} m/s.
Budget: {st["springs"]} springs, {st["dampers"]} dampers, {st["inerters"]} inerters
(inertance at most {st["max_inertance"]:g} kg). Objective: {e(obj["name"])} [{e(obj["unit"])}],
scored as the {e(obj["time_domain"])}; the layouts were searched with the H2 norm of
{e(obj["h2_objective"])} (linear, white road velocity).</p>
<h2>Ranking</h2>
<p>Expected value of {e(obj["name"])} [{e(obj["unit"])}] &plusmn; 95 % interval of the
expected value; gain over the optimised k | c on the same roads [%] &plusmn; its 95 % interval
(positive: better). Deflection [m RMS] and tyre load [N RMS] are expected values.</p>
<table><tr><th>rank</th><th>candidate</th><th>kind</th><th>{e(obj["name"])} [{e(obj["unit"])}]</th>
<th>gain vs k | c [%]</th><th>deflection [m]</th><th>tyre load [N]</th><th>limits met</th>
<th>parameters [SI]</th></tr>{"".join(rows)}</table>
<h2>Device requirements</h2>
<p>The friction or parasitic damping at which the ideal design of the device's layout,
built with the device (its stiffness as identified, the other loss off), loses its
expected gain over k | c on {st["tune_roads"]} tuning roads (the ITP method on the gain
crossing zero, in the logarithm).</p><ul>{req or "<li>no device candidates</li>"}</ul>
<h2>Devices in every layout (H2, linear, the device's stiffness and damping held)</h2>
<table><tr><th>device</th><th>layout</th><th>H2 norm</th><th>vs k | c [%]</th><th>stands for</th></tr>{dl}</table>
<h2>Figures</h2>{figs_html}
<h2>Layouts (H2 optimum, linear)</h2>
<table><tr><th>layout</th><th>H2 norm [{e(result["layouts"][0].get("h2_unit", ""))}]</th>
<th>vs k | c [%]</th><th>stands for</th><th>parameters [SI]</th></tr>{"".join(lay)}</table>
<h2>Notes</h2><ul>{notes or "<li>none</li>"}</ul>
<p>Computed in {result["seconds"]:.1f} s.</p>
</body></html>
"""
