"""A small version of scripts/uncertainty/calibrate.py (issue 30): the FRF's 95 % band, the plant
fits' and the 2-DoF tuning's intervals on the virtual bench, over a few noise seeds, with bounds that
a variance wrong by 20 % (the band) or a standard error wrong by a factor 2 fails (docs/uncertainty.md,
section 6). The full script runs 200 seeds (minutes)."""

import math
import os
import sys

import numpy as np
import pytest

from piezobench import bench, lti

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "uncertainty"))
import calibrate  # noqa: E402

SEEDS = range(1, 9)  # 8 records of 20 s: ~64,000 lines per output


@pytest.fixture(scope="module")
def records():
    """Per seed: the noisy FRF, the noise-free one, and the bench's exact sampled response."""
    out = []
    for seed in SEEDS:
        frf = calibrate.welch(bench.simulate("frf-noise", 1, seed, duration=20.0))
        ideal = calibrate.welch(bench.simulate("frf-noise", 1, seed, duration=20.0, **calibrate.IDEAL))
        band = (frf.freq_Hz >= 1.0) & (frf.freq_Hz <= 2000.0)
        truth = calibrate.sampled_response(bench.linear_model(1, seed), frf.freq_Hz[band], calibrate.frf_rate(frf))
        out.append((frf, ideal, band, truth))
    return out


def band_z(records, reference):
    """(|H_est| - |H_ref|) / std_H over the lines with coherence > 0.5 in 1-2000 Hz, per output, and
    each FRF's band factor k (the drawn band is H +- k std_H)."""
    z = {"de": [], "Vs": []}
    k = []
    for frf, ideal, band, truth in records:
        ref = ideal.H[:, band] if reference == "ideal" else truth
        k.append(frf.band_factor)
        for i, name in enumerate(["de", "Vs"]):
            h, s, c = frf.H[i][band], frf.std_H[i][band], frf.coherence[i][band]
            use = c > 0.5
            z[name].append((np.abs(h[use]) - np.abs(ref[i][use])) / s[use])
    return {n: np.concatenate(v) for n, v in z.items()}, float(np.mean(k))


@pytest.mark.parametrize("reference", ["ideal", "truth"])
def test_frf_band_covers_95_percent_and_a_variance_wrong_by_20_percent_fails(records, reference):
    z, k = band_z(records, reference)
    for name, values in z.items():
        coverage = np.mean(np.abs(values) <= k)
        assert 0.93 <= coverage <= 0.975, (name, coverage)
        # The same check with std_H 20 % too small or too large: outside the bounds.
        assert np.mean(np.abs(values) <= k * 0.8) < 0.93, name
        assert np.mean(np.abs(values) <= k * 1.2) > 0.975, name


def test_sampled_bench_equals_its_linear_models_exact_sampled_response(records):
    # The noise-free record's FRF against the hold's image sum (calibrate.sampled_response) from
    # 250 Hz to 2 kHz: 1.0-1.6e-4 rms, 1.2e-3 at most (the Welch estimate's own leakage); the first term
    # alone, H(f) sinc(f / fs), is 2-3 % off for Vs near 2 kHz.
    frf, ideal, band, truth = records[0]
    f = frf.freq_Hz[band]
    use = (f >= 250.0) & (f <= 2000.0)
    for i in range(2):
        ratio = ideal.H[i][band][use] / truth[i][use]
        assert np.sqrt(np.mean(np.abs(ratio - 1.0) ** 2)) < 3e-4, i
        assert np.max(np.abs(ratio - 1.0)) < 2e-3, i
    fs = calibrate.frf_rate(frf)
    top = (f >= 1900.0) & (f <= 2000.0)
    first = np.asarray(lti.freqresp(bench.linear_model(1, SEEDS[0]), 2 * math.pi * f[top]))[:, 1, 0] * np.sinc(f[top] / fs)
    assert np.min(np.abs(ideal.H[1][band][top] / first)) > 1.02


def test_antiresonance_intervals_against_the_noise_free_record(records):
    # z = (value - ideal) / se of the IFF plant fit's wz and xz: mean z^2 is 1 for a right standard
    # error; the bounds fail one wrong by a factor 2.
    z = {"antiresonance_Hz": [], "antiresonance_damping": []}
    for frf, ideal, _, _ in records:
        est, _ = calibrate.fitted(frf, 20.0, 500.0)
        ref, _ = calibrate.fitted(ideal, 20.0, 500.0)
        for key in z:
            value, se = est[key]
            z[key].append((value - ref[key][0]) / se)
    for key, values in z.items():
        assert 0.25 <= np.mean(np.square(values)) <= 4.0, (key, values)


def test_resonance_interval_against_the_truth(records):
    # z = (value - truth) / se of the d_e fit's natural frequency, the truth its pseudo-true value (the
    # same estimator on the bench's exact sampled response, calibrate.reference_fits). Its scatter is the
    # random input's, through the window's leakage at the peak (the noise-free record scatters as much),
    # which the leakage error's covariance (dsp/leakage_covariance.hpp) carries: mean z^2 0.61 over
    # these 8 seeds (z sd 0.99 over 200 seeds since the plant fits' second pass weighted by the model's
    # variance; 0.31 and 0.72 before, the weights following each record's coherence). The bounds fail
    # the interval of 4-5 times the scatter (mean z^2 ~0.015 here) and a standard error 2.5 times too
    # small (1.95).
    z = []
    for frf, _, band, truth in records:
        est, _ = calibrate.fitted(frf, 20.0, 500.0)
        ref = calibrate.reference_fits(frf, truth, band, 20.0, 500.0, welch_estimate=False)
        value, se = est["resonance_Hz"]
        z.append((value - ref["resonance_Hz"]) / se)
    mean_z2 = float(np.mean(np.square(z)))
    assert 0.15 <= mean_z2 <= 1.5, z


def test_tuned_parameters_intervals_against_the_noise_free_record(records):
    # z = (value - ideal) / se of the 2-DoF tuning's parameters (ratios 2), the ideal being the same
    # estimator with the same weights on the noise-free record (calibrate.tuned_reference). Mean z^2
    # is 1 for a right standard error; over these 8 seeds it is 0.31-1.61 per parameter, 0.90 pooled
    # (over 200 seeds each parameter's z has a standard deviation of 0.89-1.02; with the window's
    # leakage counted as noise, before dsp::random_frf_std, 0.56-0.61 for ka, ga, gs:
    # docs/uncertainty.md, section 6). The pooled bounds fail standard errors 2 times too large or too
    # small; no parameter is biased by the noise (the former relative error's c1: z +2.5 on average,
    # mean z^2 ~ 6.6).
    z = {n: [] for n in ["k1", "c1", "ka", "ca", "ga", "gs"]}  # ke, ce = 2 ka, 2 ca
    for frf, ideal, band, _ in records:
        est, _ = calibrate.fitted(frf, 20.0, 500.0)
        ref = calibrate.tuned_reference(frf, ideal.H[:, band], band, 20.0, 500.0, welch_estimate=True)
        for n in z:
            value, se = est["tuned_" + n]
            z[n].append((value - ref["tuned_" + n]) / se)
    per_parameter = {n: float(np.mean(np.square(v))) for n, v in z.items()}
    pooled = np.mean(list(per_parameter.values()))
    assert 0.4 <= pooled <= 2.0, per_parameter
    assert pooled * 4.0 > 2.0 and pooled / 4.0 < 0.4  # se / 2 and 2 se: outside
    assert max(per_parameter.values()) < 4.0, per_parameter
    assert all(abs(np.mean(v)) < 1.0 for v in z.values()), {n: np.mean(v) for n, v in z.items()}
