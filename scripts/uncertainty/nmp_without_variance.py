#!/usr/bin/env python3
"""The NMP verdict of the IFF plant fit on FRFs that record no variance (docs/uncertainty.md, section 2).

The report's plant (eq. 2.3: g0 0.64, anti-resonance 42.7 Hz, resonance 95.2 Hz, xp 0.02, corner
0.4 Hz known, 400 us delay) on 0.25 Hz lines, complex Gaussian noise of a given fraction of g0 on every
line, no coherence: the verdict from xz +- 3 se (ident::kVerdictCoverage), counted wrong or
undetermined over the seeds, and how often xz's 95 % interval covers the truth.

    PYTHONPATH=build/python /usr/bin/python3 scripts/uncertainty/nmp_without_variance.py [--seeds 40]
"""
import argparse

import numpy as np

import piezobench.ident as ident


def plant(w, xz, g0=0.64, fz=42.7, fp=95.2, xp=0.02, fh=0.4, tau=400e-6):
    s = 1j * w
    wz, wp, wh = 2 * np.pi * fz, 2 * np.pi * fp, 2 * np.pi * fh
    return g0 * (1 + 2 * xz * s / wz + s * s / wz**2) / (1 + 2 * xp * s / wp + s * s / wp**2) * s / (wh + s) * np.exp(-s * tau)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=40)
    args = ap.parse_args()
    w = np.linspace(0.25, 1000.0, 4000) * 2 * np.pi
    cases = [(n, xz) for n in (0.005, 0.01, 0.02) for xz in (-0.003, 0.003)]
    cases += [(n, xz) for n in (0.001, 0.01, 0.02) for xz in (-0.0015, 0.0015, -0.006, 0.006)]
    print(f"noise  xz        wrong  undetermined  xz 95 % covers  (of {args.seeds} seeds)")
    for noise, xz in cases:
        wrong = undetermined = covered = 0
        for seed in range(args.seeds):
            rng = np.random.default_rng(seed)
            sd = noise * 0.64 / np.sqrt(2.0)
            h = plant(w, xz) + rng.normal(0.0, sd, w.size) + 1j * rng.normal(0.0, sd, w.size)
            f = ident.fit_iff_plant(w, h, None, fmin_Hz=20.0, fmax_Hz=500.0, fixed_w_hpf=2 * np.pi * 0.4)
            se = f.uncertainty.standard_error_of("xz")
            lo, hi = f.xz - 3.0 * se, f.xz + 3.0 * se
            if lo <= 0.0 <= hi:
                undetermined += 1
            elif (hi < 0.0) != (xz < 0.0):
                wrong += 1
            covered += abs(f.xz - xz) <= 1.959963984540054 * se
        print(f"{noise:<6} {xz:<+9} {wrong:>5}  {undetermined:>12}  {covered:>14}")


if __name__ == "__main__":
    main()
