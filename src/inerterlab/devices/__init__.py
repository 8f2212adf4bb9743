"""Real two-terminal devices (thesis ch. 3.2.4, 3.3.4, 5): models, motions, forces.

A device runs as its network of elements on the model core's rig (:func:`device_rig`).

>>> from inerterlab.devices import device_preset, device_force, Motion
>>> res = device_force(device_preset("hydraulic"), Motion.square(frequency=0.5,
...                    velocity_amplitude=0.01), duration=2.0, sample_rate=200)
>>> bool(270 < res.force[50] < 275)   # b_ah q + F_fh on the plateau (5.1): 81 + 190
True
"""

from .force import DeviceForceResult as DeviceForceResult
from .force import device_force as device_force
from .force import device_rig as device_rig
from .models import DEVICES as DEVICES
from .models import PARAMETER_UNITS as PARAMETER_UNITS
from .models import HydraulicDevice as HydraulicDevice
from .models import RectifierDevice as RectifierDevice
from .models import ScrewDevice as ScrewDevice
from .models import device_preset as device_preset
from .motion import SIGNALS as SIGNALS
from .motion import Motion as Motion
from .motion import motion_from_samples as motion_from_samples

__all__ = [
    "DEVICES",
    "PARAMETER_UNITS",
    "SIGNALS",
    "DeviceForceResult",
    "HydraulicDevice",
    "Motion",
    "RectifierDevice",
    "ScrewDevice",
    "device_force",
    "device_rig",
    "device_preset",
    "motion_from_samples",
]
