"""The design study: which layout, how much, and with which real device, for one car.

The car is a quarter car, or the half or full car of a vehicle file with the same
layout at every corner and its values per axle (:mod:`inerterlab.design.vehicle`: the
linear stage by the vehicle's Lyapunov H2, the scores by vehicle simulations); the
stages below are the same for both.

Stages (each a sweep of :mod:`inerterlab.design.scoring`, stored under ``<out>/stores``
as ``<stage>-<key>.zarr``, the key a digest of the stage's sweep and of the code that
computes it, so a rerun resumes and a change recomputes the stages it changes):

1. every layout of the budget (:func:`inerterlab.networks.enumerate_networks`, bounded
   by :func:`inerterlab.network_design.check_budget`) optimised by the H2 optimiser
   (:func:`inerterlab.network_design.optimize_network`: Sobol sample, differential
   evolution and gradient polish), the main spring held at the car's static stiffness,
   every inerter bounded by ``max_inertance``;
2. optionally the positive-real optimum of a given McMillan degree
   (:func:`inerterlab.synthesis.synthesize`) and its smallest realisation
   (:func:`inerterlab.synthesis.realise_all`), as one more candidate;
3. every single-inerter layout with each real device, optimised by H2 with the
   device's series stiffness and parallel damping held in the network
   (``design-device-linear``); for each device its best ``recheck`` layouts where it
   acts (an optimum that shorts the device, a spring across it rigid, or leaves it at
   its smallest inertance stands for a simpler layout and is not one) then have the
   inertance searched in the time domain with friction and nonlinear losses
   (``design-device``);
4. every candidate, ``k | c`` included, simulated on ``roads`` ISO 8608 roads by the
   model core: expected value with its 95 % interval, gain over ``k | c`` road by road;
5. for each device's best candidate, the friction and parasitic damping at which its
   gain over ``k | c`` vanishes (``design-requirement`` point, the ITP crossing).

The linear objective and the time-domain score are the same quantity where the H2
optimiser has it: ``body_acc`` (RMS body acceleration), ``tyre_load`` (RMS dynamic
tyre-spring force; the H2 stage minimises the tyre deflection, k_t times smaller),
``weighted``; ``body_acc_wk`` is scored in the time domain with the ISO 2631-1 Wk
weighting and searched in the H2 stage by the optimiser's own ``body_acc_wk`` when it
has one (else by ``body_acc``, said in the result's notes).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from ..errors import DataFileError, ParameterError
from . import scoring
from .scoring import DEVICES, OBJECTIVE_METRIC, SCORE_METRICS, SCORE_RTOL, candidate_text

__all__ = [
    "DesignSettings",
    "DESIGN_OBJECTIVES",
    "road_velocity_scale",
    "estimate",
    "check_out_folder",
    "run_design",
]

DESIGN_OBJECTIVES = ("seat_wk", "body_acc_wk", "body_acc", "tyre_load", "weighted")
_OUT_MEMBERS = ("stores", "design.json", "report.html")
_STORES = (
    "layouts.zarr",
    "devices_linear.zarr",
    "devices.zarr",
    "scores.zarr",
    "requirements.zarr",
)
#: seeds of the tuning roads (device stage, requirements) start here; the scoring
#: roads start at ``seed``, so the two sets never share a road for seeds below this
TUNE_SEED_OFFSET = 1_000_000


@dataclass(frozen=True)
class DesignSettings:
    """Everything a design study depends on (its stores are keyed on these)."""

    sprung_mass: float = 370.0
    unsprung_mass: float = 25.0
    tyre_stiffness: float = 120_000.0
    tyre_damping: float = 1300.0
    stiffness: float = 90_000.0
    road_class: str = "C"
    speed: float = 25.0
    springs: int = 2
    dampers: int = 1
    inerters: int = 1
    objective: str = "body_acc"
    limits: dict = field(default_factory=dict)  # deflection [m RMS], tyre_load [N RMS]
    max_inertance: float = 2000.0
    devices: tuple = DEVICES
    synthesize: int = 0
    roads: int = 20
    tune_roads: int = 4
    horizon: float = 10.0
    seed: int = 0
    top: int = 4
    recheck: int = 1
    source: str = "options"
    #: a half or full car: the vehicle file's TOML text (the stores are keyed on it) and
    #: the model ('half' or 'full'); empty for the quarter car of the values above
    vehicle: str = ""
    model: str = "quarter"
    #: numerical settings: most adaptive steps per simulated road, the factor either side
    #: of the H2 inertance the time-domain device search spans, the requirement's accuracy
    #: in halvings of its range
    max_steps: int = 400_000
    device_span: float = 3.0
    bisections: int = 8
    #: relative tolerance of the adaptive quarter-car simulations (the device
    #: candidates; the linear ones run exact steps), :data:`.scoring.SCORE_RTOL`
    rtol: float = SCORE_RTOL

    @property
    def is_vehicle(self) -> bool:
        return self.model in ("half", "full")

    @property
    def car(self) -> dict:
        if self.is_vehicle:
            return {"vehicle": self.vehicle, "model": self.model}
        return {
            "sprung_mass": self.sprung_mass,
            "unsprung_mass": self.unsprung_mass,
            "tyre_stiffness": self.tyre_stiffness,
            "tyre_damping": self.tyre_damping,
        }

    def check(self) -> DesignSettings:
        from ..errors import check_nonnegative, check_positive, check_seed

        check_positive("--sprung-mass", self.sprung_mass, "kg")
        check_positive("--unsprung-mass", self.unsprung_mass, "kg")
        check_positive("--tyre-stiffness", self.tyre_stiffness, "N/m")
        check_nonnegative("--tyre-damping", self.tyre_damping, "N s/m")
        check_positive("--spring-stiffness", self.stiffness, "N/m")
        if self.road_class not in "ABCDEFGH" or len(self.road_class) != 1:
            raise ParameterError("--road-class", self.road_class, "one of A, B, ..., H")
        if not 0.5 <= self.speed <= 100.0:
            raise ParameterError("--speed", self.speed, "a speed in [0.5, 100] m/s")
        if self.objective not in DESIGN_OBJECTIVES:
            raise ParameterError("--objective", self.objective, ", ".join(DESIGN_OBJECTIVES))
        if self.is_vehicle:
            from .vehicle import VEHICLE_OBJECTIVES, vehicle_car

            vehicle_car(self.vehicle, self.model)
            if self.objective not in VEHICLE_OBJECTIVES:
                raise ParameterError(
                    "--objective", self.objective,
                    ", ".join(VEHICLE_OBJECTIVES) + " for a half or full car (its tyre loads "
                    "and deflections are infinite under white road velocity; limit them "
                    "with --limit, taken on the band-limited road)",
                )  # fmt: skip
            if self.synthesize:
                raise ParameterError(
                    "--synthesize", self.synthesize,
                    "0 for a half or full car (the positive-real synthesis optimises a "
                    "quarter car; design a corner with --corner front|rear)",
                )  # fmt: skip
        elif self.objective == "seat_wk":
            raise ParameterError(
                "--objective",
                "seat_wk",
                "body_acc_wk, body_acc, tyre_load or weighted: the design works on a "
                "quarter car, which has no seat (seat_wk needs the vehicle's seat)",
            )
        for k, v in self.limits.items():
            if k not in ("deflection", "tyre_load"):
                raise ParameterError("--limit", k, "deflection=<m RMS> or tyre_load=<N RMS>")
            if not (math.isfinite(v) and v > 0):
                raise ParameterError(f"--limit {k}", v, "a limit > 0")
        if not 1.0 <= self.max_inertance <= 1e5:
            raise ParameterError("--max-inertance", self.max_inertance, "1 to 100000 kg")
        for d in self.devices:
            if d not in DEVICES:
                raise ParameterError("--devices", d, "a list of " + ", ".join(DEVICES))
        if self.synthesize not in (0, 1, 2, 3):
            raise ParameterError("--synthesize", self.synthesize, "0 (none), 1, 2 or 3")
        if not 2 <= self.roads <= 1000:
            raise ParameterError("--roads", self.roads, "an integer in [2, 1000]")
        if not 1 <= self.tune_roads <= 100:
            raise ParameterError("--tune-roads", self.tune_roads, "an integer in [1, 100]")
        if not 2.0 <= self.horizon <= 600.0:
            raise ParameterError("--horizon", self.horizon, "a duration in [2, 600] s")
        if not 1 <= self.top <= 50:
            raise ParameterError("--top", self.top, "an integer in [1, 50]")
        if not 0 <= self.recheck <= 10:
            raise ParameterError("--recheck", self.recheck, "an integer in [0, 10]")
        check_seed("--seed", self.seed)
        if not 1e-10 <= self.rtol <= 1e-6:
            raise ParameterError("rtol", self.rtol, "a relative tolerance in [1e-10, 1e-6]")
        if self.seed + self.roads >= TUNE_SEED_OFFSET:
            raise ParameterError(
                "--seed", self.seed, f"a seed below {TUNE_SEED_OFFSET - self.roads}"
            )
        return self

    def to_dict(self) -> dict:
        d = asdict(self)
        d["devices"] = list(self.devices)
        if self.is_vehicle:
            from .vehicle import axle_stiffness

            d["stiffness"] = axle_stiffness(self.car)
        return d


def road_velocity_scale(road_class: str, speed: float) -> float:
    """RMS of an output per unit H2 norm under an ISO 8608 road of waviness 2 without
    band limits: the road velocity is then white with one-sided PSD
    G_v = (2 pi n0)^2 Gd(n0) V [m^2/s^2/Hz], so RMS = ||H||_2 sqrt(G_v / 2)
    (||H||_2^2 = (1/pi) int_0^inf |H(jw)|^2 dw)."""
    from ..excitation import ISO8608_CLASSES, ISO8608_N0

    gv = (2 * math.pi * ISO8608_N0) ** 2 * ISO8608_CLASSES[road_class] * speed
    return math.sqrt(gv / 2.0)


def _h2_objective(objective: str) -> tuple[str, str]:
    """The H2 optimiser's objective for a design objective, and a note if it differs."""
    from ..network_design import OBJECTIVES

    if objective in OBJECTIVES:
        return objective, ""
    if objective == "tyre_load":
        return "tyre_deflection", ""
    return "body_acc", (
        f"the linear stage searched with the H2 norm of body_acc (the optimiser has no "
        f"{objective}); candidates are scored on {objective} in the time domain"
    )


