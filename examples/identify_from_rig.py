"""Simulate a rig campaign for the inverse-screw device and identify its parameters.

The thesis's measurements are not public: the rig simulator produces the Appendix A
test matrix from the device model with sensor noise and reversal spikes. The data set
is written to disk and read back, as measured data would be.

Run: python examples/identify_from_rig.py
"""

import tempfile

import inerterlab
from inerterlab.identify import identify

true = inerterlab.device_preset("screw", flywheel_preset="nylon")  # (5.11): k, c, f
campaign = inerterlab.simulate_rig(
    true,
    matrix="appendix-a2",
    noise=5.0,
    spikes=True,
    seed=1,
    max_duration=2.0,
    sample_rate=200.0,
)

with tempfile.TemporaryDirectory() as tmp:
    inerterlab.write_rig_data(campaign, f"{tmp}/rig")
    data = inerterlab.load_rig_data(f"{tmp}/rig")

print(
    f"{len(data.tests)} tests: {len(data.select('identification'))} identification, "
    f"{len(data.select('validation'))} validation"
)
fit = identify(data, true, method="joint", loss="cauchy")
print(fit)
for name, p in fit.parameters.items():
    print(f"{name:>10}: {p}   true {getattr(true, name):.7g}")
print("validation:", fit.validation())
