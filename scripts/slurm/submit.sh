#!/usr/bin/env bash
# Submits a campaign to Slurm as a job array (one task per group of units) plus a dependent merge
# job. docs/cluster.md explains the set-up on a real cluster.
#
#   scripts/slurm/submit.sh CAMPAIGN.toml OUT_DIR [--parts N] [--throttle M] [--piezobench PATH]
#                           [--wait] [-- EXTRA_SBATCH_ARGS...]
#
#   --parts N         array tasks (default: one per unit, capped at 64); units are split in the
#                     campaign file's order, part K of N gets units K, K+N, ... (balanced)
#   --throttle M      at most M array tasks at once (sbatch --array=1-N%M); default: no limit
#   --piezobench P    the program (default: piezobench on PATH); must be on a shared file system
#   --wait            return only when the merge job has ended; exit non-zero if it failed
# Prints the two job ids. Partial results go to OUT_DIR/parts, the merged ones to OUT_DIR.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
usage() { sed -n '2,15p' "${BASH_SOURCE[0]}" >&2; exit 2; }
[ $# -ge 2 ] || usage
campaign="$(realpath "$1")"; out="$2"; shift 2
parts=""; throttle=""; program="$(command -v piezobench || true)"; wait=0; extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --parts) parts="$2"; shift 2 ;;
    --throttle) throttle="$2"; shift 2 ;;
    --piezobench) program="$2"; shift 2 ;;
    --wait) wait=1; shift ;;
    --) shift; extra=("$@"); break ;;
    *) echo "submit.sh: unknown option '$1'" >&2; usage ;;
  esac
done
[ -f "$campaign" ] || { echo "submit.sh: no campaign file '$campaign'" >&2; exit 3; }
[ -n "$program" ] && [ -x "$program" ] || { echo "submit.sh: piezobench not found (give --piezobench PATH)" >&2; exit 2; }
program="$(realpath "$program")"
if [ -z "$parts" ]; then
  parts=$("$program" run "$campaign" --list-units | wc -l)
  [ "$parts" -gt 64 ] && parts=64
fi
[[ "$parts" =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: --parts expects a positive integer, found '$parts'" >&2; exit 2; }
mkdir -p "$out/parts"
out="$(realpath "$out")"
array="1-$parts"
[ -n "$throttle" ] && array="$array%$throttle"
export PIEZOBENCH="$program" CAMPAIGN="$campaign" PARTS="$out/parts" NPARTS="$parts" OUT="$out"
part_job=$(sbatch --parsable --array="$array" --output="$out/parts/slurm-%A_%a.out" \
  --export=ALL "${extra[@]}" "$here/campaign_part.sbatch")
part_job="${part_job%%;*}"
merge_args=(--parsable --dependency="afterok:$part_job" --kill-on-invalid-dep=yes
            --output="$out/slurm-merge-%j.out" --export=ALL)
[ "$wait" -eq 1 ] && merge_args+=(--wait)
echo "array job $part_job ($parts tasks), merge job follows" >&2
merge_job=$(sbatch "${merge_args[@]}" "${extra[@]}" "$here/campaign_merge.sbatch")
echo "$part_job ${merge_job%%;*}"
