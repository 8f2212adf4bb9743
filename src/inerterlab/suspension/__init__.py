"""Quarter-car models built from a device (thesis ch. 4 and 6, docs/model.md §5)."""

from .linear import LinearQuarterCar as LinearQuarterCar
from .linear import linear_quarter_car as linear_quarter_car
from .model import LAWS as LAWS
from .model import SUSPENSIONS as SUSPENSIONS
from .model import QuarterCar as QuarterCar
from .model import describe_quarter_car as describe_quarter_car
from .network_linear import NetworkQuarterCar as NetworkQuarterCar
from .network_linear import network_h2 as network_h2
from .network_linear import network_quarter_car as network_quarter_car
from .parameters import HydraulicDeviceParameters as HydraulicDeviceParameters
from .parameters import QuarterCarParameters as QuarterCarParameters
