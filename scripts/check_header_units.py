#!/usr/bin/env python3
"""Lists the floating-point fields and parameters of the public headers that do not name their unit.

    python3 scripts/check_header_units.py [ROOT]            # exit 1 on a violation not in the baseline
    python3 scripts/check_header_units.py --all [ROOT]      # every violation, baseline or not
    python3 scripts/check_header_units.py --write-baseline  # rewrite scripts/header_units_baseline.txt

The rule (docs/design.md, "Conventions"): a `double` (or `float`, `Eigen::VectorXd`, `Vector`,
`std::vector<double>`) field or parameter of include/piezobench/ names its unit
  - in its name: a unit suffix (`fmin_Hz`, `duration_s`, `stiffness_N_per_m`, `gain_dB`), or
  - in the comment on its line or the comment block just above it (`double wz;  // rad/s`;
    "dimensionless", "ratio", "relative" count too, and so does a unit named by reference: "input
    unit", "output unit", "data units", "same unit as the values"), or
  - for a parameter, in the comment just above its declaration, on a line naming the parameter
    (`// omega in rad/s`), or
  - it is a dimensionless kind by name (`*_ratio`, `relative_*`, `damping`, `coherence`, `overlap`,
    `fraction`, `z`, `*_factor`, ...).
Headers of generic numerical methods, whose numbers carry the caller's units (core/least_squares.hpp,
core/minimize.hpp, ...), say so in their first comment block ("Units: the caller's") and are skipped.
ctest runs it (check_header_units; tests/scripts/check_header_units_test.py checks the checker).
The baseline (scripts/header_units_baseline.txt, one `header: name` a line) holds the violations
the headers had when the check came; a new one fails; a baseline line no header has any more is
named on stderr, to be removed (so the baseline only shrinks).
"""
import os
import re
import sys

FLOAT_TYPES = r"(?:double|float|Eigen::VectorXd|Eigen::ArrayXd|lti::Vector|Vector|std::vector<double>|std::optional<double>)"
# A unit written in a name, as the project spells them (docs/design.md, "Conventions").
UNIT_WORDS = (r"Hz|kHz|s|ms|us|ns|min|h|m|mm|um|nm|pm|m2|m3|V|mV|uV|kV|A|mA|N|kN|mN|kg|g|Pa|kPa|MPa|GPa|F|uF|nF|pF|"
              r"C|J|W|K|degC|dB|deg|rad|rads|rad_s|percent|pct|ppm|Vrms|V2|N2|m_s|m_s2|Hz2|V2_per_Hz|bits|counts|cycles|"
              r"samples|lines|points|decade|octave|dec|lsb|LSB|ohm|Ohm|S|H|T|sq|seconds|volts|metres|meters|hertz|newtons")
NAME_UNIT = re.compile(rf"(?:^|_)(?:{UNIT_WORDS})(?:_per_[A-Za-z0-9_]+)?$|_per_(?:{UNIT_WORDS})\d?$|_per_[A-Za-z0-9]+$")
# A unit written in a comment.
COMMENT_UNIT = re.compile(r"(?<![A-Za-z])(?:Hz|kHz|s|ms|us|ns|m|mm|um|nm|V|mV|A|N|kg|Pa|GPa|F|uF|nF|dB|deg|degrees|rad|"
                          r"rad/s|V/V|N/m|V/m|N/V|m/V|m/N|1/s|s\^-1|m/s|m/s\^2|K|W|J|C|ohm|%|ppm|LSB|counts?|"
                          r"samples?|dimensionless|ratio|fraction|relative|unitless|per unit|a count|SI|Hz\^-1|"
                          r"Ohm|kOhm|GB|MB|"
                          # A unit named by reference: generic code whose numbers carry another's unit.
                          r"(?:input|output|data|command|caller's|values'?) units?|same units? as)(?![A-Za-z])")
DIMENSIONLESS = re.compile(r"(^|_)(ratio|relative|rel|fraction|damping|zeta|coherence|overlap|factor|weight|weights|z|"
                           r"xz|xp|probability|confidence|quantile|alpha|beta|exponent|order|kurtosis|skew|r2|nrmse|"
                           r"correlation|efficiency|spread|robust_z|tolerance_relative|scale|fill|share|fit|misfit|"
                           r"chi2|dof|sigma_ratio|count|index|percentile|q|p|nmp|asymmetry|coverage)(_|$)")
