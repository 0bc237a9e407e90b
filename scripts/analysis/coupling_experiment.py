#!/usr/bin/env python3
"""Rigid or distributing remote points on the APA95ML shell, against the Ansys super element (issue 31).

Usage: coupling_experiment.py FROM_STEP_DIR FEA-Response-Top.txt KINDS [--beam E,nu,rho,A,SEGMENTS,e|t ...]
       [--split-ends]
FROM_STEP_DIR: the output of `piezobench superelement from-step ... --preset apa95ml-beam --keep-temp`
(mesh.inp, matrices.inp, from_step.json). KINDS: rigid|dist for top,bottom,stack_a,stack_b, e.g.
`rigid,rigid,dist,dist`. --beam: the stack between stack_a and stack_b (SEGMENTS beams, e: Euler-Bernoulli
as fem/beam.hpp, t: Timoshenko with shear factor 5/6); default the preset's. --split-ends: instead, the
shell alone with the stack ends split in two remote points each (the end face of the end block and the
two arch feet, all distributing, at -+35 and -+28 mm like the Ansys nodes), and its static compliances.

ccx (in PATH) dumps the free-free K and M of the mesh WITHOUT the *RIGID BODY lines; the couplings
are then applied here (scipy), so that both kinds act on exactly the same mesh:
- rigid (RBE2, what from-step writes): every face node moves with the remote point;
- dist (RBE3, Ansys's "deformable" remote point, Abaqus *DISTRIBUTING): the remote point's 6 DOF are
  the least-squares rigid motion of the face nodes (equal weights); the face deforms freely.
Then Craig-Bampton (30 modes), the stack beam on the reduced model, bottom fixed, force pair
stack_a/stack_b along x, top's y: median |dB| against FEA-Response-Top, as compare_ansys_response.py.
"""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp
import scipy.sparse.linalg as sla


def skew(r):
    """S with S u = r x u."""
    return np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])


def rigid_rows(ref, x):
    """3 x 6: translation of a point at x moving rigidly with [u, theta] of ref."""
    return np.hstack([np.eye(3), -skew(x - ref)])


def read_mesh(path):
    coords, sets, mode, name = {}, {}, None, None
    for line in open(path):
        if line.startswith("**"):
            continue
        if line.startswith("*"):
            u = line.upper()
            mode = "node" if u.startswith("*NODE") else "nset" if u.startswith("*NSET") else None
            if mode == "nset":
                name = re.search(r"NSET=(\w+)", u).group(1)
                sets[name] = []
            continue
        p = line.replace(",", " ").split()
        if mode == "node" and p:
            coords[int(p[0])] = np.array([float(v) for v in p[1:4]])
        elif mode == "nset" and p:
            sets[name] += [int(v) for v in p]
    return coords, sets


def dump_free_matrices(folder):
    """K, M (scipy CSR, symmetric) and the (node, direction) of each row, from ccx without rigid bodies."""
    work = tempfile.mkdtemp(prefix="coupling-")
    deck = [l for l in open(os.path.join(folder, "matrices.inp")) if "RIGID BODY" not in l.upper()]
    with open(os.path.join(work, "raw.inp"), "w") as f:
        f.writelines(deck)
    os.symlink(os.path.abspath(os.path.join(folder, "mesh.inp")), os.path.join(work, "mesh.inp"))
    subprocess.run(["ccx", "-i", "raw"], cwd=work, check=True, timeout=1200, stdout=subprocess.DEVNULL)
    dofs = [tuple(int(v) for v in t.split(".")) for t in open(os.path.join(work, "raw.dof")).read().split()]
    n = len(dofs)

    def load(ext):
        a = np.loadtxt(os.path.join(work, "raw." + ext))
        m = sp.coo_matrix((a[:, 2], (a[:, 0].astype(int) - 1, a[:, 1].astype(int) - 1)), shape=(n, n)).tocsr()
        return (m + m.T - sp.diags(m.diagonal())).tocsr()
    K, M = load("sti"), load("mas")
    for f in os.listdir(work):
        os.remove(os.path.join(work, f))
    os.rmdir(work)
    return K, M, {d: i for i, d in enumerate(dofs)}


