#!/usr/bin/python3
"""Writes the benchmark record for `piezobench frf` vs scipy: 6,000,000 samples at 10 kHz of an
input u (white noise) and two outputs de, Vs (filtered noise), as MATLAB v5 via scipy.io.savemat.

Usage: /usr/bin/python3 bench/dsp/make_frf_record.py OUT.mat   (about 190 MB; not committed)
"""
import sys

import numpy as np
import scipy.io
import scipy.signal

n, fs = 6_000_000, 10_000.0
rng = np.random.default_rng(1)
u = rng.standard_normal(n)
b1, a1 = scipy.signal.bilinear([-16.8e-6 * (2 * np.pi * 95) ** 2], [1, 2 * 0.02 * 2 * np.pi * 95, (2 * np.pi * 95) ** 2], fs)
b2, a2 = scipy.signal.bilinear([0.6, 0, 0.6 * (2 * np.pi * 41) ** 2], [1, 2 * 0.02 * 2 * np.pi * 95, (2 * np.pi * 95) ** 2], fs)
de = scipy.signal.lfilter(b1, a1, u) + 1e-9 * rng.standard_normal(n)
vs = scipy.signal.lfilter(b2, a2, u) + 1e-3 * rng.standard_normal(n)
scipy.io.savemat(sys.argv[1], {"t": np.arange(n) / fs, "u": u, "de": de, "Vs": vs})
