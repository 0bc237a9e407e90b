#!/usr/bin/env python3
"""Monte Carlo calibration of piezobench's uncertainties on the virtual bench (issue 30).

For each noise seed, unit `--unit` of the batch drawn from that seed runs the frf-noise experiment
(the report's FRF measurement, 20 s); then, as the campaign does:
  - the Welch FRF u -> [d_e, Vs] (4 s segments, 50 %, hann, mean removed) with its std_H
    (Bendat & Piersol with Welch's n_d, dsp/frf_variance.hpp);
  - the plant fits (ident.fit_actuator_plants, weighted by that variance) with their standard errors;
  - the 2-DoF tuning (apa.tune_two_dof_measured, ratios 2) with its standard errors.
The truth is the bench's own: its linear model u -> [d_e, Vs] (bench.linear_model), its resonance,
anti-resonance and damping ratios (bench.truth) and the unit's 2-DoF parameters.

Coverage measured (docs/uncertainty.md):
  - band: fraction of (seed, output, line) with coherence > 0.5 inside the excited band whose true
    |H| lies within |H_est| +- 1.96 std_H (the drawn 95 % band); the phase band likewise;
  - intervals: fraction of seeds whose 95 % interval (value +- 1.96 se) covers the truth, for the
    resonance (d_e fit), its damping, the anti-resonance (Vs fit), its damping |xz|, and each tuned
    2-DoF parameter.

Usage (minutes; not run in CI):
    PYTHONPATH=build/python python3 scripts/uncertainty/calibrate.py --seeds 200 [--unit 1] [--json out.json]
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


def one_seed(seed, unit=1, duration=20.0, fmin=20.0, fmax=500.0):
    """Coverage counts and interval checks of one noise seed."""
    ts = bench.simulate("frf-noise", unit, seed, duration=duration)
    fs = ts.sample_rate
    nfft = int(round(4.0 * fs))
    est = dsp.frf(ts["u"], np.vstack([ts["de"], ts["Vs"]]), fs, outputs=["de", "Vs"],
                  nfft=nfft, overlap=0.5, window="hann-periodic", detrend="mean")
    frf = est.frf
    f = frf.freq_Hz
    truth_sys = bench.linear_model(unit, seed)
    h_true = lti.freqresp(truth_sys, 2 * math.pi * f)  # (points, outputs, inputs) or similar
    h_true = np.asarray(h_true)
    if h_true.ndim == 3:
        h_true = np.stack([h_true[:, 0, 0], h_true[:, 1, 0]])
    out = {"seed": seed, "band": {}, "phase": {}, "intervals": {}}
    sel = (f >= 1.0) & (f <= 2000.0)
    for i, name in enumerate(["de", "Vs"]):
        h, s, c = frf.H[i], frf.std_H[i], frf.coherence[i]
        use = sel & (c > 0.5)
        inside = np.abs(np.abs(h[use]) - np.abs(h_true[i][use])) <= Z95 * s[use]
        dphi = np.angle(h[use] / h_true[i][use])
        inside_ph = np.abs(dphi) <= Z95 * s[use] / np.abs(h[use])
        out["band"][name] = [int(inside.sum()), int(use.sum())]
        out["phase"][name] = [int(inside_ph.sum()), int(use.sum())]
    t = bench.truth(unit, seed)
    plants = ident.fit_actuator_plants(frf, "de", "Vs", fmin_Hz=fmin, fmax_Hz=fmax)

    def check(key, value, se, true):
        if value is None or se is None or not math.isfinite(se) or true is None:
            return
        out["intervals"][key] = bool(abs(value - true) <= Z95 * se)

    if plants.de is not None:
        u = plants.de.uncertainty
        check("resonance_Hz", plants.de.natural_frequency / (2 * math.pi),
              u.standard_error_of("natural_frequency") / (2 * math.pi), t.resonance_Hz)
        check("resonance_damping", plants.de.damping, u.standard_error_of("damping"), t.resonance_damping)
    if plants.vs is not None:
        u = plants.vs.uncertainty
        check("antiresonance_Hz", plants.vs.wz / (2 * math.pi), u.standard_error_of("wz") / (2 * math.pi), t.antiresonance_Hz)
        if t.antiresonance_damping is not None:
            check("antiresonance_damping", plants.vs.xz, u.standard_error_of("xz"), t.antiresonance_damping)
        out["nmp_verdict"] = None
        lo, hi = plants.vs.xz - Z95 * u.standard_error_of("xz"), plants.vs.xz + Z95 * u.standard_error_of("xz")
        out["nmp_verdict"] = "nmp" if hi < 0 else ("mp" if lo > 0 else "undetermined")
        out["nmp_truth"] = "nmp" if t.zero_is_nonminimum_phase else "mp"
    if plants.de is not None and plants.vs is not None:
        tuned = apa.tune_two_dof_measured(frf, plants.de, plants.vs, fmin_Hz=fmin, fmax_Hz=fmax, min_coherence=0.5,
                                          amplifier_gain=20.0)
        true_params = t.model_2dof
        if tuned.uncertainty is not None and true_params is not None:
            for name in ["k1", "c1", "ke", "ce", "ka", "ca", "ga", "gs"]:
                check("tuned_" + name, tuned.params[name], tuned.uncertainty.standard_error_of(name), true_params[name])
        out["tuned_undetermined"] = list(tuned.undetermined)
    return out


def summarize(results):
    s = {"seeds": len(results), "band": {}, "phase": {}, "intervals": {}}
    for kind in ("band", "phase"):
        for name in ("de", "Vs"):
            hit = sum(r[kind][name][0] for r in results)
            n = sum(r[kind][name][1] for r in results)
            s[kind][name] = hit / n if n else float("nan")
    keys = sorted({k for r in results for k in r["intervals"]})
    for k in keys:
        v = [r["intervals"][k] for r in results if k in r["intervals"]]
        s["intervals"][k] = {"coverage": sum(v) / len(v), "seeds": len(v)}
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
    p.add_argument("--json", help="write the per-seed results and the summary here")
    a = p.parse_args()
    results = []
    start = time.time()
    for k, seed in enumerate(range(a.first_seed, a.first_seed + a.seeds)):
        results.append(one_seed(seed, a.unit, a.duration))
        print(f"\rseed {seed} ({k + 1}/{a.seeds}, {time.time() - start:.0f} s)", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    s = summarize(results)
    print(f"{s['seeds']} seeds, unit {a.unit}, pb {pb.__version__ if hasattr(pb, '__version__') else ''}")
    for kind in ("band", "phase"):
        print(f"95 % {kind} coverage (coherence > 0.5): " + ", ".join(f"{n} {100 * v:.1f} %" for n, v in s[kind].items()))
    for k, v in s["intervals"].items():
        print(f"95 % interval of {k}: covers the truth in {100 * v['coverage']:.1f} % of {v['seeds']} seeds")
    print(f"NMP verdict: {s['nmp']['wrong']} wrong, {s['nmp']['undetermined']} undetermined of {s['nmp']['seeds']}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"summary": s, "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
