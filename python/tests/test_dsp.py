"""piezobench.dsp against scipy.signal on the same arrays."""

import numpy as np
import pytest
import scipy.signal as ss
from scipy.stats import t as ss_t

import piezobench as pb
from piezobench import dsp


def _record(n=50_000, fs=10e3, seed=3):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    b, a = ss.butter(2, [80.0, 120.0], btype="bandpass", fs=fs)
    y = ss.lfilter(b, a, u) + 0.05 * rng.standard_normal(n)
    y2 = 0.3 * u + 0.1 * rng.standard_normal(n)
    return u, y, y2, fs


def test_welch_csd_equal_scipy():
    u, y, _, fs = _record()
    f, p = dsp.welch(u, fs, nfft=2048, overlap=0.5, detrend="mean")
    fr, pr = ss.welch(u, fs, nperseg=2048, noverlap=1024, detrend="constant")
    np.testing.assert_array_equal(f, fr)
    assert np.max(np.abs(p - pr)) <= 1e-12 * np.max(np.abs(pr))
    f, c = dsp.csd(u, y, fs, nfft=1000, overlap=0.25, window="hamming-periodic")
    fr, cr = ss.csd(u, y, fs, window="hamming", nperseg=1000, noverlap=250, detrend=False)
    np.testing.assert_allclose(f, fr, rtol=0, atol=1e-12)
    assert np.max(np.abs(c - cr)) <= 1e-12 * np.max(np.abs(cr))