# ---------------------------------------------------------------------------------------
# bounds before work


#: measured costs on one core (s): one layout optimisation per free parameter, one
#: second of simulated road for a linear and a device candidate
_COST = {"layout": 0.25, "linear_s": 0.0008, "device_s": 0.012, "synth": 20.0}


def estimate(st: DesignSettings, workers: int = 2) -> dict:
    """Seconds and bytes the study needs, estimated before any work."""
    from ..network_design import check_budget

    n = check_budget(st.dampers, st.inerters, st.springs, cli=True)
    layouts = n["candidates"]
    params = st.springs + st.dampers + st.inerters
    t_layout = layouts * _COST["layout"] * params
    ndev = len(st.devices) * st.recheck
    t_dev = ndev * 12 * st.tune_roads * st.horizon * _COST["device_s"]
    t_dev += layouts * len(st.devices) * _COST["layout"] * (params + 2)
    cands = min(st.top, layouts) + 1 + (1 if st.synthesize else 0)
    t_score = st.roads * st.horizon * (cands * _COST["linear_s"] + ndev * _COST["device_s"])
    nreq = 2 * len(st.devices)
    t_req = nreq * 12 * st.tune_roads * st.horizon * _COST["device_s"]
    t_syn = _COST["synth"] * (4 if st.synthesize == 3 else 1) if st.synthesize else 0.0
    if st.is_vehicle:
        # one vehicle layout (two quarter-car starts and the polish with exact
        # gradients) about 4 s of CPU, a device's linear search about 2 s (a full car,
        # measured on the loaded machine); a second of vehicle road about 2.5 times a
        # quarter car's device candidate
        n_lin = len([d for d in st.devices if d != "fluid"])
        t_layout = layouts * 4.0
        t_dev = ndev * 12 * st.tune_roads * st.horizon * _COST["device_s"] * 2.5
        t_dev += min(layouts, st.top) * n_lin * 2.0
        t_score = st.roads * st.horizon * (cands + ndev) * _COST["device_s"] * 2.5
        t_req *= 2.5
    w = max(1, workers)
    seconds = t_layout / w + t_dev / w + t_score / w + t_req / w + t_syn + 10.0
    # one simulation keeps its samples (1000 per second, ~60 outputs) in memory, per worker
    nbytes = w * st.horizon * 1000 * 80 * 8 + 2e8
    return {"seconds": seconds, "bytes": nbytes, "layouts": layouts, "candidates": cands + ndev}


