#!/usr/bin/env bash
# The large model of the Craig-Bampton benchmark (bench/fem_cb_bench.cpp; issue 4: "about 150,000
# DOF with 12 interface DOF and 30 modes"), made with the reference tools Gmsh and CalculiX:
#
#  1. Gmsh meshes ../shared/data/apa95ml-ansys/APA95ML.step with quadratic tetrahedra (C3D10) at
#     MESH_SIZE mm (default 2: about 50,000 nodes, 150,000 DOF), the block that stands for the
#     stack split off as its own volume (as `piezobench superelement from-step` does by default).
#  2. A Python step writes the deck in metres with two remote points (*RIGID BODY, REF NODE +
#     ROT NODE) on the top and bottom interfaces (the faces at y = +-29.9975 mm): 12 interface DOF.
#     Materials: shell steel (E 190 GPa, nu 0.3, 7800 kg/m^3), stack PZT (E 48 GPa, nu 0.31,
#     7800 kg/m^3).
#  3. ccx runs cb_dump.inp (*FREQUENCY,SOLVER=MATRIXSTORAGE: K, M, DOF list) and, unless
#     NO_REFERENCE is set, cb_ref.inp: *FREQUENCY with 30 modes and both remote points clamped,
#     which is exactly the fixed-interface eigenproblem of the reduction (the peer figure).
#
# Nothing here is committed (the .sti/.mas files of the 2 mm mesh are about 180 MB each).
# Usage: scripts/bench/make_cb_mesh.sh OUT_DIR [MESH_SIZE_MM]
# Then:  /usr/bin/time -v BUILD/bench/fem_cb_bench OUT_DIR/cb_dump --modes 30
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
step="$repo/../shared/data/apa95ml-ansys/APA95ML.step"
out="${1:?usage: make_cb_mesh.sh OUT_DIR [MESH_SIZE_MM]}"
size="${2:-2}"
for tool in gmsh ccx /usr/bin/python3; do
  command -v "$tool" >/dev/null || { echo "make_cb_mesh: $tool not found (apt install gmsh calculix-ccx python3)" >&2; exit 3; }
done
[ -f "$step" ] || { echo "make_cb_mesh: $step not found" >&2; exit 3; }
mkdir -p "$out"
cd "$out"
cp "$step" model.step

cat > cb.geo <<GEO
SetFactory("OpenCASCADE");
Geometry.OCCTargetUnit = "MM";
Geometry.ToleranceBoolean = 1e-3;
Merge "model.step";
body() = Volume{:};
Box(1000) = {-34.7793, -10, -11.25, 69.5586, 20, 22.5};
inner() = BooleanIntersection{ Volume{body()}; }{ Volume{1000}; Delete; };
all() = BooleanFragments{ Volume{body()}; Delete; }{ Volume{inner()}; Delete; };
Mesh.MeshSizeMax = $size;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 2;
Mesh.Optimize = 1;
GEO
echo "make_cb_mesh: gmsh, ${size} mm, C3D10" >&2
/usr/bin/time -f "gmsh: %e s wall, %M kB peak" gmsh -3 cb.geo -format inp -o gmsh.inp > gmsh.log 2>&1 || { tail -20 gmsh.log >&2; exit 4; }
tail -n 1 gmsh.log >&2

PYTHONPATH="$repo/scripts/fem" /usr/bin/python3 - <<'PY'
from ccx_mesh import read_gmsh_inp, rigid_bodies, used_nodes, write_nodes, write_remote_points
nodes, blocks = read_gmsh_inp('gmsh.inp', 'C3D10')
used = used_nodes(blocks)
ys = [nodes[n][1] for n in used]
tol = 1e-9
faces = {'TOP': [n for n in used if abs(nodes[n][1] - max(ys)) < tol],
         'BOTTOM': [n for n in used if abs(nodes[n][1] - min(ys)) < tol]}
def in_stack(e):  # the block volume: corner nodes inside |x| <= 34.7793, |y| <= 10 mm
    return all(abs(nodes[n][0]) <= 0.0347793 + 1e-9 and abs(nodes[n][1]) <= 0.010 + 1e-9 for n in e[1:5])
with open('mesh.inp', 'w') as f:
    f.write('** APA95ML.step meshed by gmsh (C3D10), metres; scripts/bench/make_cb_mesh.sh\n')
    write_nodes(f, nodes, used)
    for name, es in blocks.items():
        region = 'STACK' if all(in_stack(e) for e in es) else 'SHELL'
        f.write('*ELEMENT, TYPE=C3D10, ELSET=%s\n' % region)
        for e in es:
            f.write(', '.join(map(str, e)) + '\n')
    refs = write_remote_points(f, nodes, faces, max(used) + 1)
common = ['*INCLUDE, INPUT=mesh.inp',
          '*MATERIAL, NAME=STEEL', '*ELASTIC', '1.9e11, 0.3', '*DENSITY', '7800.',
          '*MATERIAL, NAME=PZT', '*ELASTIC', '4.8e10, 0.31', '*DENSITY', '7800.',
          '*SOLID SECTION, ELSET=SHELL, MATERIAL=STEEL', '*SOLID SECTION, ELSET=STACK, MATERIAL=PZT'] + rigid_bodies(refs)
with open('cb_dump.inp', 'w') as f:
    f.write('\n'.join(common + ['*STEP', '*FREQUENCY, SOLVER=MATRIXSTORAGE', '10', '*END STEP']) + '\n')
bc = []
for ref, rot, _ in refs.values():
    bc += ['%d, 1, 3' % ref, '%d, 1, 3' % rot]
with open('cb_ref.inp', 'w') as f:
    f.write('\n'.join(common + ['*BOUNDARY'] + bc + ['*STEP', '*FREQUENCY', '30', '*END STEP']) + '\n')
with open('cb_interface.txt', 'w') as f:
    f.write(' '.join('%d:%d' % (ref, rot) for ref, rot, _ in refs.values()) + '\n')
print('make_cb_mesh: %d nodes, %d elements, about %d DOF; remote points %s' %
      (len(used), sum(len(es) for es in blocks.values()), 3 * len(used),
       {k: '%d:%d (%d face nodes)' % (r[0], r[1], len(faces[k])) for k, r in refs.items()}))
PY

echo "make_cb_mesh: ccx *FREQUENCY,SOLVER=MATRIXSTORAGE (the dump)" >&2
/usr/bin/time -f "ccx dump: %e s wall, %M kB peak" ccx -i cb_dump > cb_dump.log 2>&1 || { tail -20 cb_dump.log >&2; exit 4; }
tail -n 1 cb_dump.log >&2
if [ -z "${NO_REFERENCE:-}" ]; then
  echo "make_cb_mesh: ccx *FREQUENCY, 30 modes, both interfaces clamped (the peer)" >&2
  /usr/bin/time -f "ccx *FREQUENCY: %e s wall, %M kB peak" ccx -i cb_ref > cb_ref.log 2>&1 || { tail -20 cb_ref.log >&2; exit 4; }
  tail -n 1 cb_ref.log >&2
  awk '/E I G E N V A L U E   O U T P U T/ {t = 1; next}
       t && NF == 5 && $1 ~ /^[0-9]+$/ {printf "%s ", $4; n++}
       t && n >= 30 {exit}' cb_ref.dat > cb_ref_modes.txt
  echo "ccx fixed-interface modes (Hz): $(cat cb_ref_modes.txt)" >&2
fi
