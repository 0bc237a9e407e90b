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
    # The data have 3 poles (the mirror's cancel the plant's zeros); order 4 leaves one spare pole.
    # (With 3 spare poles, where they land is decided by round-off: one pair next to the 95.2 Hz
    # pole, with a zero that cancels it, hid the resonance with the FMA kernels of vector_fit.)
    feat = ident.frf_features(w, h, fit={"order": 4})
    assert len(feat.antiresonances) == 1 and len(feat.resonances) == 1
    anti = feat.antiresonances[0]
    assert anti.frequency_Hz == pytest.approx(42.7, rel=1e-4)
    assert anti.damping == pytest.approx(0.004, rel=1e-2)
    assert anti.nonminimum_phase_model
    assert anti.phase_verdict == "non-minimum-phase"
    assert feat.resonances[0].frequency_Hz == pytest.approx(95.2, rel=1e-4)
    assert feat.to_dict()["antiresonances"][0]["phase_verdict"] == "non-minimum-phase"
    # The same plant with the zero mirrored: minimum phase.
    h_mp = lti.freqresp(control.iff_plant(xz=0.004), w)
    assert ident.frf_features(w, h_mp, fit={"order": 6}).antiresonances[0].phase_verdict == "minimum-phase"


def test_high_pass_and_second_order_fits():
    w = np.logspace(-1, 2, 200)
    s = 1j * w
    hp = ident.fit_high_pass(w, 3.0 * s / (s + 2.5))
    assert hp.corner == pytest.approx(2.5, rel=1e-6) and hp.gain == pytest.approx(3.0, rel=1e-6)
    assert hp.corner_Hz == pytest.approx(2.5 / (2 * np.pi), rel=1e-6) and isinstance(hp, ident.HighPassFit)
    wn, z, k = 2 * np.pi * 95.2, 0.02, -1.7e-5
    w2 = 2 * np.pi * np.linspace(10, 400, 600)
    s2 = 1j * w2
    h2 = k * wn**2 / (s2**2 + 2 * z * wn * s2 + wn**2)
    for method in ("nls", "vector-fitting"):
        f = ident.fit_second_order(w2, h2, method=method)
        assert f.natural_frequency == pytest.approx(wn, rel=1e-6)
        assert f.damping == pytest.approx(z, rel=1e-5)
        assert f.static_gain == pytest.approx(k, rel=1e-5)
        assert f.frequency_Hz == pytest.approx(95.2, rel=1e-6) and f.poles.shape == (2,)


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
    # The stabilization diagram: every physical pole of every order, each an ident.StabilizationPole.
    assert len(r.diagram) > 0 and all(p.order >= 2 and p.pole.imag > 0 for p in r.diagram)
    assert any(p.stable for p in r.diagram) and r.quality.verdict == "good"


# ---- the plant fits of the report (ident/plant_fit.hpp) on scipy-generated responses -----------

def _iff_plant_scipy(w, g0, wz, xz, wp, xp, w_hpf, delay):
    """Eq. 2.3 with scipy.signal.freqs: g0 (1 + 2 xz s/wz + s^2/wz^2) / (1 + 2 xp s/wp + s^2/wp^2)
    * s / (w_hpf + s) * exp(-s delay)."""
    from scipy import signal
    num = g0 * np.polymul([1 / wz**2, 2 * xz / wz, 1.0], [1.0, 0.0])
    den = np.polymul([1 / wp**2, 2 * xp / wp, 1.0], [1.0, w_hpf])
    _, h = signal.freqs(num, den, worN=w)
    return h * np.exp(-1j * w * delay)


def test_iff_plant_fit_recovers_a_scipy_eq_2_3_plant_with_its_nonminimum_phase_zero():
    truth = dict(g0=0.64, wz=2 * np.pi * 42.7, xz=-0.004, wp=2 * np.pi * 95.2, xp=0.02, w_hpf=2 * np.pi * 0.4,
                 delay=200e-6)
    w = 2 * np.pi * np.arange(0.5, 1000.01, 0.5)
    h = _iff_plant_scipy(w, **truth)
    fit = ident.fit_iff_plant(w, h)
    assert isinstance(fit, ident.IffPlantFit)
    for name in ("g0", "wz", "wp", "xp", "w_hpf", "delay"):
        assert getattr(fit, name) == pytest.approx(truth[name], rel=1e-3), name
    assert fit.xz == pytest.approx(truth["xz"], abs=1e-4)
    assert fit.zero_is_nonminimum_phase
    assert fit.wp_Hz == pytest.approx(95.2, rel=1e-3)
    assert fit.relative_rms_error < 1e-3
    assert fit.quality.verdict == "good" and not fit.quality.poor and not fit.quality.impossible
    assert fit.quality.problems == [] and fit.quality.summary == "good"
    # The fitted model is the control module's plant: same response as scipy's.
    np.testing.assert_allclose(fit.response(w), h, rtol=2e-3)
    g = control.iff_plant(**fit.params())
    np.testing.assert_allclose(np.ravel(lti.freqresp(g, w)), fit.response(w), rtol=1e-9)
    d = fit.to_dict()
    assert d["wz"] == fit.wz and d["quality"]["verdict"] == "good"
    with pytest.raises(AttributeError):
        fit.wz = 1.0  # read-only


