"""``inerterlab design``: the layout, the amount and the real device for one car.

- :mod:`.pipeline`: the study (layouts, synthesis, devices in the loop, scores on
  roads, device requirements), each stage a resumable sweep;
- :mod:`.scoring`: time-domain scoring on ISO 8608 roads and the sweeps' point
  functions;
- :mod:`.report`: the HTML design report with its figures;
- :mod:`.vehicle`: half- and full-car design (one layout at every corner, values per
  axle).
"""

from .pipeline import DESIGN_OBJECTIVES, DesignSettings, estimate, road_velocity_scale, run_design

__all__ = ["DESIGN_OBJECTIVES", "DesignSettings", "estimate", "road_velocity_scale", "run_design"]
