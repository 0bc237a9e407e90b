#!/usr/bin/python3
"""Independent check of `piezobench simulate` (issue 5, "How it is checked").

Runs the piezobench binary given on the command line to make measurement files in a temporary
folder, reads them with scipy.io.loadmat and analyses them with numpy/scipy.signal only (none of
piezobench's own analysis code), then compares what it finds with the report:

  frf-noise   resonance ~95 Hz, anti-resonance ~41 Hz, static gain ~-17 um/V, and the
              anti-resonance of u -> Vs non-minimum phase (and minimum phase with --no-nmp-zero);
  hysteresis  loops widen relative to their stroke from 20 V to 80 V;
  stiffness   k1, k2 within 1.5..2.2 N/um, creep visible between the readings (k1 < k2);
  stroke      about 250 um for a good unit, clearly less for unit 3.

The NMP test: the ratio R = Vs / d_e of the two FRFs cancels the poles and the delay, and a complex
polynomial fitted to it around 41 Hz has a root where u -> Vs has its zero. A zero in the right
half plane is non-minimum phase: the phase of u -> Vs drops by 180 degrees across it instead of
rising. The same check on a file made with --no-nmp-zero must find the zero in the left half plane.

Usage: check_simulate.py PIEZOBENCH_BINARY [--keep DIR]. Exit 0 when every check passes.
"""
import os
import subprocess
import sys
import tempfile

import numpy as np
import scipy.io
import scipy.signal

failures = []


def check(name, ok, detail):
    print(("PASS " if ok else "FAIL ") + name + ": " + detail)
    if not ok:
        failures.append(name)


def simulate(binary, folder, name, *args):
    path = os.path.join(folder, name + ".mat")
    subprocess.run([binary, "simulate", *args, "--out", path], check=True, stdout=subprocess.DEVNULL)
    m = scipy.io.loadmat(path, squeeze_me=True)
    return m