def test_delayed_second_order_fit_recovers_a_scipy_mass_spring_damper():
    from scipy import signal
    k, wn, zeta, delay = -1.68e-5, 2 * np.pi * 95.4, 0.0056, 250e-6
    w = 2 * np.pi * np.arange(20.0, 500.0, 0.5)
    _, h = signal.freqs([k * wn**2], [1.0, 2 * zeta * wn, wn**2], worN=w)
    h = h * np.exp(-1j * w * delay)
    fit = ident.fit_delayed_second_order(w, h)
    assert fit.static_gain == pytest.approx(k, rel=1e-6)
    assert fit.natural_frequency == pytest.approx(wn, rel=1e-6)
    assert fit.damping == pytest.approx(zeta, rel=1e-4)
    assert fit.delay == pytest.approx(delay, rel=1e-4)
    assert fit.pole == pytest.approx(-zeta * wn + 1j * wn * np.sqrt(1 - zeta**2), rel=1e-6)
    assert fit.quality.verdict == "good"
    # Keywords are the C++ options' names, checked.
    with pytest.raises(pb.InputError) as e:
        ident.fit_delayed_second_order(w, h, fmax=400.0)
    assert e.value.field == "fmax"


def test_actuator_plants_of_a_scipy_welch_frf_and_the_vector_fit_verdicts(welch_frf):
    frf, truth = welch_frf
    plants = ident.fit_actuator_plants(frf)
    assert plants.failures == []
    assert plants.de.natural_frequency / (2 * np.pi) == pytest.approx(truth["resonance_Hz"], rel=0.01)
    assert plants.de.static_gain == pytest.approx(truth["static_gain_de_m_per_V"], rel=0.02)
    assert plants.de.delay == pytest.approx(truth["effective_delay_s"], rel=0.05)
    assert plants.vs.wp_Hz == pytest.approx(truth["resonance_Hz"], rel=0.01)
    assert plants.vs.wz_Hz == pytest.approx(truth["antiresonance_Hz"], rel=0.01)
    assert plants.vs.w_hpf_Hz == pytest.approx(truth["hpf_corner_Hz"], rel=0.1)
    assert plants.de.quality.verdict == "good" and plants.vs.quality.verdict == "good"
    # The same plant from (frf, output) with the FRF's coherence and the options the pair used.
    vs = ident.fit_iff_plant(frf, "Vs", **plants.vs_options)
    assert vs.wz == plants.vs.wz and vs.delay == plants.vs.delay
    # Vector fitting reports its verdict: order 2 over 20-400 Hz finds the resonance (good).
    w = frf.omega
    band = (frf.freq_Hz >= 20) & (frf.freq_Hz <= 400)
    good = ident.vector_fit(w[band], frf.response("de")[band], order=2)
    assert good.quality.verdict == "good"
    assert abs(good.poles[0]) / (2 * np.pi) == pytest.approx(truth["resonance_Hz"], rel=0.01)
    # Two modes of equal static gain fitted with one pole pair leave an error far above 20 %: poor,
    # the output and its error named.
    w2 = np.linspace(10.0, 1000.0, 800)
    s2 = 1j * w2
    h2 = sum(wn**2 / (s2**2 + 2 * 0.01 * wn * s2 + wn**2) for wn in (100.0, 500.0))
    poor = ident.vector_fit(w2, h2, order=2, fail_if_not_converged=False)
    assert poor.quality.poor and poor.quality.verdict == "poor" and poor.quality.advice
    assert any("output 1" in p for p in poor.quality.problems), poor.quality.problems
    assert poor.to_dict()["quality"]["verdict"] == "poor"


