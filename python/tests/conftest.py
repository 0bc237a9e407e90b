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


@pytest.fixture
def declared():
    """check(obj, module, name): obj is the class `module.declarations()` gives for the declared struct
    `name` (issue 32: made from the C++ declaration, not a dict): its fields() are the declaration, every
    declared field is an attribute and obj[name], and to_dict() holds them all. Returns obj."""
    def check(obj, module, name):
        cls, fields = module.declarations()[name]
        assert type(obj) is cls and cls.__name__ == name
        assert [f[0] for f in cls.fields()] == fields == list(obj.keys())
        assert all(len(f) == 4 and f[3] for f in cls.fields()), "every field has a meaning"
        for f in fields:
            value, item = getattr(obj, f), obj[f]
            if isinstance(value, np.ndarray):
                np.testing.assert_array_equal(item, value)
            elif isinstance(value, (int, float, complex, str, list, type(None))):
                assert item == value
            else:  # a nested class: a new view (or copy) each time
                assert type(item) is type(value)
        assert set(obj.to_dict()) == set(fields)
        assert repr(obj).startswith(name + "(")
        return obj
    return check
