"""piezobench.control: the report's IFF plant and controller, the root locus, the discrete IFF
controller against scipy's bilinear transform."""

import numpy as np
import pytest
import scipy.signal as ss

import piezobench as pb
from piezobench import control, lti


def test_iff_plant_and_controller_are_eq_2_3_and_2_4():
    g = control.iff_plant()
    w = 2 * np.pi * np.array([1.0, 42.7, 95.2, 300.0])
    s = 1j * w
    wz, xz, wp, xp, whpf = 2 * np.pi * 42.7, 0.004, 2 * np.pi * 95.2, 0.02, 2 * np.pi * 0.4
    ref = 0.64 * (1 + 2 * xz * s / wz + s**2 / wz**2) / (1 + 2 * xp * s / wp + s**2 / wp**2) * s / (whpf + s)
    np.testing.assert_allclose(lti.freqresp(g, w), ref, rtol=1e-12)
    k = control.iff_controller()
    wh, wl, wr = 2 * np.pi * 2.0, 2 * np.pi * 20.0, 2 * np.pi * 2000.0
    kref = -10.0 * s / (s + wh) / (s + wl) / (s + wr)
    np.testing.assert_allclose(lti.freqresp(k, w), kref, rtol=1e-12)
    assert isinstance(k, lti.Zpk) and k.gain == -10.0


def test_iff_root_locus_optimum_is_the_most_damped_point():
    g, k = control.iff_plant(), control.iff_controller()
    r = control.iff_root_locus(g, k)
    assert r.optimum.gain > 0
    # Check against closed-loop poles computed independently: 1 - g K0 G = 0 on a grid of gains.
    ol = control.iff_open_loop(g, k)
    best = 0.0
    for gain in np.linspace(0.0, 2 * r.optimum.gain, 401):
        p = lti.closed_loop_poles(ol, gain)
        q = p[np.argmin(np.abs(p - r.optimum.pole))]
        best = max(best, -q.real / abs(q))
    assert r.optimum.damping == pytest.approx(best, rel=1e-3)
    assert r.optimum.damping > 0.1  # IFF damps the 95 Hz mode far beyond the plant's 2 %
    assert r.locus.poles.shape[0] == r.locus.gains.size


def test_iff_root_locus_is_the_declared_class(declared):
    g, k = control.iff_plant(), control.iff_controller()
    r = declared(control.iff_root_locus(g, k, [0.0, 1e3]), control, "IffRootLocus")
    assert r.keys() == ["locus", "resonance_pole", "optimum", "resonance_branch"]
    assert isinstance(r.locus, lti.RootLocus) and isinstance(r.optimum, lti.BranchOptimum)
    assert isinstance(r.resonance_pole, complex) and isinstance(r.resonance_branch, int)
    # At gain 0 the locus holds the open-loop poles: the resonance branch starts at the resonance pole.
    np.testing.assert_array_equal(r.locus.gains, [0.0, 1e3])
    ol = control.iff_open_loop(g, k)
    np.testing.assert_allclose(np.sort_complex(r.locus.poles[1]), np.sort_complex(lti.closed_loop_poles(ol, 1e3)), rtol=1e-9)
    assert r.locus.poles[0, r.resonance_branch] == pytest.approx(r.resonance_pole, rel=1e-9)
    assert abs(r.resonance_pole.imag) / (2 * np.pi) == pytest.approx(95.0, rel=0.1)
    assert r.to_dict()["optimum"]["gain"] == r.optimum.gain


def test_discrete_iff_equals_scipy_bilinear_of_the_controller():
    fs = 10e3
    c = control.DiscreteIff(gain=1.0, sample_rate=fs, prewarp=0.0)
    z = control.iff_controller()
    num, den = ss.zpk2tf(z.zeros, z.poles, z.gain)
    bz, az = ss.bilinear(num, den, fs)
    x = np.random.default_rng(2).standard_normal(5000)
    y = c.run(x)
    yref = ss.lfilter(bz, az, x)
    np.testing.assert_allclose(y, yref, rtol=0, atol=1e-9 * np.max(np.abs(yref)))
    m = c.model()
    assert m.sample_time == pytest.approx(1 / fs)
    # A NaN input resets the controller and gives 0.
    assert c.step(float("nan")) == 0.0 and c.nonfinite_inputs == 1
    with pytest.raises(pb.InputError) as e:
        control.DiscreteIff(antiwindup_gain=2.0)
    assert e.value.field == "antiwindup_gain"
