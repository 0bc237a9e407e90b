#!/usr/bin/env python3
"""Monte Carlo calibration of piezobench's uncertainties on the virtual bench (issue 30).

For each noise seed, unit `--unit` of the batch drawn from that seed runs the frf-noise experiment
(the report's FRF measurement, 20 s); then, as the campaign does:
  - the Welch FRF u -> [d_e, Vs] (4 s segments, 50 %, hann, mean removed) with its std_H
    (Bendat & Piersol with Welch's n_d, dsp/frf_variance.hpp);
  - the plant fits (ident.fit_actuator_plants, weighted by that variance) with their standard errors;
  - the 2-DoF tuning (apa.tune_two_dof_measured, ratios 2) with its standard errors.
Three references (the bench knows them all):
  - truth: for the FRF band, the bench's own linear model u -> [d_e, Vs] (bench.linear_model) as the
    sampled bench sees it (the hold's images included: sampled_response). For every fitted quantity
    (resonance, anti-resonance, damping ratios, tuned 2-DoF parameters) its pseudo-true value: the
    estimator (plant fits and tuning, with the noisy record's weights) on that exact response, each
    model's best fit to a bench it does not contain exactly (H. White, Econometrica 1982), and
    WITHOUT the Welch resolution kernel (dsp/resolution_kernel.hpp): the fits see their models
    through the window's kernel because a Welch estimate converges to H smoothed by it; the exact
    response is not smoothed (it is the H the kernel is applied to);
  - ideal: the same analysis of the same seed's record without noise or quantization (IDEAL below),
    kernel included (a Welch estimate, smoothed like the noisy one): what the estimates scatter
    around. The random error (the FRF band, the standard errors) is calibrated against it; truth -
    ideal is what the estimator gets wrong beyond the noise (the window's resolution where the kernel
    does not model it, the leakage common to the noisy and the noise-free record);
  - physical: the bench's own resonance, anti-resonance and damping ratios (bench.truth) and 2-DoF
    parameters: truth - physical is the models' structural bias (eq. 2.3's zero is not the bench's
    lowest zero pair; the 2-DoF model lacks the sensor stack's electromechanical coupling);
  - linearized (for the fitted quantities; --linearized-duration, 0 to skip): the same estimator,
    kernel included, on the noise-free bench's Welch estimate of a long record (400 s: 20 times the
    segments, so its own leakage error is a twentieth of the estimate's variance): what the estimator
    converges to on the bench as it is, hysteresis and creep included, at this excitation's amplitude
    (the bench's best linear approximation). truth - linearized is what the bench's nonlinearity does
    to the linear models' parameters: the hysteresis dissipates energy, and the resonance damping the
    FRF measures is about 0.5 % above the linear model's (docs/uncertainty.md, section 6).

Coverage measured (docs/uncertainty.md, section 6):
  - band: fraction of (seed, output, line) with coherence > 0.5 in 1-2000 Hz whose reference |H|
    lies within |H_est| +- k std_H (the drawn 95 % band, k = dsp.band_factor(n_d)); the phase band
    likewise;
  - intervals: fraction of seeds whose 95 % interval (value +- 1.96 se) covers the reference, for
    the resonance (d_e fit), its damping, the anti-resonance (Vs fit), its damping xz, and each tuned
    2-DoF parameter; with the mean and spread of z = (value - reference) / se (0 and 1 when right).

Usage (minutes; not run in CI):
    PYTHONPATH=build/python /usr/bin/python3 scripts/uncertainty/calibrate.py --seeds 200 \
        [--bench hysteresis=false creep=false] [--band-factor 1.96] [--unit 1] [--json out.json]
"""

import argparse
import json
import math
import sys
import time

import numpy as np

import piezobench as pb
from piezobench import apa, bench, dsp, ident, lti

Z95 = 1.959963984540054


