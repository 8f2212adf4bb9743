"""Steady-state response of the chapter-7 adaptive-flywheel suspension, fast.

Run: python examples/frequency_response_ch7.py
"""

import time

from inerterlab.frequency import chapter7_system, frequency_response, nrmse

for amplitude in (0.01, 0.03, 0.05):
    system = chapter7_system(amplitude)  # metal flywheel, thesis law, B in metres
    t0 = time.perf_counter()
    fr = frequency_response(
        system,
        "sihb",
        fmin=0.1,
        fmax=3.0,
        df=0.005,
        harmonics=15,
        direction="both",
        stability=False,
    )
    dt = time.perf_counter() - t0
    peak = fr.resonance("down")
    print(
        f"B = {100 * amplitude:.0f} cm: resonance {peak['freq_hz']:.3f} Hz, "
        f"peak {1e3 * peak['amplitude_m']:.2f} mm, {len(fr.freq_hz)} points in {dt:.2f} s"
    )

# check a few points against time integration to steady state
system = chapter7_system(0.03)
fr = frequency_response(system, "sihb", freq_hz=[0.5, 1.0, 1.2, 2.0], harmonics=15)
ref = frequency_response(system, "brute", freq_hz=[0.5, 1.0, 1.2, 2.0])
print(f"NRMSE of SIHB against brute force (7.16): {100 * nrmse(fr, ref):.4f} %")
