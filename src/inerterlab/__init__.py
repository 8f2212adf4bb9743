"""inerterlab: adaptive-flywheel inerters and the vehicle suspensions that use them.

The model is described in docs/model.md; SI units throughout.

Quick start
-----------
A flywheel whose inertia grows with speed (thesis Table 3.3):

>>> import inerterlab
>>> fw = inerterlab.flywheel("nylon")
>>> round(fw.changing_ratio, 3), round(fw.saturation_speed, 2)
(0.285, 45.45)

A quarter car with that flywheel in an ideal inerter, over a 5 cm, 10 ms road bump:

>>> car = inerterlab.quarter_car("afw", sprung_mass=370)
>>> res = inerterlab.simulate(car, inerterlab.bump(0.05), 2.0)
>>> m = res.metrics()
>>> m["rms_deflection"] < 0.01 and m["rms_body_acc_wk"] > 0
True

Across the bump's steps the inerter passes part of the tyre impulse to the body, whose
velocity jumps: the plain RMS acceleration is then not finite and says why.

>>> m["rms_body_acc"] is None, [round(dv, 3) for _, dv in res.body_velocity_jumps]
(True, [0.152, -0.152])
>>> res.to_xarray()["body_acc"].attrs["units"]
'm/s^2'

The force a real device needs on a test rig, and the steady-state frequency response of
the chapter-7 system by harmonic balance:

>>> dev = inerterlab.device_preset("hydraulic")
>>> f = inerterlab.device_force(dev, inerterlab.Motion.sine(frequency=1.0, amplitude=0.005),
...                             duration=1.0, sample_rate=100)
>>> f.force.shape
(101,)
>>> fr = inerterlab.frequency_response(inerterlab.chapter7_system(0.03), "shb",
...                                    freq_hz=[0.8, 1.2, 2.0])
>>> bool(fr.converged.all())
True

``inerterlab.simulate`` is the module :mod:`inerterlab.simulate`; calling it calls
:func:`inerterlab.simulate.simulate`. Everything is also on the command line: ``inerterlab --help``. The names above come from
the subpackages (:mod:`inerterlab.suspension`, :mod:`inerterlab.excitation`,
:mod:`inerterlab.devices`, :mod:`inerterlab.identify`, :mod:`inerterlab.frequency`,
:mod:`inerterlab.studies`), which hold the rest; they are loaded on first use.
"""

from __future__ import annotations

import importlib

# first: the compiled kernels' disk cache is keyed on every source file of the package
from . import _numba_cache as _numba_cache  # noqa: I001
from .errors import ConvergenceError as ConvergenceError
from .errors import DataFileError as DataFileError
from .errors import InerterlabError as InerterlabError
from .errors import ParameterError as ParameterError
from .flywheels import AdaptiveFlywheel as AdaptiveFlywheel
from .flywheels import constant_flywheel as constant_flywheel
from .flywheels import flywheel as flywheel
from .flywheels import size_spring as size_spring
from .transmissions import Transmission as Transmission
from .transmissions import equivalent_mass as equivalent_mass
from .transmissions import inertance as inertance
from .transmissions import transmission as transmission


def _version() -> str:
    try:
        from importlib.metadata import PackageNotFoundError, version
    except ImportError:  # pragma: no cover
        return "0.1.0"
    try:
        return version("inerterlab")
    except PackageNotFoundError:  # running from a source tree that is not installed
        return "0.1.0"


__version__ = _version()

#: public names loaded on first use: name -> (module, attribute)
_LAZY = {
    # quarter car
    "quarter_car": (".systems", "quarter_car"),
    "QuarterCar": (".suspension", "QuarterCar"),
    "simulate": (".simulate", None),  # the module, callable as simulate.simulate
    "simulate_metrics": (".simulate", "simulate_metrics"),
    "SimulationOptions": (".simulate", "SimulationOptions"),
    "SimulationResult": (".simulate", "SimulationResult"),
    "h2_norms": (".metrics", "h2_norms"),
    # road inputs
    "drop": (".excitation", "drop"),
    "bump": (".excitation", "bump"),
    "sine": (".excitation", "sine"),
    "iso8608": (".excitation", "iso8608"),
    "road_series": (".excitation", "road_series"),
    "read_road_csv": (".excitation", "read_road_csv"),
    # devices and identification
    "device_preset": (".devices", "device_preset"),
    "device_force": (".devices", "device_force"),
    "Motion": (".devices", "Motion"),
    "DeviceForceResult": (".devices", "DeviceForceResult"),
    "simulate_rig": (".identify", "simulate_rig"),
    "load_rig_data": (".identify", "load_rig_data"),
    "write_rig_data": (".identify", "write_rig_data"),
    "FitResult": (".identify", "FitResult"),
    # frequency response
    "chapter7_system": (".frequency", "chapter7_system"),
    "frequency_response": (".frequency", "frequency_response"),
    "FrequencyResponse": (".frequency", "FrequencyResponse"),
    "nrmse": (".frequency", "nrmse"),
    # design studies
    "sweep": (".studies", "sweep"),
    "sweep_spec": (".studies", "sweep_spec"),
    "load_sweep": (".studies", "load_sweep"),
    "optimize_ratio": (".studies.ratio", "optimize_ratio"),
    "ratio_model": (".studies.ratio", "ratio_model"),
    "baseline_metrics": (".studies.ratio", "baseline_metrics"),
}

__all__ = [
    "ConvergenceError",
    "DataFileError",
    "InerterlabError",
    "ParameterError",
    "AdaptiveFlywheel",
    "constant_flywheel",
    "flywheel",
    "size_spring",
    "Transmission",
    "equivalent_mass",
    "inertance",
    "transmission",
    "__version__",
    *_LAZY,
]


def __getattr__(name: str):
    try:
        module, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'inerterlab' has no attribute {name!r}") from None
    mod = importlib.import_module(module, __name__)
    value = mod if attr is None else getattr(mod, attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
