#!/usr/bin/python3
"""Writes the benchmark record for `piezobench frf` vs scipy: 6,000,000 samples at 10 kHz of an
input u (white noise) and two outputs de, Vs (filtered noise), as MATLAB v5 via scipy.io.savemat,
or with --v73 as MATLAB v7.3 via h5py (HDF5 with MATLAB's 512-byte header and MATLAB_class
attributes, each channel a 6,000,000 x 1 double: what MATLAB's `save -v7.3` writes).

Usage: /usr/bin/python3 bench/dsp/make_frf_record.py OUT.mat [--v73]   (about 190 MB; not committed)
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
record = {"t": np.arange(n) / fs, "u": u, "de": de, "Vs": vs}
if "--v73" not in sys.argv[2:]:
    scipy.io.savemat(sys.argv[1], record)
    sys.exit(0)

import h5py  # noqa: E402  (python3-h5py, only for --v73)

with h5py.File(sys.argv[1], "w", userblock_size=512) as f:
    for name, x in record.items():
        # MATLAB stores an n x 1 column as an HDF5 dataset of shape (1, n) (reversed dimensions).
        d = f.create_dataset(name, data=x.reshape(1, n))
        d.attrs.create("MATLAB_class", np.bytes_("double"))
with open(sys.argv[1], "r+b") as f:
    text = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created by: bench/dsp/make_frf_record.py HDF5 schema 1.00 ."
    f.write(text.ljust(116, b" ") + b"\0" * 8 + b"\x00\x02" + b"IM")
