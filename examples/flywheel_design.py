"""Size an adaptive flywheel and compare the three force laws on one motion.

Run: python examples/flywheel_design.py
"""

import numpy as np

from inerterlab import flywheel, size_spring, transmission
from inerterlab.report.ch3 import compare_force_laws

# 1. The nylon flywheel of Table 3.3 on the hydraulic device of Table 3.2
fw = flywheel("nylon")
r = transmission("hydraulic").ratio
print(
    f"inertia {fw.inertia_min:.4e} .. {fw.inertia_max:.4e} kg m^2, ratio {100 * fw.changing_ratio:.2f} %"
)
print(f"equivalent mass {r**2 * fw.inertia_min:.1f} .. {r**2 * fw.inertia_max:.1f} kg")
print(
    f"sliders reach the stop at {fw.saturation_speed:.2f} rad/s = {fw.saturation_speed / r * 1e3:.1f} mm/s"
)

# 2. A spring that saturates at a terminal speed of 0.2 m/s instead (3.39)-(3.40)
k = size_spring(
    slider_mass=fw.slider_mass,
    slider_min=fw.slider_min,
    slider_max=fw.slider_max,
    design_speed=r * 0.2,
)
print(
    f"spring for saturation at 0.2 m/s: {k:.4g} N/m (the prototype has {fw.spring_stiffness:g} N/m)"
)

# 3. Variants with a larger changing ratio keep I_min and the slider law
for x in (0.2, 0.4, 0.55):
    v = fw.with_changing_ratio(x)
    print(f"x = {x:.2f}: I_max = {v.inertia_max:.4e} kg m^2")

# 4. The three force laws on one motion: only the energy-consistent ones balance
res = compare_force_laws(periods=1.25)
for law in ("thesis", "momentum", "slider-dynamics"):
    imbalance = res["work"][law] - res["stored"][law] - res["dissipated"][law]
    peak = np.max(np.abs(res["force"][law]))
    print(f"{law:16s} peak force {peak:7.2f} N, energy imbalance {imbalance:+.2e} J")
