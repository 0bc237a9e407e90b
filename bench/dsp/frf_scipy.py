#!/usr/bin/python3
"""The peer of `piezobench frf FILE --input u --output de,Vs --nfft 10000 --overlap 0.5`: scipy reads
the same .mat file and computes H1 = csd(u, y) / welch(u) and the coherence for both outputs with
the same periodic Hann window, 50 % overlap and no detrending.

Usage: /usr/bin/python3 bench/dsp/frf_scipy.py FILE.mat
"""
import sys

import scipy.io
import scipy.signal

data = scipy.io.loadmat(sys.argv[1])
t = data["t"].ravel()
fs = 1.0 / (t[1] - t[0])
u = data["u"].ravel()
kw = dict(fs=fs, window="hann", nperseg=10000, noverlap=5000, detrend=False)
_, suu = scipy.signal.welch(u, **kw)
for name in ("de", "Vs"):
    y = data[name].ravel()
    _, suy = scipy.signal.csd(u, y, **kw)
    _, coh = scipy.signal.coherence(u, y, **kw)
    h1 = suy / suu
    print(name, abs(h1[10]), coh[10])