def check_out_folder(out: Path) -> None:
    """``out`` must be new, empty, or a folder this command wrote (only its members)."""
    out = Path(out)
    if out.is_symlink() and not out.exists():
        raise DataFileError(out, "is a symbolic link to nothing; choose another --out")
    if not out.exists():
        return
    if not out.is_dir():
        raise DataFileError(out, "exists and is not a folder; choose another --out")
    for entry in out.iterdir():
        if entry.name in _OUT_MEMBERS or entry.name.startswith((".design.json", ".report.html")):
            continue
        raise DataFileError(
            out,
            f"holds {entry.name!r}, which 'inerterlab design' did not write (it keeps only "
            f"{', '.join(_OUT_MEMBERS)} there); choose another --out",
        )
    from ..studies.sweep import claim_store_folder

    claim_store_folder(out / "stores", _STORES, keyed=True)


# ---------------------------------------------------------------------------------------
# the stages


#: points computed by the last :func:`run_design` per stage (the rest came from its stores)
COMPUTED: dict = {}
#: the names of the stores the last :func:`run_design` read (the others in its folder
#: are from earlier settings or code: ``unread_stores`` of its result)
READ: set = set()
#: wall seconds of each stage of the last :func:`run_design`
SECONDS: dict = {}
#: CPU seconds of each stage of the last :func:`run_design`, this process and its
#: worker processes (each stage's workers have ended when it returns)
CPU_SECONDS: dict = {}


def process_cpu() -> float:
    """CPU seconds of this process and of its ended child processes."""
    import os

    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def _sweep(point, params, settings, store, workers, progress):
    from ..studies import sweep, sweep_spec
    from ..studies.sweep import keyed_store

    t0 = time.perf_counter()
    c0 = process_cpu()
    backend = "serial" if (workers or 1) <= 1 else "processes"
    spec = sweep_spec(point, parameters=params, settings=settings)
    path = None if store is None else keyed_store(store, spec)
    ds = sweep(
        spec,
        store=path,
        backend=backend,
        workers=workers,
        progress=progress,
    )
    COMPUTED[point] = int(ds.attrs.get("points_computed", 0))
    if path is not None:
        READ.add(path.name)
    SECONDS[point] = time.perf_counter() - t0
    CPU_SECONDS[point] = process_cpu() - c0
    return ds


def _unpack(ds, idx: dict, names: list) -> dict:
    vals = {}
    for i, n in enumerate(sorted(names)):
        vals[n] = float(ds[f"p{i}"].sel(**idx))
    return vals