FIELD = re.compile(rf"^\s*(?:static\s+)?(?:constexpr\s+)?(?:const\s+)?{FLOAT_TYPES}\s+([A-Za-z_][A-Za-z0-9_]*(?:\s*=\s*[^,;]+)?"
                   rf"(?:\s*,\s*[A-Za-z_][A-Za-z0-9_]*(?:\s*=\s*[^,;]+)?)*)\s*;\s*$")
PARAM = re.compile(rf"(?:[(,]\s*)(?:const\s+)?{FLOAT_TYPES}\s*&?\s+([A-Za-z_][A-Za-z0-9_]*)\s*(?=[,)=])")


def read_text(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


def names_unit(name):
    return bool(NAME_UNIT.search(name)) or bool(DIMENSIONLESS.search(name.lower()))


def comment_of(line):
    return line.split("//", 1)[1] if "//" in line else ""


def comments_above(lines, i):
    """The // comment lines just above line i, at its indentation (a declaration's contract; a
    comment indented further continues the line above's trailing comment)."""
    out = []
    indent = len(lines[i]) - len(lines[i].lstrip())
    j = i - 1
    while j >= 0 and lines[j].strip().startswith("//") and len(lines[j]) - len(lines[j].lstrip()) == indent:
        out.append(lines[j])
        j -= 1
    return out


def trailing_comment(lines, i):
    """The comment on line i and the comment-only lines that continue it below."""
    out = [comment_of(lines[i])]
    j = i + 1
    while out[0] and j < len(lines) and lines[j].strip().startswith("//"):
        out.append(lines[j])
        j += 1
    return " ".join(out)


def violations(path, rel):
    lines = read_text(path).splitlines()
    found = []
    head = " ".join(l for l in lines[:40] if l.strip().startswith("//"))
    if "Units: the caller's" in head:
        return found
    for i, line in enumerate(lines):
        code = line.split("//", 1)[0]
        m = FIELD.match(code)
        if m and "(" not in m.group(1):
            comment = trailing_comment(lines, i) + " ".join(comments_above(lines, i))
            for decl in m.group(1).split(","):
                name = decl.split("=")[0].strip().rstrip("_")
                if names_unit(name) or COMMENT_UNIT.search(comment):
                    continue
                found.append((rel, i + 1, name))
            continue
        if "(" not in code:
            continue
        above = comments_above(lines, i)
        for pm in PARAM.finditer(code):
            name = pm.group(1)
            if names_unit(name) or COMMENT_UNIT.search(comment_of(line)):
                continue
            word = re.compile(rf"(?<![A-Za-z0-9_`]){re.escape(name)}(?![A-Za-z0-9_])|`{re.escape(name)}`")
            if any(word.search(c) and COMMENT_UNIT.search(c) for c in above):
                continue
            found.append((rel, i + 1, name))
    return found


def scan(root):
    base = os.path.join(root, "include", "piezobench")
    found = []
    for dirpath, _, names in os.walk(base):
        for n in sorted(names):
            if n.endswith(".hpp"):
                path = os.path.join(dirpath, n)
                found += violations(path, os.path.relpath(path, root))
    return sorted(found)


def baseline_path(root):
    return os.path.join(root, "scripts", "header_units_baseline.txt")


def key(v):
    return f"{v[0]}: {v[2]}"


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    root = os.path.abspath(args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    found = scan(root)
    if "--write-baseline" in argv:
        with open(baseline_path(root), "w", encoding="utf-8") as f:
            f.write("# scripts/check_header_units.py: violations the public headers had when the check came.\n"
                    "# Fix one (a unit in its name or its comment) and remove its line; never add one.\n")
            for k in sorted({key(v) for v in found}):
                f.write(k + "\n")
        print(f"check_header_units: {len(found)} violation(s) written to the baseline", file=sys.stderr)
        return 0
    baseline = set()
    if os.path.isfile(baseline_path(root)):
        baseline = {l.strip() for l in read_text(baseline_path(root)).splitlines() if l.strip() and not l.startswith("#")}
    new = [v for v in found if key(v) not in baseline]
    stale = sorted(baseline - {key(v) for v in found})
    for v in (found if "--all" in argv else new):
        print(f"{v[0]}:{v[1]}: `{v[2]}` names no unit (in its name, its comment, or the comment above)"
              + ("" if key(v) not in baseline else " [baseline]"))
    for k in stale:  # not fatal: a header renamed in a parallel change must not fail the check
        print(f"scripts/header_units_baseline.txt: `{k}` names its unit now (or is gone): remove the line",
              file=sys.stderr)
    print(f"check_header_units: {len(found)} violation(s), {len(found) - len(new)} in the baseline, {len(new)} new, "
          f"{len(stale)} stale baseline line(s)", file=sys.stderr)
    return 1 if new else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