def coupling_transform(ndof, dmap, coords, points):
    """u = T [independent DOF, 6 DOF per remote point]; points: (face nodes, ref position, kind)."""
    dep = {}  # dependent DOF -> {('u', dof) | ('q', k): coefficient}
    for p, (nodes, ref, kind) in enumerate(points):
        if kind == "rigid":
            for nd in nodes:
                r = rigid_rows(ref, coords[nd])
                for c in range(3):
                    dep[dmap[(nd, c + 1)]] = {("q", 6 * p + k): r[c, k] for k in range(6) if r[c, k] != 0}
            continue
        g = np.vstack([rigid_rows(ref, coords[nd]) for nd in nodes])
        C = np.linalg.solve(g.T @ g, g.T)  # q = C u_face (least-squares rigid motion)
        face = [dmap[(nd, c + 1)] for nd in nodes for c in range(3)]
        cand = [j for j in range(len(face)) if face[j] not in dep]
        piv = sl.qr(C[:, cand], pivoting=True)[2]
        d = [cand[j] for j in piv[:6]]
        rest = [j for j in range(len(face)) if j not in set(d)]
        cd_inv = np.linalg.inv(C[:, d])
        A = -cd_inv @ C[:, rest]
        for a, jd in enumerate(d):
            e = {("q", 6 * p + k): cd_inv[a, k] for k in range(6)}
            for b, jr in enumerate(rest):
                e[("u", face[jr])] = e.get(("u", face[jr]), 0.0) + A[a, b]
            dep[face[jd]] = e
    changed = True
    while changed:  # a face node shared by two remote points: substitute the other's expression
        changed = False
        for e in dep.values():
            for key in [k for k in e if k[0] == "u" and k[1] in dep]:
                v = e.pop(key)
                for kk, vv in dep[key[1]].items():
                    e[kk] = e.get(kk, 0.0) + v * vv
                changed = True
    free = [i for i in range(ndof) if i not in dep]
    col = {g: i for i, g in enumerate(free)}
    rows, cols, vals = [], [], []
    for i in range(ndof):
        for (t, k), v in (dep[i].items() if i in dep else [(("u", i), 1.0)]):
            rows.append(i)
            cols.append(col[k] if t == "u" else len(free) + k)
            vals.append(v)
    return sp.coo_matrix((vals, (rows, cols)), shape=(ndof, len(free) + 6 * len(points))).tocsr(), len(free)


def craig_bampton(K, M, nfree, modes=30):
    n = K.shape[0]
    i, b = np.arange(nfree), np.arange(nfree, n)
    kii, mii = K[i][:, i].tocsc(), M[i][:, i].tocsc()
    psi = -sla.splu(kii).solve(K[i][:, b].toarray())
    w2, phi = sla.eigsh(kii, k=modes, M=mii, sigma=0, which="LM")
    order = np.argsort(w2)
    w2, phi = w2[order], phi[:, order]
    T = np.zeros((n, len(b) + modes))
    T[b, np.arange(len(b))] = 1
    T[np.ix_(i, np.arange(len(b)))] = psi
    T[np.ix_(i, np.arange(len(b), len(b) + modes))] = phi
    T = sp.csr_matrix(T)
    kr, mr = (T.T @ (K @ T)).toarray(), (T.T @ (M @ T)).toarray()
    return (kr + kr.T) / 2, (mr + mr.T) / 2, np.sqrt(np.abs(w2)) / (2 * np.pi)