def run_design(st: DesignSettings, out: Path | None = None, *, workers: int = 1,
               progress=False, say=None) -> dict:  # fmt: skip
    """Run the study (module docstring); returns the result as a JSON-ready dict."""
    from ..network_design import check_budget, design_parameters
    from ..networks import enumerate_networks, parse_network

    st.check()
    COMPUTED.clear()
    READ.clear()
    SECONDS.clear()
    CPU_SECONDS.clear()
    say = say or (lambda text: None)
    t0 = time.perf_counter()
    stores = None
    if out is not None:
        out = Path(out)
        check_out_folder(out)
        stores = out / "stores"
        stores.mkdir(parents=True, exist_ok=True)

    def store(name):
        return None if stores is None else str(stores / name)

    if (workers or 1) > 1:
        c0 = process_cpu()
        _warm_up(st.car if st.is_vehicle else None)
        SECONDS["warm-up"] = time.perf_counter() - t0
        CPU_SECONDS["warm-up"] = process_cpu() - c0

    car = st.car
    h2obj, note = _h2_objective(st.objective)
    if st.is_vehicle:
        h2obj, note = st.objective, ""
    notes = [note] if note else []
    scale = road_velocity_scale(st.road_class, st.speed)
    constraints = {}
    if st.is_vehicle:
        notes.append(
            "vehicle: the same layout at every corner, its values per axle; the linear "
            f"stage minimised the RMS {st.objective} [m/s^2] under white road velocity "
            "(Lyapunov, the Wk filter as states, tracks independent, the rear wheels "
            "delayed by the wheelbase)"
            + ("; limits on the worst corner, spectral method on the band-limited road"
               if st.limits else "")
        )  # fmt: skip
    else:
        if "deflection" in st.limits:
            constraints["suspension_deflection"] = st.limits["deflection"] / scale
        if "tyre_load" in st.limits:
            constraints["tyre_deflection"] = st.limits["tyre_load"] / st.tyre_stiffness / scale
    check_budget(st.dampers, st.inerters, st.springs, cli=True)
    nets = [n.text for n in enumerate_networks(st.dampers, st.inerters, st.springs)]
    if "k | c" not in nets:
        nets.insert(0, "k | c")
    bounds_of = {}
    for text in nets:
        net = parse_network(text)
        bd = {}
        for n, kind in zip(net.names, net.kinds, strict=True):
            if kind == "b":
                lo = design_parameters(text)[n].design[0]
                bd[n] = [min(lo, st.max_inertance / 10), st.max_inertance]
        bounds_of[text] = bd
    common = {
        "car": car,
        "stiffness": st.stiffness,
        "h2_objective": h2obj,
        "objective": st.objective,
        "constraints": constraints,
        "bounds_of": bounds_of,
        "seed": st.seed,
        "limits": dict(st.limits),
        "max_inertance": st.max_inertance,
        "road_class": st.road_class,
        "speed": st.speed,
        "horizon": st.horizon,
        "max_steps": st.max_steps,
        "device_span": st.device_span,
        "bisections": st.bisections,
        "rtol": st.rtol,
        "tune_seeds": list(
            range(TUNE_SEED_OFFSET + st.seed, TUNE_SEED_OFFSET + st.seed + st.tune_roads)
        ),
    }

    # 1. layouts ---------------------------------------------------------------------
    say(f"design: optimising {len(nets)} layouts ({h2obj} H2, linear)")
    keys = ("car", "stiffness", "h2_objective", "constraints", "bounds_of", "seed")
    if st.is_vehicle:
        keys += ("limits", "road_class", "speed")
    layout_settings = {k: common[k] for k in keys}
    if st.is_vehicle:  # every layout searched in the vehicle, on exact gradients (a store
        # of the former first pass, at the quarter-car optima alone, is not reused)
        layout_settings["polish"] = True
    ds = _sweep("design-layout", {"network": nets}, {"settings": json.dumps(layout_settings, sort_keys=True)},
                store("layouts.zarr"), workers, progress)  # fmt: skip
    source = {text: ds for text in nets}
    layouts = []
    for text in nets:
        ds = source[text]
        row = ds.sel(network=text)
        if int(row.status) != 1 or not math.isfinite(float(row.objective)):
            reason = (
                str(row.reason.values)
                if int(row.status) != 1
                else f"no finite H2 norm of {h2obj} anywhere in the bounds (a direct "
                "feed-through from the road, e.g. an inerter beside a damped tyre, or an "
                "unstable car)"
            )
            layouts.append({"network": text, "objective": None, "reason": reason})
            continue
        names = list(design_parameters(text))
        if st.is_vehicle:
            from .vehicle import AXLES

            names = [f"{a}_{n}" for a in AXLES for n in names]
        entry = {
            "network": text,
            "objective": float(row.objective),
            "parameters": _unpack(ds, {"network": text}, names),
        }
        if not st.is_vehicle:  # the quarter car's three H2 norms (a vehicle has none)
            norms = {k: float(row[f"norm_{k}"]) for k in ("body_acc", "tyre_deflection",
                                                          "suspension_deflection")}  # fmt: skip
            entry["norms"] = {k: (v if math.isfinite(v) else None) for k, v in norms.items()}
        layouts.append(entry)
    ok = sorted((r for r in layouts if r["objective"] is not None), key=lambda r: r["objective"])
    base = next((r for r in ok if r["network"] == "k | c"), None)
    if base is None:
        raise ParameterError("car", car, "a car whose k | c has a finite optimum")
    for r in ok:
        r["h2_improvement"] = 100.0 * (1.0 - r["objective"] / base["objective"])
        r["h2_unit"] = _H2_UNIT.get(h2obj, "")
        # linear prediction of the RMS on the chosen road (none for the weighted score)
        r["predicted_rms"] = (
            None
            if h2obj == "weighted"
            else r["objective"] * scale * (st.tyre_stiffness if h2obj == "tyre_deflection" else 1.0)
        )
        if st.is_vehicle:  # the vehicle's linear objective is the RMS itself
            r["h2_unit"] = "m/s^2 RMS (linear, white road velocity)"
            r["predicted_rms"] = r["objective"]
        r["simpler"] = _simpler(r["network"], r["parameters"], bounds_of[r["network"]], st)

    # 2. synthesis ---------------------------------------------------------------------
    candidates = {}  # label -> candidate dict
    candidates["k | c"] = {"kind": "reference", "network": "k | c",
                           "params": scoring.axle_params(base["parameters"], car),
                           **({"values": base["parameters"]} if st.is_vehicle else {})}  # fmt: skip
    for r in [r for r in ok if r["network"] != "k | c" and not r["simpler"]][: st.top]:
        candidates[r["network"]] = {
            "kind": "layout",
            "network": r["network"],
            "params": scoring.axle_params(r["parameters"], car),
            **({"values": r["parameters"]} if st.is_vehicle else {}),
        }
    synth = None
    if st.synthesize:
        say(f"design: positive-real synthesis of degree {st.synthesize}")
        synth = _synthesis(st, h2obj, car, notes)
        if synth and synth.get("network"):
            candidates[f"PR degree {st.synthesize}: {synth['network']}"] = {
                "kind": "synthesis", "network": synth["network"], "params": synth["parameters"],
            }  # fmt: skip

    # 3. devices ---------------------------------------------------------------------
    single = [r for r in ok if r["network"] != "k | c" and not r["simpler"]
              and sum(1 for k in parse_network(r["network"]).kinds if k == "b") == 1]  # fmt: skip
    if st.is_vehicle and st.devices:
        # a vehicle optimisation per (layout, device) costs seconds: the best --top
        # single-inerter layouts where every device can sit at a corner
        from .vehicle import device_misfit, split_axles

        fits = []
        for r in single:
            front = split_axles(r["parameters"])["front"]
            why = next((f"{d}: {w}" for d in st.devices
                        if (w := device_misfit(r["network"], front, d))), "")  # fmt: skip
            if why:
                notes.append(f"devices not tried in {r['network']} ({why})")
            else:
                fits.append(r)
        single = fits[: st.top]
    base_cand = {"network": "k | c", "params": scoring.axle_params(base["parameters"], car)}
    dev_settings = {**common, "reference": json.dumps(base_cand, sort_keys=True)}
    device_linear = []
    jobs = []
    if single and st.devices:
        ideal = json.dumps({r["network"]: r["parameters"] for r in single}, sort_keys=True)
        by_device = {d: [(r["objective"], r["network"], r["parameters"]) for r in single]
                     for d in st.devices}  # fmt: skip
        lin_devs = [d for d in st.devices if d != "fluid"]
        if lin_devs:
            say(f"design: {len(lin_devs)} devices in {len(single)} layouts, linear parasitics (H2)")
            dsl = _sweep(
                "design-device-linear",
                {"layout": [r["network"] for r in single], "device": lin_devs},
                {"settings": json.dumps(layout_settings, sort_keys=True), "ideal": ideal},
                store("devices_linear.zarr"), workers, progress,
            )  # fmt: skip
            for d in lin_devs:
                rows = []
                for r in single:
                    row = dsl.sel(layout=r["network"], device=d)
                    if int(row.status) != 1 or not math.isfinite(float(row.objective)):
                        continue
                    vals = _unpack(
                        dsl, {"layout": r["network"], "device": d}, list(r["parameters"])
                    )
                    # an optimum on a bound that stands for a simpler layout (a spring
                    # across the device rigid, the inertance at its lower bound: the
                    # device shorted or absent) is no design with the device
                    why = _simpler(r["network"], vals, bounds_of[r["network"]], st)
                    if not why:
                        rows.append((float(row.objective), r["network"], vals))
                    device_linear.append({
                        "device": d, "layout": r["network"], "h2": float(row.objective),
                        "h2_improvement": 100.0 * (1.0 - float(row.objective) / base["objective"]),
                        "parameters": vals, "simpler": why,
                    })  # fmt: skip
                by_device[d] = sorted(rows, key=lambda x: x[0])
                best = min((q for q in device_linear if q["device"] == d),
                           key=lambda q: q["h2"], default=None)  # fmt: skip
                if best is not None and best["simpler"]:
                    notes.append(
                        f"{d}: its best linear optimum, in {best['layout']} "
                        f"({best['h2_improvement']:+.2f} % H2), stands for a simpler layout "
                        f"({best['simpler']}: the device does not act there); the device is "
                        "rechecked in its best layouts where it acts"
                        if rows else
                        f"{d}: in every layout its linear optimum stands for a simpler "
                        "layout (the device shorted or absent); not rechecked"
                    )  # fmt: skip
        for d in st.devices:
            for _, lay, vals in by_device[d][: st.recheck]:
                jobs.append({"layout": lay, "device": d, "values": vals})
    if jobs:
        say(f"design: {len(jobs)} (layout, device) pairs, inertance searched on "
            f"{st.tune_roads} roads with friction")  # fmt: skip
        texts = [json.dumps(j, sort_keys=True) for j in jobs]
        dsd = _sweep("design-device", {"job": texts}, {"settings": json.dumps(dev_settings, sort_keys=True)},
                     store("devices.zarr"), workers, progress)  # fmt: skip
        for j, tx in zip(jobs, texts, strict=True):
            row = dsd.sel(job=tx)
            lay, d = j["layout"], j["device"]
            if int(row.status) != 1:
                notes.append(f"{d} in {lay}: {str(row.reason.values)}")
                continue
            vals = _unpack(dsd, {"job": tx}, list(j["values"]))
            net, elp = scoring.device_candidate(lay, vals, d, car)
            candidates[f"{lay} [{d}]"] = {"kind": "device", "device": d, "layout": lay,
                                          "values": vals, "network": net, "params": elp}  # fmt: skip

    # 4. scores ---------------------------------------------------------------------------
    say(f"design: {len(candidates)} candidates on {st.roads} ISO 8608 class {st.road_class} roads")
    labels = list(candidates)
    texts = [candidate_text(candidates[lb]["network"], candidates[lb]["params"]) for lb in labels]
    seeds = list(range(st.seed, st.seed + st.roads))
    dss = _sweep(
        "design-score",
        {"candidate": texts, "seed": seeds},
        {"car": json.dumps(car, sort_keys=True), "road_class": st.road_class,
         "speed": st.speed, "horizon": st.horizon, "rtol": st.rtol},
        store("scores.zarr"), workers, progress,
    )  # fmt: skip
    per_road = {}
    for lb, tx in zip(labels, texts, strict=True):
        sub = dss.sel(candidate=tx)
        if int((sub.status != 1).sum()):
            notes.append(
                f"{lb}: failed on a road ({sorted({str(x) for x in sub.reason.values if str(x)})[:1]})"
            )
            continue
        per_road[lb] = {m: sub[m].values.astype(float) for m in SCORE_METRICS}
    ref_m = per_road["k | c"]
    unit = OBJECTIVE_METRIC[st.objective][1]
    table = []
    for lb in labels:
        if lb not in per_road:
            continue
        v = scoring.objective_of(per_road[lb], st.objective, ref_m)
        b = scoring.objective_of(ref_m, st.objective, ref_m)
        e = scoring.expected(v)
        g = scoring.paired_gain(v, b)
        c = candidates[lb]
        lim_ok = all(
            float(np.mean(per_road[lb][m])) <= st.limits[k] * 1.0001
            for k, m in (("deflection", "rms_deflection"), ("tyre_load", "rms_tyre_load"))
            if k in st.limits
        )
        table.append({
            "label": lb, "kind": c["kind"], "network": c["network"], "objective": st.objective,
            "unit": unit, "expected": e["mean"], "interval95": e["half_width"],
            "single_road95": e["single_road"], "roads": e["roads"],
            "gain_percent": g["mean"], "gain_interval95": g["half_width"],
            "rms_deflection": float(np.mean(per_road[lb]["rms_deflection"])),
            "rms_tyre_load": float(np.mean(per_road[lb]["rms_tyre_load"])),
            "rms_body_acc_wk": float(np.mean(per_road[lb]["rms_body_acc_wk"])),
            "limits_met": lim_ok,
            "parameters": c.get("values", c["params"]),
            "core": {"network": c["network"], "params": c["params"]},
            "h2": next((r["objective"] for r in ok if r["network"] == c["network"]), None),
            **({"device": c["device"], "layout": c["layout"]} if c["kind"] == "device" else {}),
        })  # fmt: skip
    table.sort(key=lambda r: (not r["limits_met"], r["expected"]))
    for i, r in enumerate(table, 1):
        r["rank"] = i

    # 5. device requirements --------------------------------------------------------------
    requirements = []
    best_dev = {}
    for r in table:
        if r["kind"] == "device" and r["device"] not in best_dev:
            best_dev[r["device"]] = r
    if best_dev:
        say(f"design: device requirements for {len(best_dev)} devices (the ITP crossing)")
        req_settings = {**dev_settings, "baseline": json.dumps(base_cand, sort_keys=True)}
        jobs = []
        for d, r in best_dev.items():
            for what in ("friction", "damping"):
                if d == "fluid" and what == "friction":
                    continue
                ideal_values = next(x["parameters"] for x in ok if x["network"] == r["layout"])
                jobs.append((r["layout"], d, what, json.dumps(ideal_values, sort_keys=True)))
        requirements = _requirements(
            jobs, req_settings, store("requirements.zarr"), workers, progress
        )
    from ..studies.sweep import unread_stores

    result = {
        "settings": st.to_dict(),
        "objective": {
            "name": st.objective,
            "unit": unit,
            "h2_objective": h2obj,
            "time_domain": f"expected value over {st.roads} ISO 8608 class {st.road_class} roads "
            f"at {st.speed:g} m/s, {st.horizon:g} s each (seeds {st.seed}-{st.seed + st.roads - 1}), "
            "95 % interval of the expected value (Student t)",
        },  # fmt: skip
        "road_velocity_scale": scale,
        "layouts": [{k: v for k, v in r.items()} for r in layouts],
        "ranking": table,
        "requirements": requirements,
        "device_linear": device_linear,
        "synthesis": synth,
        "notes": notes,
        "points_computed": dict(COMPUTED),
        # the stores in OUT/stores this run did not read (earlier settings or code)
        "unread_stores": [] if stores is None else unread_stores(stores, READ),
        "stage_seconds": dict(SECONDS),
        "stage_cpu_seconds": dict(CPU_SECONDS),
        "seconds": time.perf_counter() - t0,
    }
    return result


