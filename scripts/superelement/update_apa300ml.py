#!/usr/bin/python3
"""Model updating of the shipped APA300ML super element (issue 31, first step): which shell
modulus and stack modulus make the bench model's resonance and anti-resonance those the batch
measures, what the data determine (sensitivity matrix, its rank and condition), and what that does
to the static sensitivities. numpy/scipy only, on the shipped matrices: no gmsh, no ccx.

Why no re-meshing is needed for these two parameters: the shell is one material, so its stiffness
matrix scales with its Young's modulus (alpha = E_shell / E_built) and a Craig-Bampton reduction of
alpha K is alpha times the reduction of K (the constraint modes and the fixed-interface mode shapes
do not change, their eigenvalues scale); the stacks are beams between interface nodes, added to the
reduced model (fem/beam.hpp), whose matrices scale with the stack modulus (beta = E_stack / E_built).
So K(alpha, beta) = alpha (K_shipped - K_beams) + beta K_beams, M unchanged.

The bench is campaign/superelement_fit.hpp's: bottom clamped, 5.7 kg on the top interface guided
along y, force pair stack_a:stack_mid along x, outputs top y and the sensor stack's extension
stack_mid -> stack_b along x. Resonance: the first eigenfrequency; anti-resonance: the zero of
force -> sensor extension below it (undamped, by bisection of the sign change).

Usage: /usr/bin/python3 scripts/superelement/update_apa300ml.py [--resonance HZ] [--antiresonance HZ]
  [--shell-modulus PA] [--stack-modulus PA]   (the moduli the shipped element was built with)
(defaults: the mean of the accepted units of `demo --seed 1`, docs/apa300ml.md; the shipped
element's moduli since issue 31, 210.8 and 29.4 GPa: pass 200e9 and 48e9 for the one before).
It is the scipy reference of tests/campaign/superelement_update_test.cpp (`piezobench superelement
update` is the command).
"""
import argparse
import json
import os
import sys

import numpy as np
import scipy.io
import scipy.linalg
import scipy.optimize

HERE = os.path.dirname(os.path.abspath(__file__))
SE = os.path.join(HERE, "..", "..", "data", "superelement", "apa300ml")
MASS = 5.7


def read_dofs(path):
    labels, coords = [], {}
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        w = line.split()
        if w[0] == "MODE":
            labels.append(("MODE", int(w[1])))
        else:
            labels.append((int(w[0]), w[1]))
            coords[int(w[0])] = np.array([float(w[2]), float(w[3]), float(w[4])])
    return labels, coords


