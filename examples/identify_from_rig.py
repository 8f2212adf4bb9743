"""Simulate a rig campaign for the inverse-screw device and identify its parameters.

The thesis's measurements are not public: the rig simulator produces the Appendix A
test matrix from the device model with sensor noise and reversal spikes.

Run: python examples/identify_from_rig.py
"""

import tempfile

from inerterlab.cli import main

with tempfile.TemporaryDirectory() as tmp:
    main(
        [
            "rig-simulate",
            "--device",
            "screw",
            "--flywheel",
            "nylon",
            "--matrix",
            "appendix-a2",
            "--noise",
            "5",
            "--spikes",
            "on",
            "--seed",
            "1",
            "--max-duration",
            "2",
            "--sample-rate",
            "200",
            "--out",
            f"{tmp}/rig",
        ]
    )
    main(["identify", "--device", "screw", "--flywheel", "nylon", "--data", f"{tmp}/rig"])
