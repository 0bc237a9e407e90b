#!/usr/bin/env bash
# kill -9 `piezobench qualify` at random moments, then `qualify --resume` until it completes, and
# check what docs/station.md promises (issue 28; not part of every CI run: ~10 s per round):
#   - the qualification completes every time;
#   - no phase that had completed is measured again: each phase has exactly one kept try, and no
#     try of it started after that one;
#   - the database holds every try (tries are numbered 1..n per phase without a gap);
#   - no half-written file is referenced: every raw file the database names exists with its SHA-256;
#   - PRAGMA integrity_check is ok.
# Usage: scripts/station/kill_resume.sh PIEZOBENCH [ROUNDS=100] [MAX_DELAY_S=6]
set -euo pipefail
bin="$(realpath "${1:?usage: kill_resume.sh PIEZOBENCH [ROUNDS] [MAX_DELAY_S]}")"
rounds="${2:-100}"
max_delay="${3:-6}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
work="$(mktemp -d /tmp/piezobench-kill-resume.XXXXXX)"
trap 'rm -rf "$work"' EXIT
db="$work/st.db"
common=(--bench "$root/docs/examples/bench-virtual.toml" --station "$root/docs/examples/station.toml"
        --answers "$root/docs/examples/station-answers.toml" --db "$db" --data "$work/data")
kills=0
for ((i = 1; i <= rounds; i++)); do
  serial="K$i"
  delay="$(python3 -c "import random; print(f'{random.uniform(0.05, $max_delay):.3f}')")"
  "$bin" qualify "${common[@]}" --serial "$serial" >/dev/null 2>&1 &
  pid=$!
  sleep "$delay"
  if kill -9 "$pid" 2>/dev/null; then kills=$((kills + 1)); fi
  wait "$pid" 2>/dev/null || true
  # Resume until complete (a qualification that completed before the kill is not resumed).
  for ((r = 0; r < 5; r++)); do
    status="$("$bin" db show "$serial" --json --db "$db" 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["status"])' || echo none)"
    [[ "$status" == complete ]] && break
    if [[ "$status" == none ]]; then
      "$bin" qualify "${common[@]}" --serial "$serial" >/dev/null 2>&1 || true   # killed before its first write
    else
      "$bin" qualify "${common[@]}" --resume "$serial" >/dev/null 2>"$work/resume.err" || { cat "$work/resume.err"; }
    fi
  done
  python3 - "$db" "$serial" <<'PY'
import hashlib, os, sqlite3, sys
db, serial = sys.argv[1], sys.argv[2]
c = sqlite3.connect(db)
(qid, status), = c.execute("SELECT id, status FROM qualification WHERE serial = ? ORDER BY id DESC LIMIT 1", (serial,))
assert status == "complete", f"{serial}: status {status}"
tries = c.execute("SELECT id, phase_name, try_number, status FROM phase_try WHERE qualification_id = ? ORDER BY id", (qid,)).fetchall()
phases = {}
for tid, name, n, st in tries:
    phases.setdefault(name, []).append((tid, n, st))
for name, ts in phases.items():
    kept = [t for t in ts if t[2] == "complete"]
    assert len(kept) == 1, f"{serial} {name}: {len(kept)} kept tries"
    assert ts[-1][2] == "complete", f"{serial} {name}: a try after the kept one: {ts}"
    assert [t[1] for t in ts] == list(range(1, len(ts) + 1)), f"{serial} {name}: tries {ts}"
for path, sha in c.execute("SELECT f.path, f.sha256 FROM raw_file f JOIN phase_try p ON p.id = f.phase_try_id WHERE p.qualification_id = ?", (qid,)):
    assert os.path.exists(path), f"{serial}: {path} referenced but missing"
    assert hashlib.sha256(open(path, "rb").read()).hexdigest() == sha, f"{serial}: {path} hash differs"
assert c.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
print(f"{serial}: complete, {len(tries)} tries over {len(phases)} phases")
PY
done
echo "kill_resume: $rounds rounds, $kills processes killed with SIGKILL, every qualification complete and consistent"
