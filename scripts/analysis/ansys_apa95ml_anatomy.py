#!/usr/bin/env python3
"""What the Ansys APA95ML super element is made of, read from its reduced K and M (issue 31).

Usage: ansys_apa95ml_anatomy.py DIR      (DIR: the apa95ml-ansys data folder: piezo_amplified_K.txt,
                                           piezo_amplified_M.txt, piezo_amplified.txt, FEA-Response-Top.txt)
Prints, from the 108 x 108 matrices only (numpy):
- the fixed-interface frequencies (all 13 interface nodes clamped): sqrt of the modal block of K;
- which interface nodes are coupled (a non-zero 6 x 6 block): the shell couples its attachment
  points to each other, a beam element only its two neighbours;
- the stack's beam elements between the inner nodes (their rows hold nothing else), their axial,
  shear and bending terms, the section (E, A, rho, shear parameter) that reproduces them, and the
  beam's mass;
- the shell alone (the inner beam elements removed): the top's displacement per newton of a pair of
  opposite x forces on the stack-end nodes or on the inner attachment nodes (bottom fixed);
- the response of the whole element (node 76429 fixed, force pair 76430/76440 x, UY of 76423)
  against FEA-Response-Top.txt for a few loss factors.
"""
import csv
import re
import sys

import numpy as np


def read_matrix(path):
    a = np.zeros((108, 108))
    for m in re.finditer(r"\[\s*(\d+),\s*(\d+)\]:\s*([-+0-9.eE]+)", open(path).read()):
        a[int(m.group(1)) - 1, int(m.group(2)) - 1] = float(m.group(3))
    return a


def rigid_map(ra, rb):
    """6 x 6: the DOF of a point at rb moving rigidly with the point ra."""
    r = rb - ra
    t = np.eye(6)
    t[:3, 3:] = np.array([[0, r[2], -r[1]], [-r[2], 0, r[0]], [r[1], -r[0], 0]])
    return t


