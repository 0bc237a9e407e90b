#!/usr/bin/env python3
"""Vector fitting: piezobench.ident.vector_fit against scikit-rf's VectorFitting in the same process.

Usage (from the repository root, after the build; scikit-rf >= 0.30 is not a dependency of the
project and is not packaged by Debian: point --skrf at a source checkout of it):
    PYTHONPATH=build/python /usr/bin/python3 bench/python/vf_bench.py --skrf /path/to/scikit-rf \
        [--order 20] [--points 2000] [--outputs 1] [--noise 0] [--iterations 5] [--repeat 21]

The data: `order` / 2 lightly damped pairs (damping 1 % to 2.8 %) log-spaced from 10 Hz to 1 kHz,
residues growing with the mode, constant term 0.1, sampled at `points` frequencies log-spaced from
3.16 Hz to 3.16 kHz (bench/ident_vf_bench.cpp's problem for the defaults); `outputs` responses
share the poles with other residues; optional complex Gaussian noise of relative rms `noise`
(seeded). --write-data FILE saves them (CSV: f_Hz, then re and im of each output) and --data FILE
reads such a file instead (bench/data/vf_20poles_2000points.csv is the default case).

Both fits use the same settings: order/2 complex starting poles at -0.01 w + j w, w log-spaced over
the band of the data (the automatic starting poles of both); exactly --iterations relaxed pole
relocations (no early stop: piezobench's tolerances and scikit-rf's max_tol are 0); a constant
term, no proportional term; then the residues for the final poles (scikit-rf without enforce_dc,
which piezobench does not do); the same row weights: scikit-rf weighs each response's relocation
rows by sqrt(||H_i||) (the square root of its weights_responses, the response's 2-norm over the
band), and piezobench is given those as weights (a constant per output column), so that with
several outputs both solve the same least-squares problems (with one output a constant weight
changes nothing). scikit-rf fits the responses of an n-port network, n^2 of them:
--outputs must be a square (1, 4, ...), and piezobench gets the same n^2 columns.

Prints per fitter the median and minimum CPU time (time.process_time) and wall time
(time.perf_counter) of --repeat calls, alternated, the ratios, the largest relative difference
between the two sets of poles and each one's largest relative error to the generating poles.
"""

import argparse
import math
import statistics
import sys
import time
import warnings

import numpy as np


def problem(order, points, outputs, noise, seed=1):
    pairs = order // 2
    poles, residues = [], []
    for i in range(pairs):
        wn = 2 * math.pi * 10.0 * 100.0 ** (i / max(pairs - 1, 1))
        zeta = 0.01 + 0.002 * i
        poles.append(complex(-zeta * wn, wn * math.sqrt(1 - zeta * zeta)))
        residues.append(complex(1.0 + i, 0.3 * i) * wn)
    poles, residues = np.array(poles), np.array(residues)
    f = 10.0 ** (0.5 + 3.0 * np.arange(points) / (points - 1))
    s = 2j * math.pi * f
    rng = np.random.default_rng(seed)
    h = np.empty((points, outputs), dtype=complex)
    for o in range(outputs):
        r = residues * complex(1.0, 0.2 * o) / (1 + o)
        h[:, o] = 0.1 + (r / (s[:, None] - poles) + np.conj(r) / (s[:, None] - np.conj(poles))).sum(axis=1)
    if noise > 0:
        h *= 1 + noise / math.sqrt(2) * (rng.standard_normal(h.shape) + 1j * rng.standard_normal(h.shape))
    return f, h, np.concatenate([poles, np.conj(poles)])


def upper_sorted(p):
    p = np.asarray(p)
    upper = p[p.imag > 0]
    return upper[np.argsort(upper.imag)]


def max_rel(a, b):
    a, b = upper_sorted(a), upper_sorted(b)
    if len(a) != len(b):
        return float("inf")
    return float(np.max(np.abs(a - b) / np.abs(b)))


