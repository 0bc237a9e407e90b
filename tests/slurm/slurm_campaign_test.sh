#!/usr/bin/env bash
# The demo campaign on a real (single-node) Slurm: the job array of partial runs plus the
# dependent merge job, run by slurmctld/slurmd, must give the same results.json as one
# `piezobench run` over all units. Exit 77 (ctest: skipped) with the reason when Slurm cannot
# start on this machine.
#   tests/slurm/slurm_campaign_test.sh PIEZOBENCH WORK_DIR
set -uo pipefail
program="$(realpath "$1")"
work="$2"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
rm -rf "$work"
mkdir -p "$work"
work="$(realpath "$work")"

# The reference: the demo's own single-process run (simulation + run over all units).
"$program" demo --fast --out "$work/demo" >"$work/demo.log" 2>&1 || { cat "$work/demo.log"; exit 1; }
campaign="$work/demo/campaign.toml"
[ -f "$campaign" ] || { echo "no campaign file in $work/demo" >&2; exit 1; }

cluster="$work/cluster"
env_lines=$("$root/scripts/slurm/local_cluster.sh" start "$cluster")
rc=$?
if [ $rc -ne 0 ]; then
  [ $rc -eq 77 ] && echo "SKIPPED: Slurm cannot start here (see above)"
  exit $rc
fi
eval "$env_lines"
trap '"$root/scripts/slurm/local_cluster.sh" stop "$cluster"' EXIT

# Three array tasks over the seven units, at most two at once, and the merge job; wait for it.
if ! timeout 600 "$root/scripts/slurm/submit.sh" "$campaign" "$work/slurm" --parts 3 --throttle 2 \
     --piezobench "$program" --wait; then
  echo "the Slurm jobs failed; their logs:" >&2
  tail -n 20 "$work"/slurm/parts/slurm-*.out "$work"/slurm/slurm-merge-*.out >&2 2>/dev/null
  tail -n 20 "$cluster/log/slurmctld.log" >&2
  exit 1
fi
/usr/bin/python3 "$root/scripts/compare_results.py" "$work/demo/results.json" "$work/slurm/results.json"
