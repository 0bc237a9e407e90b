#!/usr/bin/env python3
"""Lists the numbers of messages that do not go through the one formatter (core/format.hpp).

    python3 scripts/check_number_format.py [ROOT]          # exit 1 on a violation not in the allow-list
    python3 scripts/check_number_format.py --all [ROOT]    # every finding, allowed or not

The rule (issue 32 item 4, docs/design.md "Conventions"): a number in an error, warning or progress
message is written by `format_number` (what a person reads), `format_number_exact` (a value as the
user wrote it) or `format_number_fixed` (fixed decimals, beside a limit), never by
  1. `std::to_string` of a floating-point expression: it prints 1e-12 as "0.000000" and 1e9 as
     "1000000000.000000" (an integer may keep std::to_string);
  2. a hand-written floating format (`{:.3g}`, `{:g}`, `{:.2f}`, `%g`, ...) inside the arguments of
     a message: InputError, NumericalError, UsageError, add_problem, advise, warn, warnings.push_back,
     reasons.push_back, problems.push_back, or a `reason`, `why`, `warning`, `note` or `message`
     assigned (or appended) a fmt::format.
     Tables, reports and files keep their layouts: only these calls are looked at.
The type of a `std::to_string` argument is guessed without a compiler: it is floating when it holds a
floating literal, a complex part (`.real()`, `.imag()`), a <cmath> call, a `static_cast<double>`, or
ends in a name (a variable, member or getter, indexed or not) declared `double`, `float` or as a
vector of doubles in the same file, or else in a header of include/ or src/ while the file declares
no integer of that name. A finding that is an integer after all goes to the allow-list
scripts/number_format_allow.txt (`path: the call as written`), which only shrinks.
ctest runs it (check_number_format; tests/scripts/check_number_format_test.py checks the checker).
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_function_length import blank, read_text  # noqa: E402  (blank: comments and strings blanked out)

DIRS = ("src", "app", os.path.join("python", "src"), "include")
EXTENSIONS = (".cpp", ".cc", ".hpp", ".h")
ALLOW = os.path.join("scripts", "number_format_allow.txt")

FLOAT_DECL = r"(?:long\s+double|double|float)"
VECTOR_DECL = (r"(?:Eigen::VectorXd|Eigen::ArrayXd|Eigen::MatrixXd|VectorXd|ArrayXd|MatrixXd|lti::Vector|Vector|"
               r"std::vector<double>|std::vector<float>|std::span<const double>|std::span<double>)")
INT_DECL = (r"(?:int|long|unsigned|short|char|bool|size_t|std::size_t|ssize_t|Index|Eigen::Index|std::ptrdiff_t|"
            r"std::u?int\d+_t|u?int\d+_t|auto)")
FLOAT_SIGNS = re.compile(r"(?<![\w.])(?:\d+\.\d*|\.\d+|\d+(?:\.\d*)?[eE][-+]?\d+)(?![\w.])|\.real\(\)|\.imag\(\)|"
                         r"std::(?:abs|fabs|sqrt|cbrt|log|log10|log2|exp|pow|hypot|sin|cos|tan|atan2|arg|norm)\s*\(|"
                         r"static_cast<\s*(?:double|float)\s*>|\bkTwoPi\b|\bkPi\b")
# `a.b->c`, `*p`, `x.y()`, `v(k)`, `v[k]`: the last name, and whether it is indexed.
TAIL = re.compile(r"(\w+)\s*(\(\s*\)|\(\s*[^()]+\)|\[[^\[\]]+\])?\s*$")
MESSAGE_CALLS = re.compile(r"\b(InputError|NumericalError|UsageError|add_problem|advise|warn|warning|"
                           r"(?:warnings|reasons|problems)\s*\.\s*push_back|"
                           # a message assembled in its field: `v.reason = fmt::format(...)`
                           r"(?:reason|why|warning|note|message)\s*\+?=\s*fmt::format)\s*\(")
HAND_FORMAT = re.compile(r"\{[\w]*:[^{}]*[gGeEf]\}|%[-+ #0]*\d*(?:\.\d+)?[gGeEf]")


def closing(code, open_index):
    """The index of the `)` that closes the `(` at open_index in blanked code (or len(code))."""
    depth = 0
    for k in range(open_index, len(code)):
        if code[k] == "(":
            depth += 1
        elif code[k] == ")":
            depth -= 1
            if depth == 0:
                return k
    return len(code)


KINDS = (("float", FLOAT_DECL), ("vector", VECTOR_DECL), ("int", INT_DECL), ("int", r"std::vector<\s*\w+\s*>"))


TYPE_BEFORE = [(kind, re.compile(rf"(?<![\w:]){type_pattern}\s*[&*]?\s*(?:const\s+)?$")) for kind, type_pattern in KINDS]


def declarations(code, name, call=False):
    """The declarations of `name` (a function's when call) in blanked code: (index, kind) pairs, kind
    "float", "vector" (of doubles) or "int"."""
    out = []
    after = re.compile(r"\s*\(" if call else r"\s*(?:[;=,:){\[]|$)", re.M)
    for m in re.finditer(rf"(?<![\w.>:]){re.escape(name)}(?!\w)", code):
        if not after.match(code, m.end()):
            continue
        head = code[max(0, m.start() - 80):m.start()]
        for kind, pattern in TYPE_BEFORE:
            if pattern.search(head):
                out.append((m.start(), kind))
                break
    return out


class Headers:
    """The blanked text of every header of include/ and src/, read once."""

    def __init__(self, root):
        texts = []
        for top in ("include", "src"):
            for dirpath, _, names in os.walk(os.path.join(root, top)):
                for n in names:
                    if n.endswith((".hpp", ".h")):
                        texts.append(blank(read_text(os.path.join(dirpath, n))))
        self.code = "\n".join(texts)
        self.cache = {}

    def floating(self, name, indexed, call):
        k = (name, indexed, call)
        if k not in self.cache:
            self.cache[k] = floating_in(self.code, name, indexed, call)
        return self.cache[k]


def floating_in(code, name, indexed, call):
    """Whether the headers declare `name` floating (a vector of doubles when indexed) and never as an
    integer."""
    kinds = {k for _, k in declarations(code, name, call)}
    return "int" not in kinds and ("vector" if indexed else "float") in kinds


def is_floating(arg, at, code, headers):
    """The guess of whether the expression `arg` (blanked, at index `at` of `code`) has a
    floating-point type."""
    a = " ".join(arg.split())
    if FLOAT_SIGNS.search(a):
        return True
    m = TAIL.search(a)
    if not m:
        return False
    name, suffix = m.group(1), (m.group(2) or "").replace(" ", "")
    call = suffix == "()"
    indexed = bool(suffix) and not call
    local = declarations(code, name, call)
    if local:  # the nearest declaration above the call, else the first one below (a class member)
        before = [k for i, k in local if i < at]
        kind = before[-1] if before else local[0][1]
        return kind == ("vector" if indexed else "float")
    return headers.floating(name, indexed, call)


def line_of(text, index):
    return text.count("\n", 0, index) + 1


def findings_of(path, rel, headers):
    text = read_text(path)
    code = blank(text)
    found = []
    for m in re.finditer(r"\bstd::to_string\s*\(", code):
        open_index = m.end() - 1
        end = closing(code, open_index)
        if is_floating(code[open_index + 1:end], m.start(), code, headers):
            call = " ".join(text[m.start():end + 1].split())
            found.append((rel, line_of(text, m.start()), call, "std::to_string of a floating value"))
    for m in MESSAGE_CALLS.finditer(code):
        open_index = m.end() - 1
        end = closing(code, open_index)
        raw = text[open_index:end + 1]
        for f in HAND_FORMAT.finditer(raw):
            # Only inside string literals: the blanked code has spaces where the raw text has the format.
            at = open_index + f.start()
            if code[at:at + len(f.group(0))].strip():
                continue
            found.append((rel, line_of(text, at), f"{m.group(1)}(... \"{f.group(0)}\" ...)",
                          "a hand-written number format in a message"))
    return found


def scan(root):
    headers = Headers(root)
    found = []
    for top in DIRS:
        for dirpath, _, names in os.walk(os.path.join(root, top)):
            for n in sorted(names):
                if n.endswith(EXTENSIONS):
                    path = os.path.join(dirpath, n)
                    found += findings_of(path, os.path.relpath(path, root), headers)
    return sorted(found)


def key(v):
    return f"{v[0]}: {v[2]}"


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    root = os.path.abspath(args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    found = scan(root)
    allow = set()
    allow_file = os.path.join(root, ALLOW)
    if os.path.isfile(allow_file):
        allow = {l.strip() for l in read_text(allow_file).splitlines() if l.strip() and not l.startswith("#")}
    new = [v for v in found if key(v) not in allow]
    stale = sorted(allow - {key(v) for v in found})
    for v in (found if "--all" in argv else new):
        print(f"{v[0]}:{v[1]}: {v[3]}: {v[2]} (use format_number / format_number_exact of core/format.hpp)"
              + (" [allowed]" if key(v) in allow else ""))
    for k in stale:
        print(f"{ALLOW}: `{k}` is not found any more: remove the line", file=sys.stderr)
    print(f"check_number_format: {len(found)} finding(s), {len(found) - len(new)} allowed, {len(new)} new, "
          f"{len(stale)} stale allow-list line(s)", file=sys.stderr)
    return 1 if new else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
