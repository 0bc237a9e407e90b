#!/usr/bin/env python3
"""Median magnitude error (dB) of a super element's response against Ansys's FEA-Response-Top.

Usage: compare_ansys_response.py RESPONSE.json FEA-Response-Top.txt
RESPONSE.json is what `piezobench superelement ... --output TOP:y --force A:B:x --json` prints
(freq_Hz, H[0] as [re, im] pairs or complex objects). Our log-spaced response is interpolated in
dB at Ansys's frequencies (1009-10000 Hz); prints the median and the 10/90 % quantiles of
|20 log10 |H_ours| - 20 log10 |H_ansys||, and the peaks of both between 1 and 10 kHz.
"""
import csv
import json
import sys

import numpy as np


def magnitude(h):
    out = []
    for v in h:
        if isinstance(v, dict):
            out.append(abs(complex(v.get("re", 0.0), v.get("im", 0.0))))
        elif isinstance(v, (list, tuple)):
            out.append(abs(complex(v[0], v[1])))
        else:
            out.append(abs(v))
    return np.array(out)


def peaks(f, a):
    return [float(f[i]) for i in range(1, len(a) - 1) if a[i] > a[i - 1] and a[i] > a[i + 1] and 1000 <= f[i] <= 10000]


def main():
    doc = json.load(open(sys.argv[1]))
    f = np.array(doc["freq_Hz"], dtype=float)
    ours = magnitude(doc["H"][0])
    with open(sys.argv[2]) as fh:
        rows = [r for r in csv.DictReader(fh)]
    fa = np.array([float(r["Freq"]) for r in rows])
    aa = np.array([float(r["Ampl"]) for r in rows])
    ours_db = np.interp(np.log10(fa), np.log10(f), 20 * np.log10(ours))
    err = np.abs(ours_db - 20 * np.log10(aa))
    print(json.dumps({
        "median_dB": float(np.median(err)),
        "p10_dB": float(np.quantile(err, 0.1)),
        "p90_dB": float(np.quantile(err, 0.9)),
        "static_ours_m_per_N": float(ours[0]),
        "peaks_ours_Hz": peaks(f, ours),
        "peaks_ansys_Hz": peaks(fa, aa),
    }, indent=1))


if __name__ == "__main__":
    main()
