"""The exceptions: classes, attributes, and the library's errors mapped to them."""

import numpy as np
import pytest

import piezobench as pb


def test_exception_classes():
    assert issubclass(pb.InputError, pb.Error) and issubclass(pb.InputError, ValueError)
    assert issubclass(pb.NumericalError, pb.Error) and issubclass(pb.NumericalError, ArithmeticError)


def test_input_error_attributes_from_the_library():
    with pytest.raises(pb.InputError) as e:
        pb.lti.TransferFunction([1.0], [0.0, 1.0])
    assert e.value.field.startswith("den")
    assert e.value.expected and e.value.found
    assert f"expected {e.value.expected}, found {e.value.found}" in str(e.value)


def test_numerical_error_attributes():
    # Vector fitting of pure noise with too few iterations to settle: the library's NumericalError.
    rng = np.random.default_rng(1)
    w = np.linspace(1.0, 100.0, 200)
    h = rng.standard_normal(200) + 1j * rng.standard_normal(200)
    with pytest.raises(pb.NumericalError) as e:
        pb.ident.vector_fit(w, h, order=20, max_iterations=1, significance_floor=0.0, residual_tolerance=0.0)
    assert e.value.retry_may_help is True
    assert "vector fitting" in e.value.method.lower()


@pytest.mark.parametrize("call", [
    lambda: pb.lti.freqresp(pb.lti.TransferFunction([1.0], [1.0, 1.0]), [1.0, np.nan]),
    lambda: pb.lti.StateSpace(np.eye(2), np.ones((3, 1)), np.ones((1, 2))),
    lambda: pb.control.iff_plant(wz=-1.0),
    lambda: pb.control.iff_plant(wzz=1.0),
    lambda: pb.apa.two_dof_bench(k1="stiff"),
    lambda: pb.ident.lscf(np.linspace(1, 10, 20), np.ones((20, 1)), max_order=-3),
    lambda: pb.io.read_timeseries("/nonexistent/record.mat"),
    lambda: pb.dsp.frf(np.ones(10), None, 1.0),
])
def test_bad_arguments_never_crash(call):
    with pytest.raises(pb.InputError) as e:
        call()
    assert str(e.value)