def test_each_declared_ident_result_is_a_class_with_every_declared_field():
    """ident's results declare their fields once (ident/*.hpp); Python binds them from the declaration:
    ident.declarations() lists each with its class, every declared field is an attribute, and the
    classes live in ident (not in the module that first held them)."""
    decl = ident.declarations()
    assert {"IffPlantFit", "DelayedSecondOrderFit", "VectorFittingResult", "HysteresisFit", "HysteresisModel",
            "PrandtlIshlinskii", "DeadZoneSuperposition", "CreepFit", "LoopMetrics", "FrfFeatures", "ModalFeature",
            "AntiResonance", "HighPassFit", "SecondOrderFit", "LscfResult", "Mode", "StabilizationPole",
            "ActuatorPlants", "IffPlantFitOptions"} <= set(decl)
    for name, (cls, fields) in decl.items():
        assert getattr(ident, name) is cls, name
        assert [f[0] for f in cls.fields()] == fields, name
        missing = [f for f in fields if not hasattr(cls, f)]
        assert not missing, (name, missing)
    units = {f[0]: f[1] for f in ident.IffPlantFit.fields()}
    assert units["wz"] == "rad/s" and units["delay"] == "s" and units["xz"] == "1"


def test_every_declared_field_of_the_plant_fits_holds_the_fits_value():
    from scipy import signal
    k, wn, zeta = -1.68e-5, 2 * np.pi * 95.4, 0.0056
    w = 2 * np.pi * np.arange(20.0, 500.0, 0.5)
    _, h = signal.freqs([k * wn**2], [1.0, 2 * zeta * wn, wn**2], worN=w)
    fit = ident.fit_delayed_second_order(w, h)
    assert fit.points == len(w) and fit.iterations > 0
    assert fit.status in ("cost-converged", "step-converged", "gradient-converged")  # an enum by its name
    # The relative rms error recomputed from the fit's own response.
    rel = np.sqrt(np.mean(np.abs(fit.response(w) / h - 1) ** 2))
    assert fit.relative_rms_error == pytest.approx(rel, rel=1e-6, abs=1e-12)
    u = fit.uncertainty
    assert list(u.names) == ["static_gain", "natural_frequency", "damping", "delay"]
    assert u.value[1] == fit.natural_frequency
    # The vector fit: every declared field, the per-output error recomputed with numpy.
    w2 = np.linspace(10.0, 1000.0, 800)
    s2 = 1j * w2
    h2 = sum(wn**2 / (s2**2 + 2 * 0.01 * wn * s2 + wn**2) for wn in (100.0, 500.0))
    vf = ident.vector_fit(w2, h2, order=2, fail_if_not_converged=False)
    err = vf.evaluate(w2)[:, 0] - h2
    assert vf.relative_rms_error_per_output[0] == pytest.approx(np.sqrt(np.sum(abs(err) ** 2) / np.sum(abs(h2) ** 2)), rel=1e-9)
    assert vf.rms_error == pytest.approx(np.sqrt(np.mean(abs(err) ** 2)), rel=1e-9)
    assert vf.convergence in ("not-converged", "poles-settled", "residual-settled")
    assert vf.converged == (vf.convergence != "not-converged")
    assert vf.residues.shape == (1, 2) and len(vf.d) == 1 and len(vf.e) == 1
    assert vf.brief_report()


def test_the_fits_see_their_model_through_the_welch_windows_resolution_kernel():
    # A Welch estimate converges to H smoothed by the window's kernel |W(nu)|^2 (dsp/resolution_kernel.hpp).
    # Here that smoothing is computed independently: scipy's hann of nfft = 4000 samples at 1 kHz (0.25 Hz
    # lines), its DTFT on a 1/32-line grid over +-8 lines, applied to an exact mass-spring-damper whose
    # half-power half-width (0.53 Hz) is two lines. With the FRF's provenance the fit sees its model
    # through the kernel and recovers the damping; without it (window_resolution=False, or an FRF with no
    # provenance) the smoothing reads as more damping: measured +0.01 % and +3.6 %.
    from scipy import signal
    k, fn, zeta = -1.68e-5, 95.4, 0.0056
    fs, nfft = 1000.0, 4000
    df = fs / nfft
    f = np.arange(20.0, 500.0, df)
    offsets = np.arange(-8 * 32, 8 * 32 + 1) / 32.0
    window = signal.get_window("hann", nfft)
    kernel = np.abs(np.exp(-2j * np.pi * np.outer(offsets / nfft, np.arange(nfft))) @ window) ** 2
    kernel /= kernel.sum()
    wn = 2 * np.pi * fn

    def response(freq):
        s = 2j * np.pi * freq
        return k * wn**2 / (s**2 + 2 * zeta * wn * s + wn**2)

    smoothed = sum(c * response(f + o * df) for c, o in zip(kernel, offsets))
    provenance = {"window": "hann", "nfft": nfft, "sample_rate": fs}
    frf = pb.dsp.Frf(f, smoothed, outputs=["de"], provenance=provenance)
    with_kernel = ident.fit_delayed_second_order(frf, "de", fit_delay=False)
    without = ident.fit_delayed_second_order(frf, "de", fit_delay=False, window_resolution=False)
    bare = ident.fit_delayed_second_order(pb.dsp.Frf(f, smoothed, outputs=["de"]), "de", fit_delay=False)
    assert with_kernel.damping == pytest.approx(zeta, rel=1e-3)
    assert without.damping / zeta - 1.0 > 0.03
    assert bare.damping == without.damping
    assert with_kernel.natural_frequency == pytest.approx(wn, rel=1e-5)
    # The smoothing the fit undid: the smoothed response is 5.7 % below the exact one at the peak.
    peak = np.argmin(np.abs(f - fn))
    assert abs(smoothed[peak] / response(f[peak])) < 0.95


