#!/usr/bin/python3
"""The peer of `piezobench frf FILE --input u --output de,Vs --nfft 10000 --overlap 0.5 --detrend none`:
scipy reads the same .mat file and computes H1 = Puy / Puu and the coherence |Puy|^2 / (Puu Pyy)
for both outputs with the same periodic Hann window, 50 % overlap and no detrending, as a
competent user would write it: each spectrum once (Puu once for both outputs, Puy and Pyy once per
output; scipy.signal.coherence would recompute all three), the arrays used as loadmat returns them
(ravel of a column is a view, no copy).

Usage: /usr/bin/python3 bench/dsp/frf_scipy.py FILE.mat
"""
import sys

import numpy as np
import scipy.io
import scipy.signal

data = scipy.io.loadmat(sys.argv[1])
t = data["t"].ravel()
fs = (len(t) - 1) / (t[-1] - t[0])
u = data["u"].ravel()
kw = dict(fs=fs, window="hann", nperseg=10000, noverlap=5000, detrend=False)
_, puu = scipy.signal.welch(u, **kw)
for name in ("de", "Vs"):
    y = data[name].ravel()
    _, puy = scipy.signal.csd(u, y, **kw)
    _, pyy = scipy.signal.welch(y, **kw)
    h1 = puy / puu
    coh = np.abs(puy) ** 2 / (puu * pyy)
    print(name, abs(h1[10]), coh[10])
