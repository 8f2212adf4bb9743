"""Shared test set-up."""

import os

from inerterlab.studies.points import LOG_FILE_ENV

# the synthetic point's evaluation log (used to count evaluations) is a testing aid that
# user configurations cannot switch on; the tests, and the processes they start, may
os.environ.setdefault(LOG_FILE_ENV, "1")
# the per-structure right-hand side (systems/_compiled.py) gives the generic code's
# results to the last bit (tests/test_core_compiled.py, tests/test_vehicle_factored.py
# build and compare it explicitly); elsewhere the suite does not let a long test compile
# it for its structure on the way (up to 90 s of CPU each), nor the processes it starts
os.environ.setdefault("INERTERLAB_SPECIALISE", "never")


def pytest_addoption(parser):
    parser.addoption(
        "--update-guides",
        action="store_true",
        default=False,
        help="tests/test_guides.py: rewrite the expected output of every checked console "
        "block in README.md and docs/guide/*.md that no longer agrees with the command",
    )
