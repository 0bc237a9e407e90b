#!/usr/bin/env python3
"""Runs the piezobench CLI over the regression corpus of hostile files (fuzz/regression/) and checks
the contract of issue 21: every run ends with exit 2, 3 or 4 (0 for a file named valid_*, any of
0, 2, 3, 4 for heavy_*) within 20 s of CPU time and under 1 GB of address space, never a signal, a
sanitizer report of its own process (a forked HDF5 reader's is the child's: src/io/isolated.hpp)
or exit 1 ("internal error"), and its output does not depend on MALLOC_PERTURB_.

usage: hostile_cli.py PIEZOBENCH_BINARY [--corpus DIR] [--timeout S] [--memory-mb MB]
Exit status 0 when every case holds; the failures are listed otherwise. Under a sanitizer build the
address-space limit is left out (ASan reserves terabytes of it), the timeout is tripled and the
sanitizer reports count.
"""
import argparse
import mmap
import os
import re
import resource
import subprocess
import sys
import tempfile
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
SEP = "\n@@@@\n"


def split(path, parts, names, workdir):
    """Writes the '@@@@'-separated parts of a multi-file input (fuzz/readers_fuzz.cpp) to files."""
    with open(path, "rb") as f:
        data = f.read().decode("latin-1")
    chunks = data.split(SEP, parts - 1)
    chunks += [""] * (parts - len(chunks))
    out = []
    for chunk, name in zip(chunks, names):
        p = os.path.join(workdir, name)
        with open(p, "wb") as f:
            f.write(chunk.encode("latin-1"))
        out.append(p)
    return out


# Corpora that are not files the CLI reads: the UDP target's datagrams (fuzz_udp_target replays them)
# and the web server's requests (fuzz_http_request).
NOT_FILES = {"udp_target", "http_request"}


def command(reader, path, workdir):
    """The command line that reads `path` with the reader under test."""
    if reader in ("mat_timeseries", "csv_timeseries"):
        return ["frf", path, "--input", "u", "--output", "de", "--fs", "10000", "--json"]
    if reader in ("mat_frf", "csv_frf", "uff58"):
        return ["fit", path, "--order", "4", "--json"]
    if reader == "lti_toml":
        return ["iff", "rlocus", "--plant", path, "--json"]
    if reader == "two_dof_toml":
        return ["model", "2dof", "--params", path, "--json"]
    if reader == "campaign_toml":
        return ["run", path, "--out", os.path.join(workdir, "out")]
    if reader in ("station_toml", "answers_toml"):
        # Refused before anything moves: the station file, then the answers against it.
        examples = os.path.join(ROOT, "docs", "examples")
        station = path if reader == "station_toml" else os.path.join(examples, "station.toml")
        answers = path if reader == "answers_toml" else os.path.join(examples, "station-answers.toml")
        return ["qualify", "--bench", os.path.join(examples, "bench-virtual.toml"), "--station", station, "--answers", answers,
                "--serial", "H1", "--db", os.path.join(workdir, "station.db"), "--data", os.path.join(workdir, "data"), "--json"]
    if reader == "twin_toml":
        return ["simulate", "frf-noise", "--twin", path, "--duration", "0.2", "--out", os.path.join(workdir, "twin.mat")]
    if reader == "ansys_text":
        return ["superelement"] + split(path, 3, ["k.txt", "m.txt", "master.txt"], workdir) + ["--json"]
    if reader == "matrix_market":
        return ["superelement"] + split(path, 3, ["k.mtx", "m.mtx", "dofs.txt"], workdir) + ["--json"]
    if reader == "calculix":
        sti, mas, dof, inp = split(path, 4, ["a.sti", "a.mas", "a.dof", "a.inp"], workdir)
        return ["superelement", sti, mas, dof, "--nlist", inp, "--json"]
    raise SystemExit(f"hostile_cli: no command for reader folder '{reader}'")


def sanitized(binary):
    """Whether the binary carries a sanitizer runtime: g++ links libasan/libubsan as shared
    libraries, clang links its runtime statically (its symbols are then in the binary itself)."""
    try:
        out = subprocess.run(["ldd", binary], capture_output=True, text=True).stdout
        if "libasan" in out or "libubsan" in out:
            return True
        with open(binary, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as m:
            return m.find(b"__asan_init") >= 0 or m.find(b"__ubsan_handle_") >= 0
    except (OSError, ValueError):
        return False


def run(binary, args, timeout, memory_mb, perturb, cwd):
    def limits():
        # The time bound is CPU time (SIGXCPU past it), so that a loaded machine does not fail a run
        # that is fast; the wall-clock timeout (6x) catches a process that hangs without computing.
        cpu = int(timeout)
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))
        if memory_mb:
            resource.setrlimit(resource.RLIMIT_AS, (memory_mb << 20, memory_mb << 20))
    env = dict(os.environ, MALLOC_PERTURB_=str(perturb))
    t0 = time.monotonic()
    with subprocess.Popen([binary] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=limits, env=env,
                          cwd=cwd) as p:
        try:
            out, err = p.communicate(timeout=6 * timeout)
        except subprocess.TimeoutExpired:
            p.kill()
            p.communicate()
            return None, b"", b"", time.monotonic() - t0
    return p.returncode, out, own_reports(err, p.pid), time.monotonic() - t0