def _warm_up(vehicle_car=None) -> None:
    """Load the compiled kernels the stages use into this process before the worker
    processes are forked from it, so each worker inherits them instead of loading them
    again for every stage."""
    from .. import excitation as ex
    from ..network_design import optimize_network
    from ..systems import quarter_car

    if vehicle_car is not None:
        from .vehicle import axle_stiffness, simulate_vehicle_candidate

        ks = axle_stiffness(vehicle_car)
        cand = {"network": "k | c", "params": {a: {"k": ks[a], "c": 2e3} for a in ks}}
        simulate_vehicle_candidate(cand, vehicle_car, "C", 20.0, 0.5, 0)
        net, elp = scoring.device_network("k | (c - b)", {"k": 5e4, "c": 2e3, "b": 200.0}, "screw")
        cand = {"network": net, "params": {a: {**elp, "k": ks[a]} for a in ks}}
        simulate_vehicle_candidate(cand, vehicle_car, "C", 20.0, 0.5, 0)

    optimize_network("k | (c - b)", "body_acc", fixed={"k": 5e4}, starts=1, samples=16,
                     evolve=False, compare=False)  # fmt: skip
    road = ex.iso8608("C", 20.0, seed=0)
    quarter_car("k | c", {"k": 5e4, "c": 2e3}).simulate(road, horizon=0.5)
    net, elp = scoring.device_network("k | (c - b)", {"k": 5e4, "c": 2e3, "b": 200.0}, "screw")
    quarter_car(net, elp).simulate(road, horizon=0.5)


