#!/bin/sh
# Makes the APA300ML super element shipped in data/superelement/apa300ml/ (the one `piezobench demo`
# puts on its virtual bench and compares with the measurements, report section 4) from the
# repository's own geometry, data/geometry/apa300ml.geo, with gmsh, ccx and piezobench:
#
#   piezobench superelement from-step data/geometry/apa300ml.geo --mesh-size $MESH --modes $MODES --verify
#
# (preset apa300ml: remote points top, bottom, stack_a, stack_b, joint stack_mid; the three stacks
# as beams with Table 4.1's area). The moduli are the updated ones (issue 31, docs/apa300ml.md:
# `piezobench superelement update` against the accepted units of `demo --seed 1`): the shell's
# SHELL_E = 210.8e9 Pa and the stacks' effective STACK_E = 29.4e9 Pa (Table 4.1's c^E is 48e9;
# SHELL_E=200e9 STACK_E=48e9 makes the element shipped before the update). Writes the super element (Matrix Market + DOF list),
# the bench description apa300ml.toml (node numbers from the run; ga and gs from eq. 4.1) and a
# summary without machine paths (summary.json). Run from the repository root after a build:
#   sh scripts/superelement/make_apa300ml.sh [path/to/piezobench]
set -eu
PB=${1:-build/app/piezobench}
MESH=${MESH:-1.5}
MODES=${MODES:-40}
SHELL_E=${SHELL_E:-210.8e9}
STACK_E=${STACK_E:-29.4e9}
DEST=data/superelement/apa300ml
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
"$PB" superelement from-step data/geometry/apa300ml.geo --mesh-size "$MESH" --modes "$MODES" --clamped-modes 10 \
  --material "body:$SHELL_E,0.3,7850" --stack "stack_a:stack_mid:$STACK_E,0.31,7800,1e-4" \
  --stack "stack_mid:stack_b:$STACK_E,0.31,7800,1e-4" --verify --out "$WORK/out" --stem apa300ml --json > "$WORK/from_step.json"
mkdir -p "$DEST"
cp "$WORK/out/apa300ml_K.mtx" "$WORK/out/apa300ml_M.mtx" "$WORK/out/apa300ml_dofs.txt" "$DEST/"
/usr/bin/python3 - "$WORK/from_step.json" "$DEST" "$MESH" "$MODES" "$SHELL_E" "$STACK_E" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
dest, mesh, modes, shell_e, stack_e = sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5], sys.argv[6]
node = {p["name"]: p["node"] for p in doc["remote_points"]}
node.update({j["name"]: j["node"] for j in doc["joints"]})
keep = {k: doc[k] for k in ("mesh", "materials", "remote_points", "joints", "stacks", "reduction", "clamp",
                            "modes_clamped_Hz", "shell_modes_clamped_Hz", "axial", "axial_stiffness_N_per_m", "shell_axial_stiffness_N_per_m", "reference_modes_Hz", "relative_difference",
                            "free_modes_Hz", "geo_parameters", "warnings") if k in doc}
keep["command"] = ("piezobench superelement from-step data/geometry/apa300ml.geo --mesh-size %s --modes %s "
                   "--clamped-modes 10 --material body:%s,0.3,7850 --stack stack_a:stack_mid:%s,0.31,7800,1e-4 "
                   "--stack stack_mid:stack_b:%s,0.31,7800,1e-4 --verify --stem apa300ml" % (mesh, modes, shell_e, stack_e, stack_e))
keep["gmsh_version"], keep["ccx_version"] = doc["gmsh"]["version"], doc["ccx"]["version"]
json.dump(keep, open(dest + "/summary.json", "w"), indent=1)
open(dest + "/summary.json", "a").write("\n")
# Eq. 4.1 with the stacks' effective modulus E (docs/apa300ml.md): ga = d33 n E A / L scales with E,
# and so does gs = d33 / (eps^T s^D n) (glue and electrodes in series take their share of the strain,
# the ceramic's share is E / c^E): Table 4.1's 26.11 N/V and 5.06e6 V/m times E / 48e9.
ga = 26.11 * float(stack_e) / 48e9
gs = 5.06e6 * float(stack_e) / 48e9
toml = f"""# The APA300ML super element on the virtual bench (bench/virtual_bench.hpp, `simulate --superelement`),
# made by scripts/superelement/make_apa300ml.sh from data/geometry/apa300ml.geo (summary.json).
# Remote points as in the report's Fig. 4.1: 1 top {node['top']}, 2 bottom {node['bottom']},
# 3 stack_a {node['stack_a']} (actuator stacks' outer end), 4 stack_mid {node['stack_mid']} (between the
# actuator stacks and the sensor stack), 5 stack_b {node['stack_b']} (sensor stack's outer end).
format = "matrix-market"
k_file = "apa300ml_K.mtx"
m_file = "apa300ml_M.mtx"
nodes_file = "apa300ml_dofs.txt"
fix = [{node['bottom']}]
actuator = "{node['stack_a']}:{node['stack_mid']}:x"
sensor = "{node['stack_mid']}:{node['stack_b']}:x"
output = "{node['top']}:y"
ga = {ga:.4g}      # N/V, eq. 4.1b with Table 4.1 and the stacks' effective modulus {float(stack_e):.4g} Pa (x E / c^E)
gs = {gs:.4g}     # V/m, eq. 4.1a with Table 4.1 and the stacks' effective modulus (x E / c^E)
modal_damping = 0.01
stack_modulus_Pa = {float(stack_e):.4g}   # the stacks' effective modulus (the campaign's eq. 4.1 uses it)
"""
open(dest + "/apa300ml.toml", "w").write(toml)
print("modes (bottom clamped, Hz):", ", ".join("%.1f" % f for f in doc["modes_clamped_Hz"][:4]))
PY
echo "written: $DEST"