def own_reports(err, pid):
    """stderr without the sanitizer reports of other processes. A MAT v7.3 file is read by a forked
    child (src/io/isolated.hpp) whose fault inside Debian's HDF5 the CLI reports as exit 3; what
    ASan prints in that child (from '==CHILD==ERROR: AddressSanitizer' to '==CHILD==ABORTING') is
    the child's. Reports of the CLI's own process, and every UBSan 'runtime error:', still count."""
    kept, foreign = [], None
    for line in err.splitlines(keepends=True):
        m = re.match(rb"==(\d+)==ERROR:", line)
        if foreign is None and m and int(m.group(1)) != pid:
            foreign = m.group(1)
        if foreign is None:
            kept.append(line)
        elif line.startswith(b"==" + foreign + b"==ABORTING"):
            foreign = None
    return b"".join(kept)


def check(binary, name, args, allowed, timeout, memory_mb, cwd, failures, deterministic=True):
    results = []
    for perturb in (0, 165):
        code, out, err, seconds = run(binary, args, timeout, memory_mb, perturb, cwd)
        problem = None
        if code is None:
            problem = f"no exit within {6 * timeout:g} s of wall-clock time"
        elif code < 0:
            problem = f"signal {-code}" + (f" (more than {timeout:g} s of CPU)" if -code == 24 else "")
        elif b"Sanitizer" in err or b"runtime error:" in err:
            problem = "sanitizer report"
        elif code not in allowed:
            problem = f"exit {code} (allowed {sorted(allowed)})"
        if problem:
            tail = err.decode("utf-8", "replace").strip().splitlines()[-3:]
            failures.append(f"{name}: {problem} [{' '.join(args)[:160]}] {' | '.join(tail)[:400]}")
            return
        results.append((code, out if code == 0 else err))
        print(f"  {name}: exit {code} in {seconds:.2f} s (MALLOC_PERTURB_={perturb})")
    if deterministic and results[0] != results[1]:
        failures.append(f"{name}: output differs with MALLOC_PERTURB_ (exit {results[0][0]} vs {results[1][0]})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("binary")
    ap.add_argument("--corpus", default=os.path.join(ROOT, "fuzz", "regression"))
    ap.add_argument("--timeout", type=float, default=20.0)
    ap.add_argument("--memory-mb", type=int, default=1024)
    a = ap.parse_args()
    binary = os.path.abspath(a.binary)
    # Under ASan the address-space limit cannot apply and everything runs several times slower.
    memory_mb = 0 if sanitized(binary) else a.memory_mb
    timeout = a.timeout * (3 if sanitized(binary) else 1)
    failures = []
    with tempfile.TemporaryDirectory(prefix="piezobench-hostile-") as tmp:
        cases = []
        for reader in sorted(os.listdir(a.corpus)):
            if reader in NOT_FILES:
                continue
            for f in sorted(os.listdir(os.path.join(a.corpus, reader))):
                cases.append((reader, f))
        for i, (reader, f) in enumerate(cases):
            work = os.path.join(tmp, str(i))
            os.makedirs(work)
            # valid_*: a good file; heavy_*: valid but costly (done or refused by a work bound).
            allowed = {0} if f.startswith("valid_") else {0, 2, 3, 4} if f.startswith("heavy_") else {2, 3, 4}
            check(binary, f"{reader}/{f}", command(reader, os.path.join(a.corpus, reader, f), work), allowed,
                  timeout, memory_mb, work, failures)
        # Cases that are not one file: command-line values, directories where files are expected.
        work = os.path.join(tmp, "extra")
        os.makedirs(work)
        for name, args, allowed in [
            ("rt rate 1e12", ["rt", "--bench", "virtual", "--gain", "1", "--rate", "1e12", "--realtime", "false"], {2}),
            ("rt gain 1e12", ["rt", "--bench", "virtual", "--gain", "1e12", "--duration", "0.3", "--realtime", "false"], {0}),
            ("rt duration 1e300", ["rt", "--bench", "virtual", "--gain", "1", "--duration", "1e300", "--realtime", "false"], {2, 3}),
            ("frf directory", ["frf", work, "--input", "u", "--output", "de", "--fs", "1000"], {2, 3}),
            ("plant directory", ["iff", "rlocus", "--plant", work], {2, 3}),
        ]:
            # The rt report holds timings: its exit code is compared, not its text.
            check(binary, name, args, allowed, timeout, memory_mb, work, failures, deterministic=not name.startswith("rt"))
        # An Ansys master listing whose out_NLIST.txt beside it is a directory (issue 21.6).
        se = os.path.join(tmp, "nlist")
        os.makedirs(os.path.join(se, "out_NLIST.txt"))
        seed = os.path.join(ROOT, "fuzz", "seeds", "ansys_text", "bar.txt")
        check(binary, "ansys out_NLIST.txt directory", ["superelement"] + split(seed, 3, ["k.txt", "m.txt", "master.txt"], se),
              {3}, timeout, memory_mb, se, failures)
    if failures:
        print(f"hostile_cli: {len(failures)} failing case(s):", file=sys.stderr)
        for f in failures:
            print("  " + f, file=sys.stderr)
        return 1
    print("hostile_cli: every case ended as it should")
    return 0


if __name__ == "__main__":
    sys.exit(main())