def test_h1_h2_coherence_equal_scipy_to_1e12():
    u, y, y2, fs = _record()
    nfft = 4096
    kw = dict(nfft=nfft, overlap=0.5, window="hann-periodic", detrend="none")
    f, h1 = dsp.h1(u, y, fs, **kw)
    _, coh = dsp.coherence(u, y, fs, **kw)
    _, h2 = dsp.h2(u, y, fs, **kw)
    sp = dict(fs=fs, window="hann", nperseg=nfft, noverlap=nfft // 2, detrend=False)
    fr, puy = ss.csd(u, y, **sp)
    _, puu = ss.welch(u, **sp)
    _, pyy = ss.welch(y, **sp)
    _, cr = ss.coherence(u, y, **sp)
    np.testing.assert_array_equal(f, fr)
    assert np.max(np.abs(h1 - puy / puu) / np.abs(puy / puu)) < 1e-12
    assert np.max(np.abs(h2 - pyy / np.conj(puy)) / np.abs(pyy / puy)) < 1e-12
    assert np.max(np.abs(coh - cr)) < 1e-12
    # frf(): both outputs in one pass, the same numbers.
    est = dsp.frf(u, np.vstack([y, y2]), fs, outputs=["de", "Vs"], **kw)
    assert est.H.shape == (2, nfft // 2 + 1)
    np.testing.assert_array_equal(est.H[0], h1)
    np.testing.assert_array_equal(est.coherence[0], coh)
    _, puy2 = ss.csd(u, y2, **sp)
    assert np.max(np.abs(est.H[1] - puy2 / puu) / np.abs(puy2 / puu)) < 1e-12
    assert est.frf.outputs == ["de", "Vs"]
    np.testing.assert_array_equal(est.frf.response("Vs"), est.H[1])
    assert est.averages == (len(u) - nfft) // (nfft // 2) + 1


def test_frf_std_is_bendat_piersol_with_welchs_effective_averages():
    # Computed here from scipy's window and coherence: n_d (Welch 1967) and
    # std_H = |H| sqrt((1 - coh) / (2 n_d coh)).
    u, y, _, fs = _record()
    nfft, step = 4096, 2048
    est = dsp.frf(u, y, fs, nfft=nfft, overlap=0.5, window="hann-periodic", detrend="none")
    w = ss.get_window("hann", nfft)
    k = est.averages
    rho = [np.dot(w[: nfft - j * step], w[j * step:]) / np.dot(w, w) for j in range(1, k) if j * step < nfft]
    n_d = k / (1 + 2 * sum((1 - (j + 1) / k) * r**2 for j, r in enumerate(rho)))
    assert est.frf.provenance["effective_averages"] == pytest.approx(n_d, rel=1e-12)
    _, coh = ss.coherence(u, y, fs=fs, window="hann", nperseg=nfft, noverlap=step, detrend=False)
    want = np.abs(est.H) * np.sqrt((1 - coh) / (2 * n_d * coh))
    np.testing.assert_allclose(est.std_H, want, rtol=1e-9)
    np.testing.assert_array_equal(est.frf.std_H, est.std_H)
    f = dsp.Frf(est.freq_Hz, est.H, coherence=est.coherence, std_H=est.std_H)
    np.testing.assert_array_equal(f.std_H, est.std_H)
    # The 95 % band's factor k = sqrt(n_d / (n_d - 1)) t(2 n_d - 2), checked through scipy's t.cdf
    # (exact to ~1e-16; its t.ppf is ~1e-9 off at these degrees of freedom).
    c, dof = np.sqrt(n_d / (n_d - 1)), 2 * n_d - 2
    assert ss_t.cdf(est.frf.band_factor / c, dof) == pytest.approx(0.975, abs=1e-13)
    assert dsp.band_factor(n_d) == est.frf.band_factor
    assert ss_t.cdf(dsp.band_factor(n_d, level=0.99) / c, dof) == pytest.approx(0.995, abs=1e-13)
    assert f.band_factor is None  # built without provenance: n_d unknown


def test_arrays_are_read_in_place_and_results_are_numpy():
    u, y, _, fs = _record(n=8192)
    f, h = dsp.h1(u, y, fs, nfft=1024)
    assert h.dtype == np.complex128 and f.dtype == np.float64
    assert h.flags["C_CONTIGUOUS"] and h.flags["OWNDATA"] is False  # handed over, not copied
    # Strided and float32 inputs are converted, with the same result as contiguous float64.
    u2 = np.repeat(u, 2)[::2]
    _, h_strided = dsp.h1(u2, y.astype(np.float64), fs, nfft=1024)
    np.testing.assert_array_equal(h, h_strided)


def test_window_equals_scipy_get_window():
    for name, ref in [("hann-periodic", "hann"), ("hamming-periodic", "hamming"), ("flattop-periodic", "flattop")]:
        np.testing.assert_allclose(dsp.window(name, 257), ss.get_window(ref, 257), rtol=0, atol=1e-15)
    np.testing.assert_allclose(dsp.window("hann-symmetric", 64), ss.windows.hann(64, sym=True), rtol=0, atol=1e-15)


def test_excitations():
    ms = dsp.multisine(sample_rate=1000.0, period_samples=1000, periods=2, lines_Hz=[10.0, 20.0, 50.0], rms=0.5,
                       offset=3.0)
    assert ms.u.shape == (2000,)
    # Exactly the three lines, with the requested rms, on top of the offset.
    spec = np.fft.rfft(ms.u[:1000] - 3.0) / 1000
    lines = np.flatnonzero(np.abs(spec) > 1e-9)
    np.testing.assert_array_equal(lines, [10, 20, 50])
    assert np.std(ms.u[:1000]) == pytest.approx(0.5, rel=1e-12)
    assert np.mean(ms.u) == pytest.approx(3.0, abs=1e-12)
    sweep = dsp.sine_sweep(sample_rate=1000.0, duration=2.0, f_start=1.0, f_end=100.0, amplitude=1.0, offset=3.0,
                           type="linear")
    assert sweep.u.size == 2000 and sweep.kind.startswith("sweep")
    assert np.max(sweep.u) <= 4.0 + 1e-12
    # The default bounds (-1..7.5 V) scale an offset noise that would leave them.
    noise = dsp.band_limited_noise(samples=4096, f_low=10.0, f_high=500.0, rms=3.0, offset=3.0, seed=7)
    assert noise.scaled and noise.scale < 1.0
    assert noise.u.min() >= -1.0 - 1e-12 and noise.u.max() <= 7.5 + 1e-12
    with pytest.raises(pb.InputError) as e:
        dsp.band_limited_noise(samples=4096, f_low=10.0, f_high=500.0, rms=3.0, offset=3.0,
                               bounds={"policy": "reject"})
    assert "bounds" in str(e.value) or e.value.field
    st = dsp.steps(sample_rate=100.0, levels=[1.0, 2.0], hold_time=1.0, ramp_time=0.0)
    assert set(np.round(np.unique(st.u), 12)) == {0.0, 1.0, 2.0}


def test_dsp_results_are_the_declared_classes(declared):
    """The excitations and dsp.frf return the classes of their declarations, arrays as before."""
    assert {"Frf", "FrfProvenance", "Excitation", "FrfEstimate"} <= set(dsp.declarations())
    ms = declared(dsp.multisine(sample_rate=1000.0, period_samples=1000, periods=2, lines_Hz=[10.0, 20.0, 50.0], rms=0.5,
                                offset=3.0), dsp, "Excitation")
    assert ms.keys() == ["u", "t", "sample_rate", "kind", "scaled", "scale", "clipped", "lines_Hz", "seed"]
    np.testing.assert_array_equal(ms.t, np.arange(2000) / 1000.0)
    np.testing.assert_array_equal(ms.lines_Hz, [10.0, 20.0, 50.0])
    assert ms.sample_rate == 1000.0 and ms.kind.startswith("multisine") and isinstance(ms.clipped, int)
    assert not ms.scaled and ms.scale == 1.0
    noise = declared(dsp.band_limited_noise(samples=4096, f_low=10.0, f_high=500.0, rms=0.1, seed=7), dsp, "Excitation")
    assert noise.seed == 7 and isinstance(noise.seed, int)
    # dsp.frf: one 1-D output gives 1-D arrays, two give (outputs, points); values as scipy's Welch.
    rng = np.random.default_rng(1)
    fs, nfft = 1000.0, 256
    u = rng.standard_normal(8192)
    y = ss.lfilter([0.5, 0.2], [1.0], u)
    kw = dict(nfft=nfft, overlap=0.5, window="hann-periodic", detrend="none")
    one = declared(dsp.frf(u, y, fs, **kw), dsp, "FrfEstimate")
    assert set(one.keys()) == {"freq_Hz", "H", "coherence", "std_H", "Suu", "Syy", "Suy", "averages", "frf"}
    assert one.H.shape == (nfft // 2 + 1,) and one.H.dtype == complex and one.Syy.shape == one.coherence.shape == one.H.shape
    f, pxy = ss.csd(u, y, fs, window="hann", nperseg=nfft, noverlap=nfft // 2, detrend=False)
    np.testing.assert_allclose(one.freq_Hz, f, rtol=1e-12)
    np.testing.assert_allclose(one.Suy, pxy, rtol=1e-9, atol=1e-15)
    _, puu = ss.welch(u, fs, window="hann", nperseg=nfft, noverlap=nfft // 2, detrend=False)
    np.testing.assert_allclose(one.Suu, puu, rtol=1e-9)
    np.testing.assert_allclose(one.H, pxy / puu, rtol=1e-9)
    assert isinstance(one.frf, dsp.Frf) and one.averages == one.frf.provenance.averages
    two = dsp.frf(u, np.vstack([y, 2 * y]), fs, outputs=["a", "b"], **kw)
    assert two.H.shape == (2, nfft // 2 + 1) and two.Syy.shape == two.Suy.shape == two.std_H.shape == two.H.shape
    np.testing.assert_allclose(two.H[1], 2 * one.H, rtol=1e-12)


def test_bad_arguments_raise_input_error_naming_the_field():
    u, y, _, fs = _record(n=4096)
    with pytest.raises(pb.InputError) as e:
        dsp.h1(u, y, fs, nfft=1024, nfftt=3)
    assert e.value.field == "nfftt" and "unknown" in e.value.found
    with pytest.raises(pb.InputError) as e:
        dsp.h1(u, y, fs, nfft=1)
    assert e.value.field == "nfft"
    with pytest.raises(pb.InputError) as e:
        dsp.h1(u, y, fs, window="triangle")
    assert e.value.field == "window"
    bad = y.copy()
    bad[123] = np.nan
    with pytest.raises(pb.InputError) as e:
        dsp.h1(u, bad, fs, nfft=1024)
    assert "123" in str(e.value)
    with pytest.raises(pb.InputError) as e:
        dsp.h1(u.reshape(2, -1, 1), y, fs)
    assert e.value.field == "u" and "1-D" in e.value.expected
    with pytest.raises(pb.InputError) as e:
        dsp.h1(u, y[:100], fs, nfft=64)
    with pytest.raises(pb.InputError) as e:
        dsp.h1(u, y, fs, overlap="half")
    assert e.value.field == "overlap" and e.value.expected == "a number"
    with pytest.raises(pb.InputError):
        dsp.welch(u, float("nan"))
