"""piezobench.lti against scipy.signal (freqresp, c2d, lsim) and analytic results."""

import numpy as np
import pytest
import scipy.signal as ss

import piezobench as pb
from piezobench import lti

NUM = [2.0, 3.0, 1000.0]
DEN = [1.0, 5.0, 400.0, 1200.0]


def test_freqresp_equals_scipy():
    w = np.logspace(-1, 3, 500)
    tf = lti.TransferFunction(NUM, DEN)
    _, ref = ss.freqresp((NUM, DEN), w)
    for sys in (tf, lti.zpk(tf), lti.ss(tf)):
        h = lti.freqresp(sys, w)
        assert h.dtype == np.complex128 and h.shape == w.shape
        assert np.max(np.abs(h - ref) / np.abs(ref)) < 1e-12
    # MIMO: (len(w), outputs, inputs); delays exact.
    a = np.array([[0.0, 1.0], [-100.0, -2.0]])
    b = np.array([[0.0, 1.0], [1.0, 0.0]])
    c = np.eye(2)
    mimo = lti.StateSpace(a, b, c, np.zeros((2, 2)), input_delay=[1e-3, 0.0])
    h = lti.freqresp(mimo, w)
    assert h.shape == (w.size, 2, 2)
    ref = np.array([c @ np.linalg.solve(1j * wk * np.eye(2) - a, b) for wk in w])
    ref[:, :, 0] *= np.exp(-1j * w * 1e-3)[:, None]
    np.testing.assert_allclose(h, ref, rtol=1e-12, atol=1e-14)


def test_poles_zeros_dc_gain_damp():
    tf = lti.TransferFunction(NUM, DEN)
    p = lti.poles(tf)
    z = lti.zeros(tf)
    np.testing.assert_allclose(np.sort_complex(p), np.sort_complex(np.roots(DEN)), rtol=1e-12)
    np.testing.assert_allclose(np.sort_complex(z), np.sort_complex(np.roots(NUM)), rtol=1e-10)
    assert lti.dc_gain(tf)[0, 0] == pytest.approx(1000.0 / 1200.0, rel=1e-12)
    d = lti.damp(lti.TransferFunction([1.0], [1.0, 2 * 0.05 * 30.0, 900.0]))
    np.testing.assert_allclose(d.natural_frequency, [30.0, 30.0], rtol=1e-12)
    np.testing.assert_allclose(d.damping, [0.05, 0.05], rtol=1e-12)


def test_lti_results_are_the_declared_classes(declared):
    """lti.damp, lsim/step/impulse, rlocus and max_damping_on_branch return the classes of their C++
    declarations (issue 32) with the attributes the dicts had, arrays as numpy arrays."""
    assert set(lti.declarations()) == {"TimeResponse", "RootLocus", "Damping", "BranchOptimum"}
    # damp of wn^2 / (s^2 + 2 zeta wn s + wn^2): poles -zeta wn +- j wn sqrt(1 - zeta^2).
    wn, zeta = 30.0, 0.05
    d = declared(lti.damp(lti.TransferFunction([1.0], [1.0, 2 * zeta * wn, wn**2])), lti, "Damping")
    assert d.keys() == ["poles", "natural_frequency", "damping"]
    assert d.poles.dtype == complex and d.natural_frequency.dtype == float and d.damping.shape == (2,)
    np.testing.assert_allclose(np.sort_complex(d.poles), np.sort_complex(np.roots([1.0, 2 * zeta * wn, wn**2])), rtol=1e-12)
    # step of a first-order lag 1 / (tau s + 1) at the samples: 1 - exp(-t / tau) (ZOH is exact for a step).
    tau, ts = 0.01, 1e-3
    st = declared(lti.step(lti.TransferFunction([1.0], [tau, 1.0]), ts, 50), lti, "TimeResponse")
    assert st.keys() == ["t", "y", "x"] and st.y.shape == (50, 1) and st.x.shape == (50, 1)
    np.testing.assert_allclose(st.y[:, 0], 1.0 - np.exp(-st.t / tau), atol=1e-12)
    np.testing.assert_allclose(st.t, np.arange(50) * ts, rtol=1e-15)
    # rlocus of 1 / (s (s + 2)): s^2 + 2 s + k = 0.
    rl = declared(lti.rlocus(lti.TransferFunction([1.0], [1.0, 2.0, 0.0]), [0.0, 4.0]), lti, "RootLocus")
    assert rl.keys() == ["gains", "poles"] and rl.gains.dtype == float and rl.poles.dtype == complex
    np.testing.assert_array_equal(rl.gains, [0.0, 4.0])
    np.testing.assert_allclose(np.sort_complex(rl.poles[1]), np.sort_complex(np.roots([1.0, 2.0, 4.0])), rtol=1e-12)
    # 1/((s+1)(s^2 + 0.2 s + 100)): the optimum's pole is a closed-loop pole at its gain, damping -Re/|p|.
    res = lti.TransferFunction([1.0], np.polymul([1.0, 1.0], [1.0, 0.2, 100.0]))
    b = declared(lti.max_damping_on_branch(res, complex(-0.1, 10.0)), lti, "BranchOptimum")
    assert b.keys() == ["gain", "damping", "pole"] and isinstance(b.pole, complex) and isinstance(b.gain, float)
    assert b.damping == pytest.approx(-b.pole.real / abs(b.pole), rel=1e-9)
    assert np.min(np.abs(lti.closed_loop_poles(res, b.gain) - b.pole)) < 1e-9 * abs(b.pole)


