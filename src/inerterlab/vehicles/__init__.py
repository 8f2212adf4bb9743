"""Linear half-car and full-car models, road tracks and their stochastic response."""

from .model import LinearVehicle as LinearVehicle
from .model import build as build
from .parameters import Corner as Corner
from .parameters import FullCar as FullCar
from .parameters import HalfCar as HalfCar
from .parameters import Seat as Seat
from .parameters import Strut as Strut
from .parameters import Tyre as Tyre
