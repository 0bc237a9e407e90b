"""piezobench.ident on responses whose poles, zeros and modes are known exactly."""

import numpy as np
import pytest

import piezobench as pb
from piezobench import control, ident, lti


def _two_modes(w):
    s = 1j * w
    p1 = -0.01 * 100 + 1j * 100 * np.sqrt(1 - 0.01**2)
    p2 = -0.02 * 300 + 1j * 300 * np.sqrt(1 - 0.02**2)
    h = (50 / (s - p1) + 50 / (s - np.conj(p1)) + (20 - 10j) / (s - p2) + (20 + 10j) / (s - np.conj(p2)) + 0.01)
    return h, p1, p2


def test_vector_fit_recovers_poles_and_residues():
    w = np.linspace(10.0, 1000.0, 800)
    h, p1, p2 = _two_modes(w)
    fit = ident.vector_fit(w, h, order=4, asymptote="d")
    assert fit.converged
    poles = sorted(fit.poles[fit.poles.imag > 0], key=lambda p: p.imag)
    np.testing.assert_allclose(poles, [p1, p2], rtol=1e-9)
    assert fit.relative_rms_error < 1e-10
    np.testing.assert_allclose(fit.d, [0.01], rtol=1e-8)
    np.testing.assert_allclose(fit.evaluate(w)[:, 0], h, rtol=1e-8)
    # The state-space model is the fitted function (lti.freqresp of it).
    np.testing.assert_allclose(lti.freqresp(fit.model, w), h, rtol=1e-8)
    with pytest.raises(pb.InputError) as e:
        ident.vector_fit(w, h, order=4, asymptote="quadratic")
    assert e.value.field == "asymptote"


def test_frf_features_find_the_nmp_zero_of_the_iff_plant():
    # The report's IFF plant with a non-minimum-phase zero (xz < 0) and no delay.
    # (The plant model refuses xz < 0: the zero pair is mirrored here by hand.)
    w = 2 * np.pi * np.linspace(1.0, 500.0, 4000)
    s, wz, xz = 1j * w, 2 * np.pi * 42.7, 0.004
    mirror = (1 - 2 * xz * s / wz + s**2 / wz**2) / (1 + 2 * xz * s / wz + s**2 / wz**2)
    h = lti.freqresp(control.iff_plant(), w) * mirror
    feat = ident.frf_features(w, h, fit={"order": 6})
    assert len(feat.antiresonances) == 1 and len(feat.resonances) == 1
    anti = feat.antiresonances[0]
    assert anti.frequency_hz == pytest.approx(42.7, rel=1e-4)
    assert anti.damping == pytest.approx(0.004, rel=1e-2)
    assert anti.nonminimum_phase_model
    assert anti.phase_verdict == "non-minimum-phase"
    assert feat.resonances[0].frequency_hz == pytest.approx(95.2, rel=1e-4)
    assert feat.to_dict()["antiresonances"][0]["phase_verdict"] == "non-minimum-phase"
    # The same plant with the zero mirrored: minimum phase.
    h_mp = lti.freqresp(control.iff_plant(xz=0.004), w)
    assert ident.frf_features(w, h_mp, fit={"order": 6}).antiresonances[0].phase_verdict == "minimum-phase"


def test_high_pass_and_second_order_fits():
    w = np.logspace(-1, 2, 200)
    s = 1j * w
    hp = ident.fit_high_pass(w, 3.0 * s / (s + 2.5))
    assert hp.corner == pytest.approx(2.5, rel=1e-6) and hp.gain == pytest.approx(3.0, rel=1e-6)
    wn, z, k = 2 * np.pi * 95.2, 0.02, -1.7e-5
    w2 = 2 * np.pi * np.linspace(10, 400, 600)
    s2 = 1j * w2
    h2 = k * wn**2 / (s2**2 + 2 * z * wn * s2 + wn**2)
    for method in ("nls", "vector-fitting"):
        f = ident.fit_second_order(w2, h2, method=method)
        assert f.natural_frequency == pytest.approx(wn, rel=1e-6)
        assert f.damping == pytest.approx(z, rel=1e-5)
        assert f.static_gain == pytest.approx(k, rel=1e-5)


def test_peak_picking_and_lscf_find_both_modes():
    w = np.linspace(10.0, 600.0, 3000)
    h, p1, p2 = _two_modes(w)
    modes = ident.peak_picking(w, h)
    assert [m.natural_frequency for m in modes] == pytest.approx([100.0, 300.0], rel=2e-3)
    assert [m.damping for m in modes] == pytest.approx([0.01, 0.02], rel=0.05)
    r = ident.lscf(w, h[:, None], max_order=16)
    freqs = sorted(m.natural_frequency for m in r.modes)
    assert freqs == pytest.approx([100.0, 300.0], rel=1e-4)
    assert sorted(m.damping for m in r.modes) == pytest.approx([0.01, 0.02], rel=1e-2)
    assert r.diagram.order.size == r.diagram.pole.size > 0
