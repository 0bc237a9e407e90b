#!/usr/bin/env python3
"""The campaign's vector-fit cross-checks against the virtual bench: their standard errors over noise seeds.

Per seed, the frf-noise record of a unit (20 s, as scripts/uncertainty/calibrate.py) and the same
record without noise or quantization (the ideal, calibrate.IDEAL); on each, the campaign's order-6
vector fits (ident.frf_features over 20-500 Hz) of u -> d_e and u -> Vs; then the standard errors of
the noisy record's (ident.vector_fit_uncertainty of the band with its std_H and its Welch provenance,
as ident/actuator_frf.cpp does) of the model's DC gain (u -> d_e) and of the zero nearest the bench's
anti-resonance (u -> Vs). It prints, for each, the z-scores (estimate - reference) / se against the
ideal (the random error) and against the bench's own values (bench.truth: the random error plus the
order-6 model's bias), and the median chi2 per degree of freedom of the fits (their misfit, which
core::fit_covariance's local widening adds to the intervals). docs/uncertainty.md section 5 quotes it:

    PYTHONPATH=build/python nice -n 5 python3 scripts/uncertainty/vector_fit_calibration.py --seeds 100
"""

import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import calibrate  # noqa: E402  (its Welch settings and its ideal bench)
from piezobench import bench, dsp, ident  # noqa: E402

OPTIONS = dict(order=6, fail_if_not_converged=False)  # ActuatorFrfOptions::fit_order, as the campaign
BAND_HZ = (20.0, 500.0)  # ActuatorFrfOptions fmin_Hz, fmax_Hz
Z95 = calibrate.Z95


def band(frf, output):
    f = frf.freq_Hz
    use = (f >= BAND_HZ[0]) & (f <= BAND_HZ[1])
    return dsp.Frf(f[use], frf.H[output][use], std_H=frf.std_H[output][use], provenance=frf.provenance)


def features(b):
    return ident.frf_features(2 * math.pi * b.freq_Hz, np.atleast_2d(b.H)[0], fit=OPTIONS)


def nearest_zero(f, w):
    return min(f.antiresonances, key=lambda a: abs(math.log(a.natural_frequency / w))) if f.antiresonances else None


def dc_gain(fit):
    return fit.evaluate(np.array([0.0]))[0, 0].real


def one_seed(seed, unit, duration):
    noisy = calibrate.welch(bench.simulate("frf-noise", unit, seed, duration=duration))
    ideal = calibrate.welch(bench.simulate("frf-noise", unit, seed, duration=duration, **calibrate.IDEAL))
    t = bench.truth(unit, seed)
    de, vs = band(noisy, 0), band(noisy, 1)
    fde, fvs, ide, ivs = features(de), features(vs), features(band(ideal, 0)), features(band(ideal, 1))
    ude = ident.vector_fit_uncertainty(de, fde.fit, **OPTIONS)
    uvs = ident.vector_fit_uncertainty(vs, fvs.fit, **OPTIONS)
    out = {"chi2": [ude.covariance.chi2_per_dof, uvs.covariance.chi2_per_dof]}
    g, g_se = dc_gain(fde.fit), math.sqrt(ident.response_covariance(fde.fit, ude, 0, 0.0)[0, 0])
    out["dc gain u -> d_e"] = [g, g_se, dc_gain(ide.fit), t.dc_gain_um_per_V * 1e-6]
    w_true = 2 * math.pi * t.antiresonance_Hz
    z, zi = nearest_zero(fvs, w_true), nearest_zero(ivs, w_true)
    if z is not None and zi is not None:
        zu = ident.zero_uncertainty(fvs.fit, uvs, 0, [z.root])[0]
        out["anti-resonance [Hz]"] = [zu.natural_frequency, zu.natural_frequency_se, zi.natural_frequency, w_true]
        out["anti-resonance damping"] = [abs(zu.damping), zu.damping_se, zi.damping, abs(t.antiresonance_damping)]
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=100)
    p.add_argument("--unit", type=int, default=1)
    p.add_argument("--duration", type=float, default=20.0)
    a = p.parse_args()
    rows = [one_seed(s, a.unit, a.duration) for s in range(1, a.seeds + 1)]
    chi2 = np.median([r["chi2"] for r in rows], axis=0)
    print(f"{a.seeds} seeds, unit {a.unit}; median chi2 per dof of the vector fits: u -> d_e {chi2[0]:.0f}, u -> Vs {chi2[1]:.0f}")
    for key in ("dc gain u -> d_e", "anti-resonance [Hz]", "anti-resonance damping"):
        v = np.array([r[key] for r in rows if key in r], dtype=float)
        for j, ref in ((2, "ideal"), (3, "bench")):
            z = (v[:, 0] - v[:, j]) / v[:, 1]
            print(f"  {key:24s} vs the {ref:5s}: {len(z)} seeds, z mean {z.mean():+6.2f} sd {z.std(ddof=1):5.2f}, "
                  f"95 % interval covers in {100 * np.mean(np.abs(z) <= Z95):5.1f} %")


if __name__ == "__main__":
    main()