def main():
    d = sys.argv[1].rstrip("/") + "/"
    K, M = read_matrix(d + "piezo_amplified_K.txt"), read_matrix(d + "piezo_amplified_M.txt")
    nodes = []
    for line in open(d + "piezo_amplified.txt"):
        p = line.split()
        if len(p) == 2 and p[0].isdigit() and int(p[0]) not in nodes:
            nodes.append(int(p[0]))
    # Coordinates (out_NLIST.txt): top, bottom, stack ends at -+35 mm, inner nodes 7 mm apart.
    pos = {76423: (0, .03, 0), 76429: (0, -.03, 0), 76430: (-.035, 0, 0), 76440: (.035, 0, 0)}
    for k in range(9):
        pos[76431 + k] = (0.028 - 0.007 * k, 0, 0)
    pos = {n: np.array(v, float) for n, v in pos.items()}
    ix = {n: slice(6 * i, 6 * i + 6) for i, n in enumerate(nodes)}

    fi = np.sqrt(np.diag(K[78:, 78:])) / (2 * np.pi)
    print("fixed-interface modes (Hz, all 13 nodes clamped):", " ".join(f"{f:.0f}" for f in fi[:10]))
    for n in nodes:
        linked = [m for m in nodes if m != n and np.abs(K[ix[n], ix[m]]).max() > 0]
        print(f"node {n} ({pos[n][0]*1e3:+.0f},{pos[n][1]*1e3:+.0f} mm) coupled to {linked}")

    # Inner beam elements: 76439 (-28 mm) .. 76431 (+28 mm); their diagonal blocks follow from the
    # off-diagonal one by rigid-body equilibrium (K_aa = -K_ab T).
    chain = [76439, 76438, 76437, 76436, 76435, 76434, 76433, 76432, 76431]
    shell = K.copy()
    for a, b in zip(chain[:-1], chain[1:]):
        kab = K[ix[a], ix[b]].copy()
        t = rigid_map(pos[a], pos[b])
        shell[ix[a], ix[a]] += kab @ t
        shell[ix[b], ix[b]] += kab.T @ np.linalg.inv(t)
        shell[ix[a], ix[b]] -= kab
        shell[ix[b], ix[a]] -= kab.T
    inner = [n for n in chain[1:-1]]
    print(f"inner nodes after removing the 8 beam elements: largest |K| left {max(np.abs(shell[ix[n], :]).max() for n in inner):.2g} N/m "
          f"(of {np.abs(K[ix[76435], ix[76435]]).max():.3g})")
    a, b = 76435, 76434
    kaa = -K[ix[a], ix[b]] @ rigid_map(pos[a], pos[b])
    L = 0.007
    ea, kv, kr, gj = kaa[0, 0] * L, kaa[1, 1], kaa[5, 5], kaa[3, 3]
    # Timoshenko beam: k_vv = 12 EI / (L^3 (1 + phi)), k_rr = (4 + phi) EI / (L (1 + phi)).
    phi = kr / kv / (L * L / 12) - 4
    ei = kv * L**3 * (1 + phi) / 12
    E = 48e9
    area = ea / E
    print(f"beam element (7 mm): EA/L {kaa[0,0]:.4g} N/m, 12EI/L^3/(1+phi) {kv:.4g} N/m, bending {kr:.4g} N m/rad, "
          f"torsion {gj:.4g} N m/rad; shear parameter phi {phi:.2f}, EI {ei:.3g} N m^2")
    print(f"  with E = 48 GPa: A = {area:.4g} m^2, square-section EI = E A^2/12 = {E*area*area/12:.3g} N m^2, "
          f"phi = 12 EI/(5/6 G A L^2) = {12*E*area*area/12/(5/6*E/2.62*area*L*L):.2f} (nu 0.31)")
    rig = np.zeros((108, 6))
    for n in nodes:
        rig[ix[n], :] = rigid_map(np.zeros(3), pos[n])
    rhoa = (M @ rig[:, 0])[6 * nodes.index(76435)] / L  # an inner node carries two half elements
    print(f"  mass {rhoa:.4g} kg/m (rho = {rhoa/area:.4g} kg/m^3), {rhoa*0.056*1e3:.1f} g over the 56 mm between -+28 mm")
    print(f"total mass {rig[:,0] @ M @ rig[:,0] * 1e3:.1f} g")

    def static(k, f_nodes):
        fixed = set(range(6, 12))
        keep = [i for i in range(78) if i not in fixed and np.abs(k[i, :78]).max() > 1e3]
        f = np.zeros(78)
        f[6 * nodes.index(f_nodes[0])] = -1
        f[6 * nodes.index(f_nodes[1])] = 1
        u = np.zeros(78)
        u[keep] = np.linalg.solve(k[np.ix_(keep, keep)], f[keep])
        return u[1]
    for name, k in (("whole element", K), ("shell alone", shell)):
        print(f"{name}: top UY per newton (bottom fixed): pair on 76430/76440 {static(k, (76430, 76440)):.4g} m, "
              f"pair on 76439/76431 {static(k, (76439, 76431)):.4g} m")

    rows = list(csv.DictReader(open(d + "FEA-Response-Top.txt")))
    fa = np.array([float(r["Freq"]) for r in rows])
    aa = np.array([float(r["Ampl"]) for r in rows])
    keep = [i for i in range(108) if not 6 <= i < 12]
    kk, mm = K[np.ix_(keep, keep)], M[np.ix_(keep, keep)]
    f = np.zeros(108)
    f[6 * nodes.index(76430)], f[6 * nodes.index(76440)] = -1, 1
    f = f[keep]
    out = keep.index(1)
    for eta in (0.0, 0.01, 0.02, 0.04):
        h = np.array([np.linalg.solve(kk * (1 + 1j * eta) - (2 * np.pi * x) ** 2 * mm, f)[out] for x in fa])
        e = np.abs(20 * np.log10(np.abs(h) / aa))
        print(f"whole element, loss factor {eta}: median {np.median(e):.2f} dB, 90 % {np.quantile(e, 0.9):.2f} dB against FEA-Response-Top")


if __name__ == "__main__":
    main()