def frf(u, y, fs, nfft):
    f, puu = scipy.signal.welch(u, fs=fs, window="hann", nperseg=nfft, noverlap=nfft // 2)
    _, puy = scipy.signal.csd(u, y, fs=fs, window="hann", nperseg=nfft, noverlap=nfft // 2)
    return f, puy / puu  # H1 (scipy's csd is conj(U) Y: y relative to u)


def zero_pair(m):
    """Zero of u -> Vs near the anti-resonance, from the ratio R = Vs / d_e (see the docstring).

    R is analytic near the zero, and a factor that does not vanish there (the read-out's high-pass,
    the sensor stack's damping, the amplifier) multiplies R without moving its zero. So a complex
    polynomial fitted to R on 34..48 Hz, in the centred variable x = (s - j w0) / W, has a root where
    R vanishes: the zero, whose real part says on which side of the imaginary axis it lies.
    """
    fs = float(m["fs"])
    nfft = int(4 * fs)  # 0.25 Hz
    f, pdd = scipy.signal.welch(m["de"], fs=fs, window="hann", nperseg=nfft, noverlap=nfft // 2)
    _, pdv = scipy.signal.csd(m["de"], m["Vs"], fs=fs, window="hann", nperseg=nfft, noverlap=nfft // 2)
    band = (f >= 34.0) & (f <= 48.0)
    w0, width = 2 * np.pi * 41.0, 2 * np.pi * 7.0
    x = (2j * np.pi * f[band] - 1j * w0) / width
    r = pdv[band] / pdd[band]
    coef, *_ = np.linalg.lstsq(np.column_stack([x**k for k in range(4)]), r, rcond=None)
    roots = 1j * w0 + width * np.roots(coef[::-1])
    z = roots[np.argmin(np.abs(roots - 1j * w0))]
    return abs(z) / (2 * np.pi), -z.real / abs(z)


def loop_ratio(m, offset=65.0):
    """Loop width at the offset (d_e going up minus going down) over the loop's stroke, last period."""
    fs = float(m["fs"])
    va, de = m["Va"], m["de"]
    n = len(va)
    start, end = n - int(2 * fs), n - int(fs)  # the last period before the ramp back to 0 V
    up = down = None
    for k in range(start + 1, end):
        if (va[k - 1] - offset) * (va[k] - offset) <= 0.0:
            if va[k] > va[k - 1]:
                up = de[k]
            else:
                down = de[k]
    seg = de[start:end]
    return abs(up - down) / (seg.max() - seg.min())


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    binary = sys.argv[1]
    keep = sys.argv[sys.argv.index("--keep") + 1] if "--keep" in sys.argv else None
    with tempfile.TemporaryDirectory() as tmp:
        folder = keep or tmp
        os.makedirs(folder, exist_ok=True)

        # --- FRFs from band-limited noise ---
        m = simulate(binary, folder, "frf-noise", "frf-noise", "--unit", "1", "--seed", "1", "--duration", "60")
        fs = float(m["fs"])
        f, hde = frf(m["u"], m["de"], fs, int(fs))  # 1 Hz
        _, hvs = frf(m["u"], m["Vs"], fs, int(fs))
        band = (f > 50) & (f < 200)
        f_res = f[band][np.argmax(np.abs(hde[band]))]
        check("resonance", abs(f_res - 95.0) < 5.0, f"peak of |u -> de| at {f_res:.1f} Hz (report: 95 Hz)")
        band = (f > 20) & (f < 80)
        f_anti = f[band][np.argmin(np.abs(hvs[band]))]
        check("anti-resonance", abs(f_anti - 41.0) < 3.0, f"dip of |u -> Vs| at {f_anti:.1f} Hz (report: 41 Hz)")
        band = (f >= 2) & (f <= 10)
        gain = np.mean(hde[band].real) * 1e6
        check("static gain", abs(gain + 17.0) < 2.0, f"{gain:.2f} um/V on 2..10 Hz (report: about -17 um/V)")
        fz, zeta = zero_pair(m)
        check("NMP zero", zeta < 0.0 and abs(fz - 41.0) < 3.0,
              f"zero pair of u -> Vs at {fz:.2f} Hz, damping {zeta:.4f} (negative: non-minimum phase)")
        m = simulate(binary, folder, "frf-noise-mp", "frf-noise", "--unit", "1", "--seed", "1", "--duration", "60",
                     "--no-nmp-zero")
        fz, zeta = zero_pair(m)
        check("MP zero with --no-nmp-zero", zeta > 0.0,
              f"zero pair at {fz:.2f} Hz, damping {zeta:.4f} (positive: the check can tell the two apart)")

        # --- hysteresis ---
        r20 = loop_ratio(simulate(binary, folder, "hyst20", "hysteresis", "--amplitude", "20"))
        r80 = loop_ratio(simulate(binary, folder, "hyst80", "hysteresis", "--amplitude", "80"))
        check("hysteresis grows", r80 > 1.5 * r20 and r20 > 0.01,
              f"loop width / stroke {100 * r20:.1f} % at 20 V, {100 * r80:.1f} % at 80 V")

        # --- static stiffness ---
        m = simulate(binary, folder, "stiffness", "stiffness", "--unit", "2")
        fs = float(m["fs"])
        de = m["de"]
        settings = m["settings"]
        mass = float(settings["added_mass_kg"])
        g = float(settings["gravity_m_per_s2"])
        mean = lambda t0, t1: de[int(t0 * fs):int(t1 * fs)].mean()
        before, early, loaded, after = mean(2.0, 2.9), mean(5.0, 5.9), mean(12.0, 12.9), mean(14.0, 15.0)
        k1 = mass * g / (before - loaded) * 1e-6
        k2 = mass * g / (after - loaded) * 1e-6
        check("stiffness", 1.5 < k1 < 2.2 and 1.5 < k2 < 2.2, f"k1 = {k1:.3f} N/um, k2 = {k2:.3f} N/um (report 1.68..1.98)")
        check("creep between the readings", k1 < k2 and (early - loaded) > 0.5e-6,
              f"k1 < k2; d_e kept sinking by {1e6 * (early - loaded):.2f} um between 5 s and 12 s under the load")

        # --- stroke ---
        strokes = {}
        for unit in ("1", "3"):
            m = simulate(binary, folder, "stroke" + unit, "stroke", "--unit", unit)
            strokes[unit] = (m["de"].max() - m["de"].min()) * 1e6
        check("stroke", 200.0 < strokes["1"] < 300.0, f"unit 1: {strokes['1']:.1f} um (report: about 250 um)")
        check("unit 3 stroke", strokes["3"] < 0.75 * strokes["1"], f"unit 3: {strokes['3']:.1f} um (clearly off)")
    print("all checks passed" if not failures else f"{len(failures)} check(s) failed: {', '.join(failures)}")
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
