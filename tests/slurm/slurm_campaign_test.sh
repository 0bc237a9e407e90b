#!/usr/bin/env bash
# The demo campaign on a real (single-node) Slurm: the job array of partial runs plus the
# dependent merge job, run by slurmctld/slurmd, must give the same results.json and report.html as
# one `piezobench run` over all units. Exit 77 (ctest: skipped) with the reason when Slurm cannot
# start on this machine (programs missing, not root, a daemon that exits at start).
#   tests/slurm/slurm_campaign_test.sh PIEZOBENCH WORK_DIR
# About 30 s: the demo's simulation and run of three units (10 s), the array and the merge (20 s).
set -uo pipefail
program="$(realpath "$1")"
work="$2"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
rm -rf "$work"
mkdir -p "$work"
work="$(realpath "$work")"

# Slurm first: a machine that cannot run it skips at once.
cluster="$work/cluster"
env_lines=$(timeout 90 "$root/scripts/slurm/local_cluster.sh" start "$cluster")
rc=$?
if [ $rc -ne 0 ]; then
  [ $rc -eq 124 ] && { "$root/scripts/slurm/local_cluster.sh" stop "$cluster"; echo "local_cluster.sh did not return within 90 s" >&2; rc=77; }
  [ $rc -eq 77 ] && echo "SKIPPED: Slurm cannot start here (see above)"
  exit $rc
fi
eval "$env_lines"
trap '"$root/scripts/slurm/local_cluster.sh" stop "$cluster"' EXIT

# The reference: the demo's own single-process run (simulation + run over its units). Units 1
# (the IFF records), 3 (rejected) and 4: one array task each.
if ! timeout 120 "$program" demo --fast --units 1,3,4 --threads 2 --out "$work/demo" >"$work/demo.log" 2>&1; then
  cat "$work/demo.log" >&2
  exit 1
fi
campaign="$work/demo/campaign.toml"
[ -f "$campaign" ] || { echo "no campaign file in $work/demo" >&2; exit 1; }

# Three array tasks, at most two at once, and the merge job; wait for it.
start=$(date +%s)
if ! timeout 180 "$root/scripts/slurm/submit.sh" "$campaign" "$work/slurm" --parts 3 --throttle 2 \
     --piezobench "$program" --wait; then
  echo "the Slurm jobs failed; their logs:" >&2
  tail -n 20 "$work"/slurm/parts/slurm-*.out "$work"/slurm/slurm-merge-*.out >&2 2>/dev/null
  tail -n 20 "$cluster/log/slurmctld.log" >&2
  exit 1
fi
echo "array and merge jobs done in $(( $(date +%s) - start )) s"
for k in 1 2 3; do
  [ -f "$work/slurm/parts/part-$k/part.json" ] || { echo "array task $k wrote no part.json" >&2; exit 1; }
done
/usr/bin/python3 "$root/scripts/compare_results.py" "$work/demo/results.json" "$work/slurm/results.json" --rtol 0 || exit 1
# The same campaign path on both sides: the documents are equal byte for byte.
for f in results.json report.html; do
  cmp "$work/demo/$f" "$work/slurm/$f" || { echo "$f of the merge job differs from the single run's" >&2; exit 1; }
done
echo "merged results.json and report.html equal the single run's"
