"""Linear half-car and full-car models, road tracks and their stochastic response.

See docs/guide/vehicles.md. Main entry points: :func:`load_vehicle` (TOML file),
:func:`linear_vehicle` (parameters -> :class:`LinearVehicle`, the core car's state space
about its static equilibrium), :func:`road_spectrum`,
:func:`spectral_response`, :func:`simulate`, :func:`generated_road` (a generated road,
exact at the wheels), :func:`simulate_vehicle` (time simulation on the model core), :func:`iri`, :func:`fit_iso8608`.
"""

from .config import example_vehicle_path as example_vehicle_path
from .config import load_vehicle as load_vehicle
from .config import loads_vehicle as loads_vehicle
from .linear import LinearVehicle as LinearVehicle
from .linear import linear_vehicle as linear_vehicle
from .parameters import Corner as Corner
from .parameters import FullCar as FullCar
from .parameters import HalfCar as HalfCar
from .parameters import NetworkStrut as NetworkStrut
from .parameters import Seat as Seat
from .parameters import Strut as Strut
from .parameters import Tyre as Tyre
from .roads import RoadSpectrum as RoadSpectrum
from .roads import fit_iso8608 as fit_iso8608
from .roads import generate_tracks as generate_tracks
from .roads import iri as iri
from .roads import isotropic_coherence as isotropic_coherence
from .roads import road_spectrum as road_spectrum
from .simulation import VehicleRun as VehicleRun
from .simulation import simulate_vehicle as simulate_vehicle
from .spectral import SpectralResult as SpectralResult
from .spectral import generated_road as generated_road
from .spectral import road_inputs as road_inputs
from .spectral import simulate as simulate
from .spectral import spectral_response as spectral_response
from .spectral import white_velocity_h2 as white_velocity_h2