# The same bench without any random error: no noise, no quantization (the DAC, the ADC and the
# encoder at a resolution far below every signal). Measured with the same excitation (same seed) and
# the same estimator, it is what the noisy estimate scatters around: the reference of the random
# error the FRF band and the standard errors describe.
IDEAL = {"noise": False, "encoder_resolution": 1e-15, "dac_bits": 30, "adc_bits": 30}


# None: each FRF's own band factor (dsp.band_factor of its n_d, as the report draws); a number: that
# factor instead (--band-factor 1.96 measures the Gaussian band the report drew before).
BAND_FACTOR = None


def welch(ts):
    fs = ts.sample_rate
    return dsp.frf(ts["u"], np.vstack([ts["de"], ts["Vs"]]), fs, outputs=["de", "Vs"],
                   nfft=int(round(4.0 * fs)), overlap=0.5, window="hann-periodic", detrend="mean").frf


def frf_rate(frf):
    """The sample rate of the record an FRF was estimated from (its provenance)."""
    return float(frf.provenance["sample_rate"])


# Images of the hold summed on each side: the terms fall as 1 / k^3 (the hold's sinc times the
# amplifier's and the anti-aliasing filter's first-order roll-offs), the tail as 1 / K^2: 100 terms
# differ from 400 by 6e-6 of |H| at most (1-2000 Hz), 60 by 1.6e-5.
ALIAS_TERMS = 100
BAND_HZ = (1.0, 2000.0)  # the lines the band's coverage counts


def sampled_response(model, freq_Hz, fs):
    """The exact response u -> [d_e, Vs] of the sampled bench at freq_Hz: the DAC holds each sample
    (zero-order hold) and the ADC samples the continuous outputs, so the discrete-time response is
    the sum over the hold's images, H_d(f) = sum_k H(f + k fs) sinc((f + k fs) / fs), H the bench's
    linear model (its input delay includes the hold's half sample, hence the real sinc). k = 0 alone
    (H(f) sinc(f / fs)) misses Vs by +0.3 % at 800 Hz, +1.4 % at 1.5 kHz and +3 % at 2 kHz: Vs's
    response is flat up to the 1 kHz anti-aliasing filter, so the hold's images near 10 kHz alias
    back (d_e falls as 1/f^2 above its resonance and its images are negligible). The noise-free
    bench's Welch estimate agrees with this sum to 2e-4 in |H| and 0.01 degree from 250 Hz to 2 kHz."""
    h = np.zeros((2, len(freq_Hz)), dtype=complex)
    for k in range(-ALIAS_TERMS, ALIAS_TERMS + 1):
        f = freq_Hz + k * fs
        r = np.asarray(lti.freqresp(model, 2 * math.pi * f))
        h += np.stack([r[:, 0, 0], r[:, 1, 0]]) * np.sinc(f / fs)
    return h


def band_counts(frf, reference):
    """(inside |H| band, inside phase band, lines) per output, lines with coherence > 0.5 in 1-2000 Hz."""
    f = frf.freq_Hz
    k = frf.band_factor if BAND_FACTOR is None else BAND_FACTOR  # the drawn band: H +- k std_H
    out = {}
    for i, name in enumerate(["de", "Vs"]):
        h, s, c = frf.H[i], frf.std_H[i], frf.coherence[i]
        use = (f >= BAND_HZ[0]) & (f <= BAND_HZ[1]) & (c > 0.5)
        mag = np.abs(np.abs(h[use]) - np.abs(reference[i][use])) <= k * s[use]
        ph = np.abs(np.angle(h[use] / reference[i][use])) <= k * s[use] / np.abs(h[use])
        out[name] = [int(mag.sum()), int(ph.sum()), int(use.sum())]
    return out


