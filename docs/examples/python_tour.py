#!/usr/bin/env python3
"""The report's analysis from arrays, in Python (docs/python.md walks through it; CI runs it).

1. a record of the virtual bench (or your own arrays): u, d_e, Vs sampled at fs;
2. the FRFs u -> d_e and u -> Vs with their coherence (Welch H1);
3. the non-minimum-phase check of the anti-resonance of u -> Vs;
4. the IFF design: the report's plant model (eq. 2.3) fitted to the FRF with its delay, the root
   locus with the report's controller, the gain of maximum damping;
5. the 2-DoF model tuned to both FRFs, the measurement chain (delay, high-pass) found by the plant
   fits and removed, as `piezobench run` and `model tune` do.
Each step checks its numbers against the virtual bench's truth and exits non-zero when one is off.
"""

import sys

import numpy as np

import piezobench as pb
from piezobench import apa, bench, control, dsp, ident

UNIT, SEED = 1, 7

# 1. Arrays: here from the virtual bench, 20 s of noise at 10 kHz (any numpy arrays will do).
record = bench.simulate("frf-noise", unit=UNIT, seed=SEED)
fs = record.sample_rate
u, de, vs = record["u"], record["de"], record["Vs"]
truth = bench.truth(UNIT, SEED)
print(f"record: {u.size} samples at {fs:g} Hz")

# 2. FRFs: H1 and coherence of both outputs in one pass (0.25 Hz resolution).
est = dsp.frf(u, [de, vs], fs, outputs=["de", "Vs"], nfft=40_000, overlap=0.5, window="hann-periodic")
f = est.freq_Hz
band = (f >= 2.0) & (f <= 400.0)
peak_Hz = f[band][np.argmax(np.abs(est.H[0][band]))]
print(f"FRF: resonance peak at {peak_Hz:.2f} Hz (truth {truth.resonance_Hz:.2f} Hz), "
      f"median coherence {np.median(est.coherence[:, band]):.3f}")

# 3. NMP check of u -> Vs: the zero fitted by vector fitting (20-500 Hz, the campaign's band) and
#    the phase of the data across it (a mirrored zero pair lowers the phase by 180 deg).
fit_band = (f >= 20.0) & (f <= 500.0)
w = 2 * np.pi * f[fit_band]
features = ident.frf_features(w, est.H[1][fit_band], fit={"order": 8, "fail_if_not_converged": False})
anti = min(features.antiresonances, key=lambda a: abs(a.frequency_Hz - truth.antiresonance_Hz))
print(f"anti-resonance {anti.frequency_Hz:.2f} Hz (truth {truth.antiresonance_Hz:.2f} Hz): fitted zero "
      f"{'in the RHP' if anti.nonminimum_phase_model else 'in the LHP'}, phase change {anti.phase_change_deg:.0f} deg "
      f"-> {anti.phase_verdict}")

# 4. IFF design with the report's plant model (eq. 2.3): g0, wz, xz, wp, xp, the high-pass corner and
#    the delay fitted to u -> Vs (the report tuned them by hand); then the root locus with the
#    report's controller (eq. 2.4) and the gain of maximum damping. xz < 0 is a non-minimum-phase zero.
plant_fit = ident.fit_iff_plant(est.frf, "Vs", fmax_Hz=500.0, min_coherence=0.5)
print(f"IFF plant fit ({plant_fit.quality.verdict}): wp {plant_fit.wp_Hz:.2f} Hz, xp {plant_fit.xp:.4f}; "
      f"wz {plant_fit.wz_Hz:.2f} Hz, xz {plant_fit.xz:.4f}; high-pass {plant_fit.w_hpf_Hz:.2f} Hz; "
      f"delay {plant_fit.delay * 1e6:.0f} us; relative rms error {plant_fit.relative_rms_error:.3f}")
locus = control.iff_root_locus(control.iff_plant(**plant_fit.params()), control.iff_controller())
print(f"IFF: optimal gain {locus.optimum.gain:.3g} -> damping {locus.optimum.damping:.3f}")

# 5. The 2-DoF model tuned to both FRFs: the plant fits give the delay of d_e and the high-pass of
#    Vs, which are removed before the report's procedure and the refinement (only the mass is known).
plants = ident.fit_actuator_plants(est.frf)
tuning = apa.tune_two_dof_measured(est.frf, plants.de, plants.vs, mass=5.7, fmin_Hz=20.0, fmax_Hz=400.0,
                                   min_coherence=0.5)
print(f"2-DoF tuning ({tuning.quality.summary}): {tuning.brief_report}")
for name in ("k1", "ke", "ka", "ga", "gs"):
    print(f"  {name} = {tuning.params[name]:.4g}   (truth {truth.model_2dof[name]:.4g})")

checks = [
    ("resonance within 1 %", abs(peak_Hz / truth.resonance_Hz - 1) < 0.01),
    ("anti-resonance within 2 %", abs(anti.frequency_Hz / truth.antiresonance_Hz - 1) < 0.02),
    ("NMP verdict as the truth", (anti.phase_verdict == "non-minimum-phase") == bool(truth.zero_is_nonminimum_phase)),
    ("fitted plant: anti-resonance within 2 %", abs(plant_fit.wz_Hz / truth.antiresonance_Hz - 1) < 0.02),
    ("fitted plant: zero pair as the truth", plant_fit.zero_is_nonminimum_phase == bool(truth.zero_is_nonminimum_phase)),
    ("fitted plant: good", plant_fit.quality.verdict == "good"),
    ("IFF damps the resonance above 10 %", locus.optimum.damping > 0.10),
    # Issue 30: the dampings' standard errors exceed 5 % on this record, so they are reported
    # undetermined and the verdict is poor; the stiffnesses and gains are determined.
    ("tuning: stiffnesses and gains determined",
     not set(tuning.undetermined) & {"k1", "ke", "ka", "ga", "gs"} and not tuning.quality.impossible),
    ("tuned k1 within 5 %", abs(tuning.params["k1"] / truth.model_2dof["k1"] - 1) < 0.05),
]
failed = [name for name, ok in checks if not ok]
for name, ok in checks:
    print(f"{'ok  ' if ok else 'FAIL'} {name}")
sys.exit(1 if failed else 0)
