"""inerterlab: adaptive-flywheel inerters and the vehicle suspensions that use them."""

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

__version__ = "0.1.0"