def beam_along_x(length, e, nu=0.31, area=1e-4):
    """12x12 Euler-Bernoulli beam along the global x axis (fem/beam.hpp's section: square,
    I = A^2/12, J = 0.1406 A^2). DOF order u v w rx ry rz at a, then at b."""
    g = e / (2 * (1 + nu))
    i = area ** 2 / 12
    j = 0.1406 * area ** 2
    L = length
    k = np.zeros((12, 12))
    def put(a, b, v):
        k[a, b] += v
    ea = e * area / L
    for (p, q, s) in [(0, 0, 1), (0, 6, -1), (6, 0, -1), (6, 6, 1)]:
        put(p, q, s * ea)
    gj = g * j / L
    for (p, q, s) in [(3, 3, 1), (3, 9, -1), (9, 3, -1), (9, 9, 1)]:
        put(p, q, s * gj)
    # bending in x-y (v, rz) and in x-z (w, ry: opposite signs of the coupling terms)
    for (v1, r1, v2, r2, sg) in [(1, 5, 7, 11, 1), (2, 4, 8, 10, -1)]:
        c = e * i / L ** 3
        m = np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L * L, -6 * L, 2 * L * L],
                      [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L * L, -6 * L, 4 * L * L]]) * c
        idx = [v1, r1, v2, r2]
        sgn = np.array([1, sg, 1, sg])
        k[np.ix_(idx, idx)] += m * np.outer(sgn, sgn)
    return k


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--resonance", type=float, default=95.4)
    ap.add_argument("--antiresonance", type=float, default=41.1)
    ap.add_argument("--shell-modulus", type=float, default=210.8e9, help="the shell's modulus the shipped element was built with, Pa")
    ap.add_argument("--stack-modulus", type=float, default=29.4e9, help="the stacks' modulus the shipped element was built with, Pa")
    args = ap.parse_args()
    K = scipy.io.mmread(os.path.join(SE, "apa300ml_K.mtx")).toarray()
    M = scipy.io.mmread(os.path.join(SE, "apa300ml_M.mtx")).toarray()
    labels, coords = read_dofs(os.path.join(SE, "apa300ml_dofs.txt"))
    summary = json.load(open(os.path.join(SE, "summary.json")))
    node = {p["name"]: p["node"] for p in summary["remote_points"]}
    node.update({j["name"]: j["node"] for j in summary["joints"]})
    index = {lab: n for n, lab in enumerate(labels)}
    dof_names = ["UX", "UY", "UZ", "ROTX", "ROTY", "ROTZ"]
    kb = np.zeros_like(K)
    for s in summary["stacks"]:
        a, b = s["node_a"], s["node_b"]
        L = float(np.linalg.norm(coords[b] - coords[a]))
        assert abs(coords[b][1] - coords[a][1]) < 1e-9 and abs(coords[b][2] - coords[a][2]) < 1e-9
        kbeam = beam_along_x(L, args.stack_modulus)
        if coords[b][0] < coords[a][0]:
            a, b = b, a
        idx = [index[(a, d)] for d in dof_names] + [index[(b, d)] for d in dof_names]
        kb[np.ix_(idx, idx)] += kbeam
        assert abs(s["axial_stiffness_N_per_m"] - args.stack_modulus * 1e-4 / L) < 1e-3 * s["axial_stiffness_N_per_m"]
    kshell = K - kb

    fixed = {node["bottom"]}
    top = node["top"]
    free = [n for n, lab in enumerate(labels) if not (lab[0] in fixed) and not (lab[0] == top and lab[1] != "UY")]
    m = M.copy()
    iy = index[(top, "UY")]
    m[iy, iy] += MASS
    f = np.zeros(len(labels))
    f[index[(node["stack_mid"], "UX")]] += 1.0
    f[index[(node["stack_a"], "UX")]] -= 1.0
    t_sensor = np.zeros(len(labels))
    t_sensor[index[(node["stack_b"], "UX")]] += 1.0
    t_sensor[index[(node["stack_mid"], "UX")]] -= 1.0
    t_top = np.zeros(len(labels))
    t_top[iy] = 1.0
    F = np.ix_(free, free)

    def model(alpha, beta):
        k = alpha * kshell + beta * kb
        return k[F], m[F]

    def resonance(alpha, beta):
        k, mm = model(alpha, beta)
        w2 = scipy.linalg.eigh(k, mm, eigvals_only=True)
        return np.sqrt(w2[0]) / (2 * np.pi)

    def h_sensor(alpha, beta, fr):
        k, mm = model(alpha, beta)
        w = 2 * np.pi * fr
        return t_sensor[free] @ np.linalg.solve(k - w * w * mm, f[free])

    def antiresonance(alpha, beta):
        fr = resonance(alpha, beta)
        grid = np.linspace(0.2 * fr, 0.98 * fr, 400)
        h = np.array([h_sensor(alpha, beta, x) for x in grid])
        i = np.where(np.sign(h[:-1]) != np.sign(h[1:]))[0]
        if len(i) == 0:
            return float("nan")
        return scipy.optimize.brentq(lambda x: h_sensor(alpha, beta, x), grid[i[0]], grid[i[0] + 1], xtol=1e-9)

    def static(alpha, beta):
        k, _ = model(alpha, beta)
        q = np.linalg.solve(k, f[free])
        return t_top[free] @ q, t_sensor[free] @ q

    def features(x):
        a, b = np.exp(x)
        return np.array([np.log(resonance(a, b)), np.log(antiresonance(a, b))])

    target = np.log([args.resonance, args.antiresonance])
    x0 = np.zeros(2)
    sol = scipy.optimize.least_squares(lambda x: features(x) - target, x0, x_scale=1.0, xtol=1e-12, ftol=1e-12)
    J = sol.jac  # d log(feature) / d log(parameter)
    sv = np.linalg.svd(J, compute_uv=False)
    alpha, beta = np.exp(sol.x)
    out = {
        "shipped": {"resonance_Hz": resonance(1, 1), "antiresonance_Hz": antiresonance(1, 1),
                    "static_top_per_N": static(1, 1)[0], "static_sensor_per_N": static(1, 1)[1]},
        "target": {"resonance_Hz": args.resonance, "antiresonance_Hz": args.antiresonance},
        "updated": {"shell_modulus_scale": alpha, "shell_E_Pa": alpha * args.shell_modulus, "stack_modulus_scale": beta,
                    "stack_E_Pa": beta * args.stack_modulus, "resonance_Hz": resonance(alpha, beta),
                    "antiresonance_Hz": antiresonance(alpha, beta),
                    "static_top_per_N": static(alpha, beta)[0], "static_sensor_per_N": static(alpha, beta)[1]},
        "sensitivity_log_log": J.tolist(),
        "singular_values": sv.tolist(),
        "condition": float(sv[0] / sv[-1]),
        "rank": int(np.sum(sv > 1e-6 * sv[0])),
    }
    json.dump(out, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