def beam(a, b, E, nu, rho, A, timoshenko):
    """12 x 12 K and consistent M of a square-section beam (as fem/beam.hpp; optional shear)."""
    L = np.linalg.norm(b - a)
    ex = (b - a) / L
    ref = np.eye(3)[np.argmin(np.abs(ex))]
    ey = ref - ex * (ref @ ex)
    ey /= np.linalg.norm(ey)
    R = np.kron(np.eye(4), np.vstack([ex, ey, np.cross(ex, ey)]))
    I, J, G = A * A / 12, 0.1406 * A * A, E / (2 * (1 + nu))
    k, m = np.zeros((12, 12)), np.zeros((12, 12))
    k[np.ix_([0, 6], [0, 6])] = E * A / L * np.array([[1, -1], [-1, 1]])
    k[np.ix_([3, 9], [3, 9])] = G * J / L * np.array([[1, -1], [-1, 1]])
    ml = rho * A * L
    m[np.ix_([0, 6], [0, 6])] = ml / 6 * np.array([[2, 1], [1, 2]])
    m[np.ix_([3, 9], [3, 9])] = rho * 2 * I * L / 6 * np.array([[2, 1], [1, 2]])
    ph = 12 * E * I / (5 / 6 * G * A * L * L) if timoshenko else 0.0
    kb = E * I / L**3 / (1 + ph) * np.array([[12, 6 * L, -12, 6 * L], [6 * L, (4 + ph) * L * L, -6 * L, (2 - ph) * L * L],
                                             [-12, -6 * L, 12, -6 * L], [6 * L, (2 - ph) * L * L, -6 * L, (4 + ph) * L * L]])
    mb = ml / 420 * np.array([[156, 22 * L, 54, -13 * L], [22 * L, 4 * L * L, 13 * L, -3 * L * L],
                              [54, 13 * L, 156, -22 * L], [-13 * L, -3 * L * L, -22 * L, 4 * L * L]])
    for v, r, s in ((1, 5, 1), (2, 4, -1)):
        idx = [v, r, v + 6, r + 6]
        S = np.diag([1, s, 1, s])
        k[np.ix_(idx, idx)] += S @ kb @ S
        m[np.ix_(idx, idx)] += S @ mb @ S
    return R.T @ k @ R, R.T @ m @ R


def response(K, M, fixed, force, out, freqs):
    keep = [i for i in range(K.shape[0]) if i not in set(fixed)]
    w2, V = sl.eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)])
    f = np.zeros(K.shape[0])
    for i, s in force:
        f[i] += s
    pf, po = V.T @ f[keep], V[keep.index(out), :]
    h = np.array([np.sum(po * pf / (w2 - (2 * np.pi * x) ** 2)) for x in freqs])
    return h, np.sqrt(np.abs(w2)) / (2 * np.pi)


def split_ends(K, M, dmap, coords, sets, pos):
    """Shell alone, each stack end as two distributing remote points (end face at -+35 mm, arch feet at -+28)."""
    pts = [(sets["F_TOP"], pos["top"], "dist"), (sets["F_BOTTOM"], pos["bottom"], "dist")]
    for s, name in ((-1, "F_STACK_A"), (1, "F_STACK_B")):
        face = [n for n in sets[name] if abs(abs(coords[n][0]) - 0.0347793) < 1e-7]
        feet = [n for n in sets[name] if abs(abs(coords[n][1]) - 0.01) < 1e-7]
        pts += [(face, np.array([s * 0.035, 0, 0]), "dist"), (feet, np.array([s * 0.028, 0, 0]), "dist")]
    pts = [pts[0], pts[1], pts[2], pts[3], pts[5], pts[4]]  # top, bottom, end_a, feet_a, feet_b, end_b
    T, nf = coupling_transform(K.shape[0], dmap, coords, pts)
    kr, _, fi = craig_bampton((T.T @ K @ T).tocsr(), (T.T @ M @ T).tocsr(), nf)
    print("fixed-interface modes (Hz):", " ".join(f"{f:.0f}" for f in fi[:8]))
    kb = kr[:36, :36]
    keep = [i for i in range(36) if not 6 <= i < 12]
    for label, (a, b) in (("end faces (-+35 mm)", (12, 30)), ("arch feet (-+28 mm)", (18, 24))):
        f = np.zeros(36)
        f[a], f[b] = -1, 1
        u = np.zeros(36)
        u[keep] = np.linalg.solve(kb[np.ix_(keep, keep)], f[keep])
        print(f"pair on the {label}: top UY {u[1]:.4g} m/N, pair's own opening {u[b]-u[a]:.4g} m/N")


