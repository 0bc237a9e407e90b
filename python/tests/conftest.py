"""pytest set-up: the module is taken from PYTHONPATH (ctest sets build/python); when it is not
importable from there, from build/python beside this source tree."""

import json
import os
import sys

import numpy as np
import pytest

try:
    import piezobench  # noqa: F401
except ImportError:
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "build", "python"))


FIXTURES = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "fixtures")


@pytest.fixture
def welch_frf():
    """tests/fixtures/ident/two_dof_welch_frf.csv (scipy's Welch H1 of a simulated 2-DoF actuator,
    scripts/fixtures/make_two_dof_frf_fixtures.py) as a dsp.Frf, read with numpy, and its truth."""
    import piezobench as pb
    base = os.path.join(FIXTURES, "ident")
    data = np.loadtxt(os.path.join(base, "two_dof_welch_frf.csv"), delimiter=",", comments="#", skiprows=2)
    with open(os.path.join(base, "two_dof_welch_truth.json")) as fh:
        truth = json.load(fh)
    H = np.vstack([data[:, 1] + 1j * data[:, 2], data[:, 4] + 1j * data[:, 5]])
    coh = np.vstack([data[:, 3], data[:, 6]])
    return pb.dsp.Frf(data[:, 0], H, outputs=["de", "Vs"], coherence=coh), truth