@pytest.mark.parametrize("band, most", [((20.0, 500.0), 1.2), ((60.0, 150.0), 2.6)])
def test_resonance_standard_error_matches_the_scatter_of_welch_estimates_with_a_random_input(band, most):
    # The random input's own error at a sharp resonance (the window's leakage, dsp/leakage_covariance.hpp):
    # 60 records of 20 s at 2 kHz, a mass-spring-damper at 95.6 Hz, zeta 0.006 (4.6 lines of 0.25 Hz
    # wide, the virtual bench's resonance), 200 us delay, a Gaussian input with a continuous spectrum
    # (periodic over 160 s, 8 records), output noise of 0.1 % of its rms; Welch's H1, hann, 4 s at
    # 50 %. The fit's standard errors against the estimates' scatter: 0.98 for the natural frequency
    # and 0.83 for the damping here (0.95 and 0.85 over 200 records; 1.00 and 0.86 over 100 at 1 %
    # noise; docs/uncertainty.md section 6). The second pass weighted by the model's variance
    # (IffPlantFitOptions::effective_averages) brought the frequency's from 1.26 (1.41 over 200
    # records), where the weights followed each record's own coherence; without the leakage error's
    # covariance it was 4-5. In a band narrow around the peak (60-150 Hz) too few lines are clean of the
    # leakage for a noise model (no second pass): the noise is then the coherence with the leakage
    # divided out, and the frequency's standard error about 2 times its scatter (5.2 when the measured
    # std, leakage and all, was kept there and the leakage counted twice; 1.03 at 1 % noise, where the
    # noise model is fitted).
    fs, n, nfft = 2000.0, 40000, 8000
    wn, zeta, delay = 2 * np.pi * 95.6, 0.006, 2e-4
    period = 8 * n
    f = np.arange(period // 2 + 1) * fs / period
    s = 2j * np.pi * f
    h = wn**2 / (s * s + 2 * zeta * wn * s + wn**2) * np.exp(-s * delay)
    rng = np.random.default_rng(3)
    frequency, frequency_se, damping, damping_se = [], [], [], []
    for _ in range(60):
        x_spectrum = rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)
        x_spectrum[0] = 0.0
        x = np.fft.irfft(x_spectrum, period)[:n]
        y = np.fft.irfft(h * x_spectrum, period)[:n]
        y = y + 1e-3 * np.std(y) * rng.standard_normal(n)
        frf = pb.dsp.frf(x, y[None, :], fs, outputs=["de"], nfft=nfft, overlap=0.5, window="hann-periodic", detrend="mean").frf
        fit = ident.fit_delayed_second_order(frf, "de", fmin_Hz=band[0], fmax_Hz=band[1])
        frequency.append(fit.natural_frequency)
        frequency_se.append(fit.uncertainty.standard_error_of("natural_frequency"))
        damping.append(fit.damping)
        damping_se.append(fit.uncertainty.standard_error_of("damping"))
    frequency_ratio = np.median(frequency_se) / np.std(frequency, ddof=1)
    damping_ratio = np.median(damping_se) / np.std(damping, ddof=1)
    assert 0.8 <= frequency_ratio <= most, frequency_ratio
    assert 0.7 <= damping_ratio <= 1.5, damping_ratio
    assert abs(np.mean(frequency) / wn - 1.0) < 1e-4  # the fit through the window's kernel is unbiased
