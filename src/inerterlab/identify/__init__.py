"""Identification of device parameters from rig data (thesis ch. 5, docs/model.md §4)."""

from .data import RigDataSet as RigDataSet
from .data import RigTest as RigTest
from .data import load_rig_data as load_rig_data
from .data import read_rig_test as read_rig_test
from .data import write_rig_data as write_rig_data
from .design import CampaignDesign as CampaignDesign
from .design import design_campaign as design_campaign
from .filters import displacement_from_velocity as displacement_from_velocity
from .filters import velocity_from_displacement as velocity_from_displacement
from .fit import FitResult as FitResult
from .fit import ParameterEstimate as ParameterEstimate
from .fit import identify as identify
from .network import NetworkFitResult as NetworkFitResult
from .network import identify_network as identify_network
from .propagate import linearised_car as linearised_car
from .propagate import propagate as propagate
from .propagate import propagate_function as propagate_function
from .propagate import ride_metrics as ride_metrics
from .sensitivity import ride_sensitivity as ride_sensitivity
from .sensitivity import sobol_indices as sobol_indices
from .simulator import MATRICES as MATRICES
from .simulator import TestSpec as TestSpec
from .simulator import simulate_rig as simulate_rig
from .simulator import test_matrix as test_matrix