def main():
    folder, fea, kinds = sys.argv[1], sys.argv[2], sys.argv[3].split(",")
    beams = [sys.argv[i + 1] for i, a in enumerate(sys.argv) if a == "--beam"] or ["48e9,0.31,16840,5.235e-5,4,e"]
    coords, sets = read_mesh(os.path.join(folder, "mesh.inp"))
    js = json.load(open(os.path.join(folder, "from_step.json")))
    pos = {p["name"]: np.array(p["position_m"]) for p in js["remote_points"]}
    K, M, dmap = dump_free_matrices(folder)
    if "--split-ends" in sys.argv:
        split_ends(K, M, dmap, coords, sets, pos)
        return
    names = ["top", "bottom", "stack_a", "stack_b"]
    pts = [(sets["F_" + n.upper()], pos[n], k) for n, k in zip(names, kinds)]
    T, nf = coupling_transform(K.shape[0], dmap, coords, pts)
    kr, mr, fi = craig_bampton((T.T @ K @ T).tocsr(), (T.T @ M @ T).tocsr(), nf)
    rows = list(csv.DictReader(open(fea)))
    fa = np.array([float(r["Freq"]) for r in rows])
    aa = np.array([float(r["Ampl"]) for r in rows])
    for spec in beams:
        p = spec.split(",")
        E, nu, rho, A, nseg, tim = float(p[0]), float(p[1]), float(p[2]), float(p[3]), int(p[4]), p[5] == "t"
        n = kr.shape[0] + 6 * (nseg - 1)
        order = list(range(24)) + list(range(24 + 6 * (nseg - 1), n))
        Kb, Mb = np.zeros((n, n)), np.zeros((n, n))
        Kb[np.ix_(order, order)], Mb[np.ix_(order, order)] = kr, mr
        at = {2: pos["stack_a"], 3: pos["stack_b"]}
        for j in range(nseg - 1):
            at[4 + j] = pos["stack_a"] + (j + 1) / nseg * (pos["stack_b"] - pos["stack_a"])
        chain = [2] + [4 + j for j in range(nseg - 1)] + [3]
        for a, b in zip(chain[:-1], chain[1:]):
            kk, mm = beam(at[a], at[b], E, nu, rho, A, tim)
            ii = list(range(6 * a, 6 * a + 6)) + list(range(6 * b, 6 * b + 6))
            Kb[np.ix_(ii, ii)] += kk
            Mb[np.ix_(ii, ii)] += mm
        h, modes = response(Kb, Mb, range(6, 12), [(12, -1.0), (18, 1.0)], 1, fa)
        h0, _ = response(Kb, Mb, range(6, 12), [(12, -1.0), (18, 1.0)], 1, [0.0])
        e = np.abs(20 * np.log10(np.abs(h) / aa))
        length = np.linalg.norm(pos["stack_b"] - pos["stack_a"])
        print(f"{','.join(kinds)} stack {spec} ({rho*A*length*1e3:.1f} g): median {np.median(e):.2f} dB "
              f"(90 % {np.quantile(e, 0.9):.1f}), static {abs(h0[0]):.3g} m/N, bottom-clamped modes "
              f"{' '.join(f'{f:.0f}' for f in modes[:8])} Hz, fixed-interface {' '.join(f'{f:.0f}' for f in fi[:4])} Hz")


if __name__ == "__main__":
    main()
