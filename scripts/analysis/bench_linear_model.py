"""The linear part of the 2-DoF virtual bench, for the scipy peers of the benchmarks
(scripts/analysis/peer_dlsim.py, bench/python/simulate_frf_noise_scipy.py): Table 3.1, amplifier
5 kHz, sensor stack with R = 80.6 kOhm, C = 4.95 uF, ground resistance 0.16 Ohm, anti-aliasing
1 kHz; the same six states as src/bench/plant.cpp (Va, x, v, xn, V, y = Vs at the ADC), input u
(V at the DAC). No hysteresis, creep, noise or quantization.
"""
import numpy as np


def linear_bench():
    """Continuous A (6 x 6), B (6 x 1) and the output rows {"Va", "de", "Vs"} (each 1 x 6)."""
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
    rows = {name: np.zeros((1, 6)) for name in ("Va", "de", "Vs")}
    rows["Va"][0, 0] = 1.0
    rows["de"][0, 1] = 1.0
    rows["Vs"][0, 5] = 1.0
    return A, B, rows