_H2_UNIT = {
    "body_acc": "m/s^2 per m/s",
    "body_acc_wk": "m/s^2 per m/s",
    "tyre_deflection": "m per m/s",
    "suspension_deflection": "m per m/s",
    "weighted": "1",
}


def _simpler(text: str, params: dict, bounds: dict, st: DesignSettings) -> str:
    """The simpler layout an optimum on a bound stands for ('' if none): an inerter at
    its lower bound is absent, a spring (other than the main one) at its upper bound
    (1e7 N/m) is a rigid link."""
    from ..network_design import design_parameters

    dp = design_parameters(text)
    if st.is_vehicle:
        # the simpler layout only where both axles stand for it
        from .vehicle import split_axles

        axles = split_axles(params)
        per = [set(_simpler(text, v, bounds, DesignSettings()).split(", ")) - {""}
               for v in axles.values()]  # fmt: skip
        return ", ".join(sorted(set.intersection(*per)))
    said = []
    for n, v in params.items():
        if n == "k" or n not in dp:
            continue
        lo, hi = bounds.get(n, dp[n].design or (0, math.inf))
        if dp[n].unit == "kg" and v <= lo * 1.01:
            said.append(f"{n} absent")
        if dp[n].unit == "N/m" and v >= hi * 0.99:
            said.append(f"{n} rigid")
        if dp[n].unit == "N s/m" and v <= lo * 1.01:
            said.append(f"{n} absent")
    return ", ".join(said)


