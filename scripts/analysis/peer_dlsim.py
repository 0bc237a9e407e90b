#!/usr/bin/python3
"""Peer timing for bench/bench_sim.cpp: the linear part of the 2-DoF virtual bench (Table 3.1,
amplifier 5 kHz, sensor stack with R = 80.6 kOhm, C = 4.95 uF, ground resistance 0.16 Ohm,
anti-aliasing 1 kHz: the same six states as src/bench/plant.cpp) discretized by ZOH at 10 kHz and
simulated over 1,000,000 samples with scipy.signal.dlsim (state space) and scipy.signal.lfilter
(the two transfer functions u -> d_e and u -> Vs). No hysteresis, creep, noise or quantization:
the peer does less work than the C++ bench.

Usage: /usr/bin/python3 scripts/analysis/peer_dlsim.py [samples]
"""
import os
import sys
import time

import numpy as np
import scipy
import scipy.signal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_linear_model import linear_bench  # noqa: E402

A, B, rows = linear_bench()
C = np.vstack([rows["de"], rows["Vs"]])
D = np.zeros((2, 1))

n = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
fs = 10e3
ad, bd, cd, dd, _ = scipy.signal.cont2discrete((A, B, C, D), 1 / fs, method="zoh")
rng = np.random.default_rng(1)
u = 0.1 * rng.standard_normal(n)
t = np.arange(n) / fs

best = np.inf
for _ in range(3):
    t0 = time.perf_counter()
    _, y, _ = scipy.signal.dlsim((ad, bd, cd, dd, 1 / fs), u, t=t)
    best = min(best, time.perf_counter() - t0)
print(f"scipy {scipy.__version__} dlsim, 6 states, {n} samples: {best:.3f} s ({n / fs / best:.0f} x real time)")

num_de, den_de = scipy.signal.ss2tf(ad, bd, cd[0:1], dd[0:1])
num_vs, den_vs = scipy.signal.ss2tf(ad, bd, cd[1:2], dd[1:2])
best = np.inf
for _ in range(3):
    t0 = time.perf_counter()
    y1 = scipy.signal.lfilter(num_de[0], den_de, u)
    y2 = scipy.signal.lfilter(num_vs[0], den_vs, u)
    best = min(best, time.perf_counter() - t0)
print(f"scipy {scipy.__version__} lfilter, both outputs, {n} samples: {best:.3f} s ({n / fs / best:.0f} x real time)")
