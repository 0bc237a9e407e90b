#!/usr/bin/python3
"""Peer of `piezobench simulate frf-noise --duration D --out FILE` (docs/performance.md): what a
competent scipy user writes for the same record, timed as a whole process (interpreter start and
imports included, as piezobench's start-up is).

  band-limited noise  white Gaussian noise, one rfft, the lines outside 0.1 Hz .. 2 kHz zeroed,
                      one irfft, scaled to 0.1 V rms (2 V rms at the stacks)
  model               the linear part of the bench (Table 3.1, amplifier 5 kHz, sensor stack with its
                      resistor, anti-aliasing 1 kHz; the six states of src/bench/plant.cpp),
                      discretized by ZOH at 10 kHz, as three transfer functions u -> Va, d_e, Vs run
                      by scipy.signal.lfilter (no hysteresis, creep, noise or quantization: the peer
                      does less than the C++ bench)
  file                scipy.io.savemat of t, u, Va, de, Vs and fs (MATLAB v5, uncompressed)

Usage: /usr/bin/python3 bench/python/simulate_frf_noise_scipy.py FILE [duration_s]
"""
import sys

import numpy as np
import scipy.io
import scipy.signal

out = sys.argv[1]
duration = float(sys.argv[2]) if len(sys.argv) > 2 else 100.0
fs = 10e3
n = int(round(duration * fs))

m, k1, c1, ke, ce, ka, ca, ga, gs = 5.7, 0.38e6, 5.0, 5e6, 100.0, 2.5e6, 50.0, -2.58, 0.46e6
G, wa, R, C_lcr, Ca, Rg, waa = 20.0, 2 * np.pi * 5000, 80.6e3, 4.95e-6, 9.87e-6, 0.16, 2 * np.pi * 1000
K = ke + ka * k1 / (ka + k1)
Cb = C_lcr * K / (K + gs * gs * C_lcr)
alpha = gs * Cb
kesc = ke - gs * alpha
kappa = -Rg * Ca
den = ca + ce
A = np.zeros((6, 6))
B = np.zeros((6, 1))
A[0, 0] = -wa
B[0, 0] = wa * G
A[1, 2] = 1.0
xnd = np.array([ga, kesc, ce, -(ka + kesc), alpha, 0.0]) / den
T = np.array([0.0, kesc, ce, -kesc, alpha, 0.0]) - ce * xnd
A[2, :] = -T / m
A[2, 1] -= k1 / m
A[2, 2] -= c1 / m
A[3, :] = xnd
A[4, :] = -gs * xnd
A[4, 2] += gs
A[4, 4] -= 1.0 / (R * Cb)
A[5, 4] = waa
A[5, 0] = -waa * kappa * wa
A[5, 5] = -waa
B[5, 0] = waa * kappa * wa * G
C = np.zeros((3, 6))
C[0, 0] = 1.0  # Va
C[1, 1] = 1.0  # d_e
C[2, 5] = 1.0  # Vs at the ADC
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