def fitted(frf, fmin, fmax, effective_averages=0.0):
    """{name: (value, standard error)} of the plant fits and the 2-DoF tuning on one FRF (n_d from its
    provenance unless given)."""
    plants = ident.fit_actuator_plants(frf, "de", "Vs", fmin_Hz=fmin, fmax_Hz=fmax, effective_averages=effective_averages)
    v = {}
    if plants.de is not None:
        u = plants.de.uncertainty
        v["resonance_Hz"] = (plants.de.natural_frequency / (2 * math.pi), u.standard_error_of("natural_frequency") / (2 * math.pi))
        v["resonance_damping"] = (plants.de.damping, u.standard_error_of("damping"))
    if plants.vs is not None:
        u = plants.vs.uncertainty
        v["antiresonance_Hz"] = (plants.vs.wz / (2 * math.pi), u.standard_error_of("wz") / (2 * math.pi))
        v["antiresonance_damping"] = (plants.vs.xz, u.standard_error_of("xz"))
    tuned_values, undetermined = tuned(frf, plants, fmin, fmax)
    v.update(tuned_values)
    return v, undetermined


TUNED = ["k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"]


def tuned(frf, plants, fmin, fmax):
    """({"tuned_NAME": (value, standard error)}, undetermined names) of the campaign's 2-DoF tuning
    (ratios 2) on one FRF, the chain removed as the plant fits found it."""
    if plants.de is None or plants.vs is None:
        return {}, []
    t = apa.tune_two_dof_measured(frf, plants.de, plants.vs, fmin_Hz=fmin, fmax_Hz=fmax, min_coherence=0.5, mass=5.7)
    if t.uncertainty is None:
        return {}, list(t.undetermined)
    return {"tuned_" + n: (t.params[n], t.uncertainty.standard_error_of(n)) for n in TUNED}, list(t.undetermined)


def tuned_reference(frf, h, band, fmin, fmax, welch_estimate):
    """The tuned parameters of the same estimator (the plant fits and the tuning, with the weights of
    the noisy record `frf`: its coherence, std_H and n_d) on the noise-free response h at the lines
    `band`: the noise-free record (what the estimates scatter around) or the bench's exact sampled
    response (the pseudo-true parameters: the 2-DoF model's best fit to the bench, which it does not
    contain exactly). The weights matter: the model misses the bench by more than the noise, so each
    weighting has its own best fit (c1 changed threefold between the noisy record's weights and the
    noise-free record's own).
    welch_estimate: True, h is a Welch estimate (the noise-free record), seen by the fits through the
    window's resolution kernel as the noisy record is (its provenance passed on); False, h is the exact
    response, which has no window smoothing, fitted without the kernel (no provenance: the fits'
    models as they are)."""
    return {k: v for k, v in reference_fits(frf, h, band, fmin, fmax, welch_estimate).items() if k.startswith("tuned_")}


def reference_fits(frf, h, band, fmin, fmax, welch_estimate):
    """{name: value} of the plant fits and the tuning (the estimator, with the noisy record's weights)
    on the noise-free response h at the lines `band` (tuned_reference). On the bench's exact response
    (welch_estimate False) these are the pseudo-true values: each model's best fit to the bench."""
    ref = dsp.Frf(frf.freq_Hz[band], h, outputs=["de", "Vs"], coherence=frf.coherence[:, band], std_H=frf.std_H[:, band],
                  provenance=frf.provenance if welch_estimate else None)
    values, _ = fitted(ref, fmin, fmax, effective_averages=frf.provenance["effective_averages"])
    return {k: value for k, (value, _) in values.items()}