def _requirements(jobs, settings, store, workers, progress) -> list:
    """One requirement sweep: dims (job) where each job text names layout, device,
    parameter and the values."""
    if not jobs:
        return []
    texts = [json.dumps({"layout": j[0], "device": j[1], "parameter": j[2],
                         "values": json.loads(j[3])}, sort_keys=True) for j in jobs]  # fmt: skip
    ds = _sweep("design-requirement", {"job": texts}, {"settings": json.dumps(settings, sort_keys=True)},
                store, workers, progress)  # fmt: skip
    out = []
    unit = {"friction": "N", "damping": "N s/m"}
    for j, tx in zip(jobs, texts, strict=True):
        row = ds.sel(job=tx)
        if int(row.status) != 1:
            out.append(
                {
                    "device": j[1],
                    "layout": j[0],
                    "parameter": j[2],
                    "reason": str(row.reason.values),
                }
            )
            continue
        br = int(row.bracket)
        thr = float(row.threshold)
        ident = scoring.device_parts(j[1]) if j[1] != "fluid" else None
        identified = (
            (ident["friction"] if j[2] == "friction" else ident["damping"]) if ident else None
        )
        other = {"friction": "parasitic damping", "damping": "friction"}[j[2]]
        cond = (
            "with the device's losses from its geometry"
            if j[1] == "fluid"
            else f"no {other}, the device's stiffness as identified"
        )
        if br == 0:
            text = (f"{j[2]} below {thr:.3g} {unit[j[2]]} ({cond}) for the ideal design's "
                    "gain over k | c to survive")  # fmt: skip
        elif br < 0:
            text = (f"no {j[2]} keeps a gain: even {thr:.3g} {unit[j[2]]} loses against k | c "
                    f"({cond}: what remains of the device erases the gain)")  # fmt: skip
        else:
            text = f"any {j[2]} up to {thr:.3g} {unit[j[2]]} keeps a gain over k | c ({cond})"
        out.append({
            "device": j[1], "layout": j[0], "parameter": j[2], "unit": unit[j[2]],
            "threshold": thr, "bracket": br, "identified": identified,
            "gain_at_low_percent": float(row.gain_low),
            # None: a road at the top of the range needs more than max_steps steps
            # (long sticking), counted as no gain
            "gain_at_high_percent": (float(row.gain_high) if math.isfinite(float(row.gain_high))
                                     else None),
            "text": text,
        })  # fmt: skip
    return out


