#!/usr/bin/python3
# Peer for the controller step: the same IFF controller (eq. 2.4, Tustin pre-warped at 95.2 Hz,
# second-order sections) in scipy: sosfilt over 1e6 samples (batch, per-sample cost) and sosfilt
# called once per sample with its state (what a Python real-time loop would do).
import time, numpy as np, scipy, scipy.signal as sg
fs = 1e4; w = 2*np.pi*95.2; c = w/np.tan(w/(2*fs))
z = [0.0]; p = [-2*np.pi*2, -2*np.pi*20, -2*np.pi*2000]; k = -10*2.8e5
zd, pd, kd = sg.bilinear_zpk(z, p, k, c/2)
sos = sg.zpk2sos(zd, pd, kd)
u = 0.3*np.sin(0.0597*np.arange(1_000_000))
best = 1e9
for _ in range(5):
    t = time.perf_counter(); y = sg.sosfilt(sos, u); best = min(best, time.perf_counter()-t)
print(f"scipy {scipy.__version__} sosfilt batch: {best/len(u)*1e9:.1f} ns per sample")
zi = np.zeros((sos.shape[0], 2)); n = 20000
t = time.perf_counter()
for i in range(n):
    yi, zi = sg.sosfilt(sos, u[i:i+1], zi=zi)
dt = (time.perf_counter()-t)/n
print(f"scipy sosfilt one sample per call: {dt*1e6:.2f} us per sample")
print("check y[1000] =", y[1000])  # piezobench: DiscreteIff({}, {}, 2.8e5) gives -0.103893538154