def one_seed(seed, unit=1, duration=20.0, fmin=20.0, fmax=500.0, kw=None, linearized_duration=0.0):
    """Coverage counts and interval checks of one noise seed against the three references of the
    module's docstring: truth (the exact sampled response; the fits' pseudo-true values), ideal (the
    noise-free record) and physical (the bench's own parameters)."""
    kw = kw or {}
    frf = welch(bench.simulate("frf-noise", unit, seed, duration=duration, **kw))
    ideal = welch(bench.simulate("frf-noise", unit, seed, duration=duration, **{**kw, **IDEAL}))
    band = (frf.freq_Hz >= BAND_HZ[0]) & (frf.freq_Hz <= BAND_HZ[1])
    h_true = np.full((2, len(frf.freq_Hz)), np.nan + 0j)
    h_true[:, band] = sampled_response(bench.linear_model(unit, seed, **kw), frf.freq_Hz[band], frf_rate(frf))
    out = {"seed": seed, "band": {"truth": band_counts(frf, h_true), "ideal": band_counts(frf, ideal.H)},
           "intervals": {"truth": {}, "ideal": {}}}
    est, undetermined = fitted(frf, fmin, fmax)
    ref, _ = fitted(ideal, fmin, fmax)
    ref = {k: value for k, value in ref.items() if not k.startswith("tuned_")}
    t = bench.truth(unit, seed, **kw)
    # The truth of every fitted quantity is its pseudo-true value: the estimator (without the window's
    # resolution kernel, which models the Welch smoothing the exact response does not have) on the
    # bench's exact sampled response, each model's best fit to the bench. The ideal is the same
    # estimator on the noise-free record (the tuned parameters with the noisy record's weights). The
    # bench's own parameters ("physical": its resonance, anti-resonance, damping ratios and 2-DoF
    # parameters) differ by the models' structure (eq. 2.3's zero is not the bench's lowest zero pair;
    # the 2-DoF model lacks the sensor stack's electromechanical coupling, bench/plant.cpp), reported as a bias.
    ref.update({k: (v, None) for k, v in tuned_reference(frf, ideal.H[:, band], band, fmin, fmax, welch_estimate=True).items()})
    truth = reference_fits(frf, h_true[:, band], band, fmin, fmax, welch_estimate=False)
    physical = {"resonance_Hz": t.resonance_Hz, "resonance_damping": t.resonance_damping,
                "antiresonance_Hz": t.antiresonance_Hz, "antiresonance_damping": t.antiresonance_damping}
    if t.model_2dof is not None:
        physical.update({"tuned_" + n: t.model_2dof[n] for n in TUNED})
    out["intervals"]["physical"] = {}
    linearized = {}
    if linearized_duration > 0.0:
        out["intervals"]["linearized"] = {}
        long = welch(bench.simulate("frf-noise", unit, seed, duration=linearized_duration, **{**kw, **IDEAL}))
        if not np.array_equal(long.freq_Hz, frf.freq_Hz):
            raise ValueError("the long record's lines differ from the record's (the same nfft is expected)")
        linearized = reference_fits(frf, long.H[:, band], band, fmin, fmax, welch_estimate=True)
    for key, (value, se) in est.items():
        if not (se is not None and math.isfinite(se)):
            continue
        for name, reference in (("truth", truth.get(key)), ("ideal", ref.get(key, (None,))[0]), ("physical", physical.get(key)),
                                ("linearized", linearized.get(key))):
            if reference is not None:
                out["intervals"][name][key] = [value, se, reference]
    if "antiresonance_damping" in est:
        xz, se = est["antiresonance_damping"]
        out["nmp_verdict"] = "nmp" if xz + Z95 * se < 0 else ("mp" if xz - Z95 * se > 0 else "undetermined")
        out["nmp_truth"] = "nmp" if t.zero_is_nonminimum_phase else "mp"
    out["tuned_undetermined"] = undetermined
    return out