def test_c2d_equals_scipy():
    ts = 1e-3
    sys = lti.ss(lti.TransferFunction(NUM, DEN))
    for method, ref in (("zoh", "zoh"), ("tustin", "bilinear")):
        d = lti.c2d(sys, ts, method=method)
        ad, bd, cd, dd, _ = ss.cont2discrete((sys.A, sys.B, sys.C, sys.D), ts, method=ref)
        np.testing.assert_allclose(d.A, ad, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(d.B, bd, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(d.C, cd, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(d.D, dd, rtol=1e-12, atol=1e-14)
        assert d.sample_time == ts and d.is_discrete
    # Transfer function in, transfer function out.
    dtf = lti.c2d(lti.TransferFunction(NUM, DEN), ts)
    assert isinstance(dtf, lti.TransferFunction) and dtf.sample_time == ts
    nd, dd_, _ = ss.cont2discrete((NUM, DEN), ts, method="zoh")
    np.testing.assert_allclose(dtf.den / dtf.den[0], dd_ / dd_[0], rtol=1e-10)
    np.testing.assert_allclose(np.trim_zeros(dtf.num / dtf.den[0], "f"), np.trim_zeros(nd.ravel() / dd_[0], "f"),
                               rtol=1e-8)
    with pytest.raises(pb.InputError) as e:
        lti.c2d(sys, ts, method="foh")
    assert e.value.field == "method" or "method" in str(e.value)


def test_lsim_equals_scipy_dlsim():
    ts = 1e-3
    d = lti.c2d(lti.ss(lti.TransferFunction(NUM, DEN)), ts)
    u = np.sin(2 * np.pi * 5 * np.arange(2000) * ts) + np.random.default_rng(0).standard_normal(2000) * 0.1
    r = lti.lsim(d, u)
    _, yref, xref = ss.dlsim((d.A, d.B, d.C, d.D, ts), u)
    np.testing.assert_allclose(r.y, yref, rtol=1e-10, atol=1e-12 * np.max(np.abs(yref)))
    np.testing.assert_allclose(r.t, np.arange(2000) * ts, rtol=1e-15)
    st = lti.step(lti.TransferFunction([100.0], [1.0, 20.0, 100.0]), 1e-3, 3000)
    assert st.y[-1, 0] == pytest.approx(1.0, abs=1e-6)


def test_root_locus_and_max_damping():
    # L = 1 / (s (s + 2)): closed-loop poles s^2 + 2 s + k = 0; damping 1/sqrt(k) beyond k = 1.
    ol = lti.TransferFunction([1.0], [1.0, 2.0, 0.0])
    rl = lti.rlocus(ol, [0.0, 1.0, 4.0])
    assert rl.poles.shape == (3, 2)
    np.testing.assert_allclose(np.sort_complex(rl.poles[2]), [-1 - 1j * np.sqrt(3), -1 + 1j * np.sqrt(3)], rtol=1e-12)
    np.testing.assert_allclose(np.sort_complex(lti.closed_loop_poles(ol, 4.0)), np.sort_complex(rl.poles[2]),
                               rtol=1e-12)
    auto = lti.rlocus(ol, gain_max=10.0)
    assert auto.gains[-1] == pytest.approx(10.0) and auto.poles.shape[0] == auto.gains.size
    # L = 1/((s+1)(s^2 + 0.2 s + 100)): the optimum is interior and found to 1e-6.
    res = lti.TransferFunction([1.0], np.polymul([1.0, 1.0], [1.0, 0.2, 100.0]))
    best = lti.max_damping_on_branch(res, complex(-0.1, 10.0))
    gains = np.linspace(0.0, best.gain * 2, 2001)
    zetas = []
    for g in gains:
        p = lti.closed_loop_poles(res, g)
        q = p[np.argmin(np.abs(p - best.pole))]
        zetas.append(-q.real / abs(q))
    assert best.damping >= max(zetas) - 1e-9
    with pytest.raises(pb.InputError) as e:
        lti.rlocus(ol, max_pointz=3)
    assert e.value.field == "max_pointz"


def test_conversions_and_interconnections():
    tf = lti.TransferFunction(NUM, DEN)
    z = lti.zpk(tf)
    back = lti.tf(z)
    np.testing.assert_allclose(np.trim_zeros(back.num, "f") / back.den[0], np.array(NUM) / DEN[0], rtol=1e-10)
    np.testing.assert_allclose(back.den / back.den[0], np.array(DEN) / DEN[0], rtol=1e-10)
    w = np.array([1.0, 10.0, 100.0])
    fb = lti.feedback(tf, lti.ss(lti.TransferFunction([2.0], [1.0])))
    h = lti.freqresp(tf, w)
    np.testing.assert_allclose(lti.freqresp(fb, w), h / (1 + 2 * h), rtol=1e-11)
    np.testing.assert_allclose(lti.freqresp(lti.series(tf, tf), w), h * h, rtol=1e-11)
    np.testing.assert_allclose(lti.freqresp(lti.parallel(tf, tf), w), 2 * h, rtol=1e-11)
    pade = lti.pade(1e-3, 4)
    np.testing.assert_allclose(np.abs(lti.freqresp(pade, w)), 1.0, rtol=1e-12)
    a = np.array([[0.0, 1.0], [-2.0, -3.0]])
    import scipy.linalg
    np.testing.assert_allclose(lti.expm(a), scipy.linalg.expm(a), rtol=1e-13)
    np.testing.assert_allclose(lti.logspace(0, 2, 3), [1.0, 10.0, 100.0], rtol=1e-15)
