#!/usr/bin/env python3
"""Compares a results.json of `piezobench demo --seed 1` with the committed reference.

    scripts/compare_results.py REFERENCE NEW [--rtol 1e-5]

The reference (tests/fixtures/campaign/demo_seed1_results.json) was first written by piezobench
before the campaign's results became typed structs. A change that moves the demo's results on
purpose regenerates it with the Release build and says in its commit which values moved and why:
    piezobench demo --seed 1 --threads 2 --out /tmp/demo-seed1
    cp /tmp/demo-seed1/results.json tests/fixtures/campaign/demo_seed1_results.json
Every value of the reference must be in NEW under the
same key, or under its new name when RENAMES lists one; numbers agree to a relative tolerance
(|a - b| <= rtol max(|a|, |b|) + 1e-300), except the entries of a correlation matrix, whose scale
is 1 whatever their value (|a - b| <= rtol max(|a|, |b|, 1): a correlation of 7e-12 is 0 to every
digit that means something, and its last bits differ between CPUs), strings, booleans and nulls exactly. Keys only NEW has
(analyses added later) are listed, not refused. Keys that hold a machine path or the version are
not compared (IGNORED). Exit 0 when the documents agree, 1 with the differences otherwise,
2 on a bad command line or an unreadable file.
"""
import argparse
import json
import math
import re
import sys

# Documented renames: a dotted path of the reference (`*` = any list index or key) and its name in
# the new document. Empty: the typed results reproduce every key of the earlier results.json.
RENAMES: dict[str, str] = {}

# Paths that hold the run's machine path or the program version.
IGNORED = {"campaign", "provenance.campaign", "generator"}


def leaves(doc, path=""):
    """Yields (dotted path, value) for every scalar of doc; list items are `path[i]`."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from leaves(v, f"{path}.{k}" if path else k)
    elif isinstance(doc, list):
        if not doc:
            yield path, []
        for i, v in enumerate(doc):
            yield from leaves(v, f"{path}[{i}]")
    else:
        yield path, doc


def pattern(dotted):
    """A RENAMES key as a regex: `*` matches one key or list index."""
    parts = []
    for piece in re.split(r"(\*)", dotted):
        parts.append(r"([^.\[\]]+|\d+)" if piece == "*" else re.escape(piece))
    return re.compile("^" + "".join(parts) + "(?=$|[.\\[])")


def renamed(path):
    for old, new in RENAMES.items():
        m = pattern(old).match(path)
        if m:
            out = new
            for g in m.groups():
                out = out.replace("*", g, 1)
            return out + path[m.end():]
    return path


# Entries of a correlation matrix (scale 1, see above).
CORRELATION = re.compile(r"\.correlation\[\d+\]\[\d+\]$")


def same(a, b, rtol, scale=0.0):
    if isinstance(a, bool) or isinstance(b, bool) or a is None or b is None or isinstance(a, str) or isinstance(b, str):
        return a == b
    if isinstance(a, list) or isinstance(b, list):
        return a == b
    a, b = float(a), float(b)
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return abs(a - b) <= rtol * max(abs(a), abs(b), scale) + 1e-300


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("new")
    ap.add_argument("--rtol", type=float, default=1e-5)
    args = ap.parse_args()
    try:
        with open(args.reference) as f:
            ref = json.load(f)
        with open(args.new) as f:
            new = json.load(f)
    except (OSError, ValueError) as e:
        print(f"compare_results: {e}", file=sys.stderr)
        return 2
    new_leaves = dict(leaves(new))
    problems = []
    compared = 0
    for path, value in leaves(ref):
        if path.split("[")[0] in IGNORED or path in IGNORED:
            continue
        target = renamed(path)
        if target not in new_leaves:
            problems.append(f"missing: {path}" + (f" (renamed {target})" if target != path else "") + f" = {value!r}")
            continue
        compared += 1
        if not same(value, new_leaves[target], args.rtol, 1.0 if CORRELATION.search(path) else 0.0):
            problems.append(f"differs: {path}: reference {value!r}, new {new_leaves[target]!r}")
    ref_targets = {renamed(p) for p, _ in leaves(ref)}
    added = sorted({re.sub(r"\[\d+\]", "[]", p) for p in new_leaves if p not in ref_targets})
    for p in added:
        print(f"added (not in the reference): {p}")
    for p in problems:
        print(p)
    print(f"compare_results: {compared} values compared, {len(RENAMES)} documented renames, {len(added)} added keys, "
          f"{len(problems)} differences (rtol {args.rtol:g})")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