def _synthesis(st, h2obj, car, notes):
    """PR optimum of degree ``st.synthesize`` and its smallest realisation."""
    from ..synthesis import synthesize
    from ..synthesis.realise import realise_all

    obj = {"tyre_deflection": "tyre_load", "body_acc": "body_acc"}.get(h2obj, "body_acc")
    if st.objective == "body_acc_wk":
        obj = "body_acc_wk"
    if obj != h2obj and not (obj == "tyre_load" and h2obj == "tyre_deflection"):
        notes.append(
            f"synthesis: the positive-real optimum minimises {obj} (the layouts' H2 search "
            f"used {h2obj}), so part of its lead over the layouts is the objective"
        )
    try:
        res = synthesize(st.synthesize, obj, static_stiffness=st.stiffness, seed=st.seed, **car)
    except Exception as e:  # noqa: BLE001 - reported, the rest of the study goes on
        notes.append(f"synthesis: {e}")
        return None
    reals = realise_all(res.numerator, res.denominator)
    best = None
    for r in reals.values():
        if isinstance(r, str) or r.network is None:
            continue
        if best is None or r.elements < best.elements:
            best = r
    out = {"degree": st.synthesize, "objective_name": obj, "objective": res.objective,
           "unit": res.unit, "numerator": res.numerator, "denominator": res.denominator,
           "realisations": {m: (r if isinstance(r, str) else r.network) for m, r in reals.items()}}  # fmt: skip
    if best is None:
        notes.append("synthesis: no realisation as a network text (Brune needs a lever)")
        return out
    params = dict(best.parameters)
    out.update({"network": best.network, "parameters": params, "method": best.method,
                "elements": best.elements, "max_relative_error": best.max_relative_error})  # fmt: skip
    why = _synthesis_outside(best.network, params, st)
    if why:
        # the positive-real search has neither an inertance bound nor limits: its
        # realisation is checked against them afterwards and left out if it breaks one
        notes.append(f"synthesis: degree-{st.synthesize} realisation left out: {why}")
        out["refused"] = why
        out.pop("network")
    return out


def _synthesis_outside(network: str, params: dict, st: DesignSettings) -> str:
    """'' if the realisation keeps --max-inertance and every --limit (RMS on the
    chosen road from its H2 norms), else the first one it breaks, in one line."""
    from ..network_design import evaluate

    for n, v in params.items():
        if parse_kind(network, n) == "b" and v > st.max_inertance * (1 + 1e-9):
            return (f"its inerter {n} = {v:.4g} kg exceeds --max-inertance "
                    f"{st.max_inertance:g} kg (the positive-real search has no inertance bound)")  # fmt: skip
    if not st.limits:
        return ""
    scale = road_velocity_scale(st.road_class, st.speed)
    norms = evaluate(network, params, ("suspension_deflection", "tyre_load"), **st.car)
    rms = {"deflection": (norms["suspension_deflection"] * scale, "m"),
           "tyre_load": (norms["tyre_load"] * scale, "N")}  # fmt: skip
    for k, lim in st.limits.items():
        v, unit = rms[k]
        if not v <= lim * (1 + 1e-6):
            return (f"its RMS {k} {v:.4g} {unit} (linear, white road velocity) exceeds "
                    f"--limit {k}={lim:g} {unit} (the positive-real search has no limits)")  # fmt: skip
    return ""


def parse_kind(text: str, name: str) -> str:
    from ..networks import parse_network

    net = parse_network(text)
    return dict(zip(net.names, net.kinds, strict=True)).get(name, "")
