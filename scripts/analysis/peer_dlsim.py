#!/usr/bin/python3
"""Peer timing for bench/bench_sim.cpp: the linear part of the 2-DoF virtual bench (Table 3.1,
amplifier 5 kHz, sensor stack with R = 80.6 kOhm, C = 4.95 uF, ground resistance 0.16 Ohm,
anti-aliasing 1 kHz: the same six states as src/bench/plant.cpp) discretized by ZOH at 10 kHz and
simulated over 1,000,000 samples with scipy.signal.dlsim (state space) and scipy.signal.lfilter
(the two transfer functions u -> d_e and u -> Vs). No hysteresis, creep, noise or quantization:
the peer does less work than the C++ bench.

dlsim is called without `t=`: given a time vector, dlsim rebuilds its own time grid from t[-1] / dt
(999,999 samples for 1,000,000, from the rounding of t[-1] / dt) and resamples u onto it with
interp1d, which both costs time and changes the input. Without it, u[k] is held over sample k
exactly as the model's ZOH discretization assumes. The script checks its two peers against a
plain state-space recursion x[k+1] = Ad x[k] + Bd u[k], y[k] = Cd x[k] + Dd u[k] on the first
20,000 samples and prints the largest relative differences: dlsim gives the recursion's numbers
exactly; lfilter on the transfer functions from ss2tf differs by about 1e-6 (the polynomial form of
six poles near z = 1 loses digits); dlsim with `t=` differed by 4e-3 and lost the last sample.

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
    _, y, _ = scipy.signal.dlsim((ad, bd, cd, dd, 1 / fs), u)
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

# The check: a plain recursion of the same discrete model on the first samples.
m_check = min(n, 20_000)
x = np.zeros(6)
ref = np.empty((m_check, 2))
for k in range(m_check):
    ref[k] = cd @ x + dd[:, 0] * u[k]
    x = ad @ x + bd[:, 0] * u[k]
scale = np.max(np.abs(ref), axis=0)
err_dlsim = np.max(np.abs(y[:m_check] - ref) / scale)
err_lfilter = max(np.max(np.abs(y1[:m_check] - ref[:, 0])) / scale[0], np.max(np.abs(y2[:m_check] - ref[:, 1])) / scale[1])
_, y_t, _ = scipy.signal.dlsim((ad, bd, cd, dd, 1 / fs), u, t=t)
m_t = min(m_check, len(y_t))
err_t = np.max(np.abs(y_t[:m_t] - ref[:m_t]) / scale)
print(f"check against x[k+1] = Ad x[k] + Bd u[k] ({m_check} samples, relative to the largest output): "
      f"dlsim {err_dlsim:.1e}, lfilter {err_lfilter:.1e}; dlsim with t= (the old call): {len(y_t)} samples "
      f"for {n}, difference {err_t:.1e}")
