"""Design studies: parameter sweeps that scale out, and the optimal changing ratio.

Sweeps evaluate a point function (the quarter car, or a cheap synthetic stand-in) over a
grid described in TOML or Python, on a serial, local-process or Dask backend, writing a
resumable Zarr store. The changing-ratio study combines the performance function
(4.30)-(4.33) with a cost function (4.34) and solves the Chebyshev goal programme
(4.38)-(4.39) over a continuous changing ratio.
"""

from .backends import Backend as Backend
from .backends import DaskBackend as DaskBackend
from .backends import ProcessBackend as ProcessBackend
from .backends import SerialBackend as SerialBackend
from .backends import make_backend as make_backend
from .points import POINT_FUNCTIONS as POINT_FUNCTIONS
from .points import ParameterSpec as ParameterSpec
from .points import PointFunction as PointFunction
from .points import point_function as point_function
from .points import register_point_function as register_point_function
from .spec import PerformanceWeights as PerformanceWeights
from .spec import SweepSpec as SweepSpec
from .spec import load_sweep_config as load_sweep_config
from .spec import sweep_spec as sweep_spec
from .sweep import SweepInterrupted as SweepInterrupted
from .sweep import load_sweep as load_sweep
from .sweep import save_netcdf as save_netcdf
from .sweep import sweep as sweep
