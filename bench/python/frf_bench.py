#!/usr/bin/env python3
"""H1 and coherence of 6,000,000 samples: piezobench.dsp against scipy.signal in the same process.

Usage (from the repository root, after the build):
    PYTHONPATH=build/python /usr/bin/python3 bench/python/frf_bench.py [--samples 6000000] [--repeat 5]

Both compute H1 = Suy/Suu and the coherence |Suy|^2/(Suu Syy) of one output, nfft 10,000, 50 %
overlap, periodic Hann, no detrending, on the same numpy arrays (the record of bench/dsp: band-
limited noise through a lightly damped mode). scipy needs csd(u, y), welch(u) and welch(y);
piezobench.dsp.frf gives both from one pass. Prints the medians and minimums of the wall times
(time.perf_counter), the speed-up, and the largest differences (which must be below 1e-12).
"""

import argparse
import platform
import statistics
import time

import numpy as np
import scipy
import scipy.signal as ss

import piezobench as pb
from piezobench import dsp


def record(n, fs, seed=1):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    b, a = ss.butter(2, [90.0, 100.0], btype="bandpass", fs=fs)
    y = ss.lfilter(b, a, u) + 1e-3 * rng.standard_normal(n)
    return u, y


def timed(f, repeat):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return out, times


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=6_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    fs, nfft = 10e3, 10_000
    u, y = record(args.samples, fs)

    def with_scipy():
        kw = dict(fs=fs, window="hann", nperseg=nfft, noverlap=nfft // 2, detrend=False)
        _, suy = ss.csd(u, y, **kw)
        _, suu = ss.welch(u, **kw)
        _, syy = ss.welch(y, **kw)
        return suy / suu, np.abs(suy) ** 2 / (suu * syy)

    def with_piezobench(threads):
        e = dsp.frf(u, y, fs, nfft=nfft, overlap=0.5, window="hann-periodic", detrend="none", threads=threads)
        return e.H, e.coherence

    results = {}
    for name, f in (("scipy csd+welch", with_scipy), ("piezobench.dsp.frf, 1 thread", lambda: with_piezobench(1)),
                    ("piezobench.dsp.frf, all cores", lambda: with_piezobench(0))):
        results[name] = timed(f, args.repeat)

    (h_ref, c_ref), t_ref = results["scipy csd+welch"]
    print(f"{args.samples} samples, nfft {nfft}, 50 % overlap; Python {platform.python_version()}, numpy "
          f"{np.__version__}, scipy {scipy.__version__}, piezobench {pb.__version__}; {args.repeat} runs each")
    for name, ((h, c), times) in results.items():
        dh = np.max(np.abs(h - h_ref) / np.abs(h_ref))
        dc = np.max(np.abs(c - c_ref))
        speed = statistics.median(t_ref) / statistics.median(times)
        print(f"{name:32s} median {statistics.median(times) * 1e3:8.1f} ms  min {min(times) * 1e3:8.1f} ms  "
              f"x{speed:5.1f}  max rel |dH1| {dh:.1e}  max |dcoh| {dc:.1e}")
        assert dh < 1e-12 and dc < 1e-12, name


if __name__ == "__main__":
    main()
