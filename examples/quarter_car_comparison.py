"""Compare the conventional, constant-flywheel and adaptive-flywheel quarter cars.

Run: python examples/quarter_car_comparison.py
"""

from inerterlab import quarter_car
from inerterlab.excitation import bump, drop, iso8608, sine
from inerterlab.metrics import h2_norms
from inerterlab.simulate import simulate_metrics

inputs = {
    "drop": drop(),
    "bump": bump(0.05, duration=0.01, shape="1-cos"),
    "sine": sine(0.05, 5.0),
    "ISO 8608 C, 20 m/s": iso8608("C", 20.0, seed=1, length=200.0),
}
print(
    f"{'input':20s} {'suspension':12s} {'rms acc':>9s} {'Wk acc':>9s} {'grip':>8s} {'defl mm':>8s}"
)
for name, road in inputs.items():
    for susp in ("traditional", "cfw", "afw"):
        m = simulate_metrics(quarter_car(susp, sprung_mass=370), road, 10.0)
        print(
            f"{name:20s} {susp:12s} {m['rms_body_acc']:9.3f} {m['rms_body_acc_wk']:9.3f} "
            f"{m['rms_tyre_grip']:8.4f} {1e3 * m['rms_deflection']:8.2f}"
        )

# Linear suspensions also have closed-form H2 indices (no time stepping)
h2 = h2_norms(quarter_car("traditional", sprung_mass=370))
print("H2 norms of the traditional car from unit white road velocity, and the RMS they")
print("predict on an ISO 8608 class C road at 20 m/s:")
rms = h2.ride_indices("C", 20.0)
for key in ("body_acc", "tyre_deflection", "suspension_deflection"):
    print(f"  {key:22s} {h2[key]:10.4g}   {rms[key]:10.4g}")
