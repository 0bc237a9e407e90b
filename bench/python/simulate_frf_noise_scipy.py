#!/usr/bin/python3
"""Peer of `piezobench simulate frf-noise --duration D --out FILE` (docs/performance.md): what a
competent scipy user writes for the same record, timed as a whole process (interpreter start and
imports included, as piezobench's start-up is).

  band-limited noise  white Gaussian noise, one rfft, the lines outside 0.1 Hz .. 2 kHz zeroed,
                      one irfft, scaled to 0.1 V rms (2 V rms at the stacks)
  model               the linear part of the bench (Table 3.1, amplifier 5 kHz, sensor stack with its
                      resistor, anti-aliasing 1 kHz: scripts/analysis/bench_linear_model.py),
                      discretized by ZOH at 10 kHz, as three transfer functions u -> Va, d_e, Vs run
                      by scipy.signal.lfilter (no hysteresis, creep, noise or quantization: the peer
                      does less than the C++ bench)
  file                scipy.io.savemat of t, u, Va, de, Vs and fs (MATLAB v5, uncompressed)

Usage: /usr/bin/python3 bench/python/simulate_frf_noise_scipy.py FILE [duration_s]
"""
import os
import sys

import numpy as np
import scipy.io
import scipy.signal

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "analysis"))
from bench_linear_model import linear_bench  # noqa: E402

out = sys.argv[1]
duration = float(sys.argv[2]) if len(sys.argv) > 2 else 100.0
fs = 10e3
n = int(round(duration * fs))

A, B, rows = linear_bench()
C = np.vstack([rows["Va"], rows["de"], rows["Vs"]])
ad, bd, cd, dd, _ = scipy.signal.cont2discrete((A, B, C, np.zeros((3, 1))), 1 / fs, method="zoh")

rng = np.random.default_rng(1)
spectrum = np.fft.rfft(rng.standard_normal(n))
f = np.fft.rfftfreq(n, 1 / fs)
spectrum[(f < max(0.1, fs / n)) | (f > 2000.0)] = 0.0
u = np.fft.irfft(spectrum, n)
u *= 0.1 / np.sqrt(np.mean(u * u))

channels = {}
for name, row in (("Va", 0), ("de", 1), ("Vs", 2)):
    b, a = scipy.signal.ss2tf(ad, bd, cd[row : row + 1], dd[row : row + 1])
    channels[name] = scipy.signal.lfilter(b[0], a, u)
t = np.arange(n) / fs
scipy.io.savemat(out, {"t": t[:, None], "u": u[:, None], **{k: v[:, None] for k, v in channels.items()}, "fs": fs})