def summarize(results):
    s = {"seeds": len(results), "band": {}, "intervals": {}}
    for ref in ("truth", "ideal"):
        s["band"][ref] = {}
        for name in ("de", "Vs"):
            c = np.sum([r["band"][ref][name] for r in results], axis=0)
            s["band"][ref][name] = {"magnitude": c[0] / c[2], "phase": c[1] / c[2], "lines": int(c[2])}
    for ref in ("truth", "ideal", "physical", "linearized"):
        s["intervals"][ref] = {}
        for k in sorted({k for r in results for k in r["intervals"].get(ref, {})}):
            rows = np.array([r["intervals"][ref][k] for r in results if k in r["intervals"].get(ref, {})], dtype=float)
            z = (rows[:, 0] - rows[:, 2]) / rows[:, 1]
            s["intervals"][ref][k] = {"coverage": float(np.mean(np.abs(z) <= Z95)), "seeds": len(rows),
                                      "mean_z": float(np.mean(z)), "std_z": float(np.std(z, ddof=1)) if len(z) > 1 else float("nan"),
                                      "median_relative_bias": float(np.median(rows[:, 2] / rows[:, 0] - 1.0) * -1.0)}
    s["tuned_undetermined"] = {n: sum(1 for r in results if n in r.get("tuned_undetermined", [])) for n in TUNED}
    verdicts = [(r.get("nmp_verdict"), r.get("nmp_truth")) for r in results if r.get("nmp_verdict")]
    s["nmp"] = {"wrong": sum(1 for v, t in verdicts if v != "undetermined" and v != t),
                "undetermined": sum(1 for v, _ in verdicts if v == "undetermined"), "seeds": len(verdicts)}
    return s


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=200)
    p.add_argument("--first-seed", type=int, default=1)
    p.add_argument("--unit", type=int, default=1)
    p.add_argument("--duration", type=float, default=20.0)
    p.add_argument("--linearized-duration", type=float, default=400.0,
                   help="s of the noise-free record of the 'linearized' reference (0: none)")
    p.add_argument("--json", help="write the per-seed results and the summary here")
    p.add_argument("--band-factor", type=float, help="k of the FRF band (default: each FRF's dsp.band_factor)")
    p.add_argument("--bench", nargs="*", default=[], metavar="KEY=VALUE",
                   help="bench options (e.g. hysteresis=false creep=false)")
    a = p.parse_args()
    global BAND_FACTOR
    BAND_FACTOR = a.band_factor
    kw = {}
    for item in a.bench:
        k, v = item.split("=", 1)
        kw[k] = {"true": True, "false": False}.get(v.lower(), None)
        if kw[k] is None:
            kw[k] = float(v) if any(c in v for c in ".e") else int(v)
    results = []
    start = time.time()
    for k, seed in enumerate(range(a.first_seed, a.first_seed + a.seeds)):
        results.append(one_seed(seed, a.unit, a.duration, kw=kw, linearized_duration=a.linearized_duration))
        print(f"\rseed {seed} ({k + 1}/{a.seeds}, {time.time() - start:.0f} s)", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    s = summarize(results)
    print(f"{s['seeds']} seeds, unit {a.unit}, bench {kw or 'default'}")
    what = {"truth": " (the band: the bench's exact sampled response; the fits: each model's best fit to it, without the window's kernel)",
            "ideal": " (the same analysis of the noise- and quantization-free record)",
            "physical": " (the bench's own resonance, anti-resonance, dampings and 2-DoF parameters: the models' structural bias)",
            "linearized": f" (the estimator on the noise-free bench's {a.linearized_duration:g} s record: its limit on the bench as it is, nonlinearity included)"}
    for ref in ("truth", "ideal", "physical", "linearized"):
        if not s["intervals"].get(ref) and ref not in s["band"]:
            continue
        print(f"-- against the {ref}" + what[ref])
        if ref in s["band"]:
            print("95 % FRF band (coherence > 0.5, 1-2000 Hz): " + ", ".join(
                f"{n} |H| {100 * v['magnitude']:.1f} % phase {100 * v['phase']:.1f} % of {v['lines']} lines" for n, v in s["band"][ref].items()))
        for k, v in s["intervals"][ref].items():
            print(f"  {k:24s} 95 % interval covers in {100 * v['coverage']:5.1f} % of {v['seeds']} seeds;"
                  f" z mean {v['mean_z']:+6.2f} std {v['std_z']:5.2f}; median bias {100 * v['median_relative_bias']:+.2f} %")
    print("tuned parameters undetermined: " + ", ".join(f"{n} {c}" for n, c in s["tuned_undetermined"].items()) + f" of {s['seeds']} seeds")
    print(f"NMP verdict: {s['nmp']['wrong']} wrong, {s['nmp']['undetermined']} undetermined of {s['nmp']['seeds']}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"summary": s, "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