def timed(fns, repeat):
    cpu = {k: [] for k in fns}
    wall = {k: [] for k in fns}
    out = {}
    for _ in range(repeat):
        for k, fn in fns.items():
            c0, w0 = time.process_time(), time.perf_counter()
            out[k] = fn()
            wall[k].append(time.perf_counter() - w0)
            cpu[k].append(time.process_time() - c0)
    return out, cpu, wall


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--skrf", help="a scikit-rf source checkout (put first on sys.path)")
    ap.add_argument("--order", type=int, default=20)
    ap.add_argument("--points", type=int, default=2000)
    ap.add_argument("--outputs", type=int, default=1)
    ap.add_argument("--noise", type=float, default=0.0)
    ap.add_argument("--iterations", type=int, default=5)
    ap.add_argument("--repeat", type=int, default=21)
    ap.add_argument("--data", help="CSV written by --write-data (replaces the generated data)")
    ap.add_argument("--write-data", help="save the data as CSV and exit")
    args = ap.parse_args()
    if args.order % 2:
        sys.exit("vf_bench: --order must be even (complex pairs only, as both fitters start)")
    ports = math.isqrt(args.outputs)
    if ports * ports != args.outputs:
        sys.exit("vf_bench: --outputs must be a square (scikit-rf fits the n^2 responses of an n-port)")

    f, h, true_poles = problem(args.order, args.points, args.outputs, args.noise)
    if args.write_data:
        cols = [f] + [c for o in range(h.shape[1]) for c in (h[:, o].real, h[:, o].imag)]
        np.savetxt(args.write_data, np.column_stack(cols), delimiter=",", fmt="%.17g",
                   header="f_Hz," + ",".join(f"re_{o},im_{o}" for o in range(h.shape[1])))
        return
    if args.data:
        raw = np.loadtxt(args.data, delimiter=",")
        f, h = raw[:, 0], raw[:, 1::2] + 1j * raw[:, 2::2]
        ports = math.isqrt(h.shape[1])

    if args.skrf:
        sys.path.insert(0, args.skrf)
    import numpy.typing  # noqa: F401  (scikit-rf uses np.typing without importing it)
    try:
        import typing_extensions  # noqa: F401
    except ImportError:  # Python >= 3.11 has what scikit-rf takes from it (Debian: no package needed)
        import typing
        sys.modules["typing_extensions"] = typing
    import skrf
    from skrf.vectorFitting import VectorFitting
    from piezobench import ident

    network = skrf.Network(frequency=skrf.Frequency.from_f(f, unit="Hz"),
                           s=h.reshape(len(f), ports, ports))
    omega = 2 * math.pi * f

    def fit_skrf():
        vf = VectorFitting(network)
        vf.max_iterations = args.iterations
        vf.max_tol = 0.0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "stopped after reaching the maximum number of iterations"
            vf.vector_fit(n_poles_real=0, n_poles_cmplx=args.order // 2, init_pole_spacing="log",
                          fit_constant=True, fit_proportional=False, enforce_dc=False)
        return vf.poles

    # scikit-rf's relocation weights (vectorFitting.py: weights_responses = ||H_i||, then sqrt).
    weights = np.ones((len(f), 1)) * np.sqrt(np.linalg.norm(h, axis=0))[None, :]

    def fit_pb():
        r = ident.vector_fit(omega, h, weights, order=args.order, asymptote="d", max_iterations=args.iterations,
                             pole_tolerance=0.0, residual_tolerance=0.0, significance_floor=0.0,
                             fail_if_not_converged=False, starting_damping=0.01, starting_spacing="log")
        return r.poles

    out, cpu, wall = timed({"piezobench": fit_pb, "scikit-rf": fit_skrf}, args.repeat)
    print(f"vector fitting: {args.order} poles, {len(f)} points, {h.shape[1]} output(s), noise {args.noise}, "
          f"{args.iterations} relocations then the residues; {args.repeat} calls each, alternated; "
          "the same starting poles, settings and row weights (scikit-rf's sqrt(||H_i||) per output)")
    print(f"scikit-rf {skrf.__version__}, numpy {np.__version__}, python {sys.version.split()[0]}")
    for k in cpu:
        print(f"  {k:11s} CPU median {1e3 * statistics.median(cpu[k]):8.3f} ms  min {1e3 * min(cpu[k]):8.3f} ms"
              f"   wall median {1e3 * statistics.median(wall[k]):8.3f} ms  min {1e3 * min(wall[k]):8.3f} ms")
    for label, d in (("CPU", cpu), ("wall", wall)):
        print(f"  scikit-rf / piezobench ({label}): median {statistics.median(d['scikit-rf']) / statistics.median(d['piezobench']):.1f}x"
              f", min {min(d['scikit-rf']) / min(d['piezobench']):.1f}x")
    print(f"  poles: largest relative difference piezobench vs scikit-rf {max_rel(out['piezobench'], out['scikit-rf']):.2e}")
    if not args.data:
        for k in out:
            print(f"  poles: largest relative error of {k} to the generating poles {max_rel(out[k], true_poles):.2e}")


if __name__ == "__main__":
    main()
