#!/usr/bin/env python3
"""Lists the function definitions of src/, app/ and python/src/ longer than 100 lines.

    python3 scripts/check_function_length.py [ROOT]            # exit 1 on a violation not in the baseline
    python3 scripts/check_function_length.py --all [ROOT]      # every function over the limit, baseline or not
    python3 scripts/check_function_length.py --top N [ROOT]    # the N longest functions, whatever their length
    python3 scripts/check_function_length.py --write-baseline  # rewrite scripts/function_length_baseline.txt

The rule (issue 32 item 5, docs/design.md "Conventions"): a function reads top to bottom, a short
sequence of named steps; none is over 100 lines. A function's length runs from the line of its name
to the line of its closing brace. Definitions are found by brace matching on the code with comments,
string literals (raw ones too), character literals and preprocessor lines blanked out: a `{` at
namespace or class scope whose declaration has a parameter list opens a function body (a constructor's
member initialisers `x_{a}` are skipped); everything inside it, lambdas and local classes included,
counts toward that function.
ctest runs it (check_function_length; tests/scripts/check_function_length_test.py checks the checker).
The baseline (scripts/function_length_baseline.txt, one `path: name lines` a line) holds the long
functions being split elsewhere; a baselined function may not grow past its recorded length, a new
long one fails, and a line whose function is short now (or gone) is named on stderr, to be removed
(so the baseline only shrinks).
"""
import os
import re
import sys

LIMIT = 100
DIRS = ("src", "app", os.path.join("python", "src"))
EXTENSIONS = (".cpp", ".cc", ".hpp", ".h")
BASELINE = os.path.join("scripts", "function_length_baseline.txt")


def read_text(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


def blank(text):
    """The text with comments, string and character literals and preprocessor lines replaced by
    spaces (newlines kept, so offsets and line numbers stay those of the file)."""
    out = list(text)
    n = len(text)
    i = 0
    line_start = True

    def wipe(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if c == "\n":
            line_start = True
            i += 1
            continue
        if line_start and c in " \t":
            i += 1
            continue
        if line_start and c == "#":  # a preprocessor line, with its continuations
            j = i
            while j < n and not (text[j] == "\n" and text[j - 1] != "\\"):
                j += 1
            wipe(i, j)
            i = j
            continue
        line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            wipe(i, j)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            wipe(i, j)
            i = j
        elif c == "R" and i + 1 < n and text[i + 1] == '"' and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")
                                                                 or text[i - 1] in "uU8L"):
            m = re.match(r'R"([^ ()\\\t\n]{0,16})\(', text[i:])
            if not m:
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i + m.end())
            j = n if end < 0 else end + len(m.group(1)) + 2
            wipe(i + 1, j)
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum() and text[i - 1:i + 2] != "u8'")):
            # A ' right after a digit or letter is a digit separator (1'000), not a character literal.
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            wipe(i + 1, j - 1)
            i = j
        else:
            i += 1
    return "".join(out)


NAME_BEFORE_PAREN = re.compile(r"((?:[A-Za-z_]\w*\s*(?:<[^<>()]*>)?\s*::\s*)*~?(?:operator\s*(?:\(\)|[^\s(\w]+|\w[\w\s:<>*&]*)|[A-Za-z_]\w*))\s*$")


def top_level_paren(head):
    """The index of the parameter list's `(` in a declaration: the first `(` outside `<...>` that
    follows a name (not the one of `operator()`), or -1."""
    depth_angle = 0
    i = 0
    while i < len(head):
        c = head[i]
        if head.startswith("operator", i) and not (i > 0 and (head[i - 1].isalnum() or head[i - 1] == "_")):
            rest = head[i + 8:].lstrip()
            if rest.startswith("()"):
                i = head.index("()", i + 8) + 2
                continue
            if rest[:1] in "<>":  # operator<, operator<=>, operator>>
                i = head.index(rest[0], i + 8) + 1
                while i < len(head) and head[i] in "<>=":
                    i += 1
                continue
        if c == "<":
            depth_angle += 1
        elif c == ">" and depth_angle:
            depth_angle -= 1
        elif c == "(" and depth_angle == 0:
            return i
        i += 1
    return -1


def classify(head):
    """What a `{` at namespace or class scope opens, from the declaration before it:
    ('function', name) | ('scope', None) for a namespace, class or extern block | ('other', None)."""
    h = " ".join(head.split())
    h = re.sub(r"\[\[.*?\]\]", " ", h).strip()
    if re.match(r"^(inline\s+)?namespace\b", h) or re.match(r"^extern\s*$", h):
        return "scope", None
    p = top_level_paren(h)
    if p >= 0:
        before = h[:p]
        if re.search(r"(?<![<>!=+\-*/%&|^])=(?!=)", before.replace("operator=", "operator")) and "operator" not in before:
            return "other", None  # a variable initialised by a call: `const auto x = make({...`
        if re.match(r"^(template\s*<.*>\s*)?(class|struct|union|enum)\b", h) and not re.search(r"\)\s*[\w\s]*$", h):
            return "scope", None
        m = NAME_BEFORE_PAREN.search(before)
        if m:
            return "function", " ".join(m.group(1).split())
        return "other", None
    if re.search(r"\b(class|struct|union)\b", h) and "=" not in h:
        return "scope", None
    return "other", None


def functions(text):
    """(name, first line, last line) of each function definition of a C++ text."""
    code = blank(text)
    line_of = [0] * (len(code) + 1)
    ln = 1
    for k, ch in enumerate(code):
        line_of[k] = ln
        if ch == "\n":
            ln += 1
    line_of[len(code)] = ln
    found = []
    stack = []          # kinds of the open braces: 'scope', 'function', 'other'
    head_start = 0      # where the current declaration at namespace/class scope begins
    fn = None           # (name, first line, depth) of the function being read
    init_depth = 0      # braces of a constructor's member initialisers (`x_{a}`) being skipped
    i = 0
    n = len(code)
    while i < n:
        c = code[i]
        at_scope = fn is None and all(k == "scope" for k in stack)
        if c == "{":
            if at_scope and init_depth == 0:
                head = code[head_start:i]
                kind, name = classify(head)
                if kind == "function":
                    close = head.rfind(")")
                    after = head[close + 1:] if close >= 0 else ""
                    # Inside a constructor's initialiser list a `{` right after a name initialises a member.
                    if re.match(r"^\s*(?:noexcept\s*)?:(?!:)", after) and re.search(r"[\w>]\s*$", head) \
                            and not re.search(r"\)\s*$", head):
                        init_depth = 1
                        i += 1
                        continue
                    p = top_level_paren(" ".join(head.split()))
                    name_pos = head_start + head.find(name.split("::")[-1].split()[0]) if name else head_start
                    fn = (name, line_of[max(name_pos, head_start)], len(stack))
                    stack.append("function")
                else:
                    stack.append(kind)
                    head_start = i + 1
            elif init_depth:
                init_depth += 1
            else:
                stack.append("other")
        elif c == "}":
            if init_depth:
                init_depth -= 1
                if init_depth == 1:
                    init_depth = 0
                i += 1
                continue
            if stack:
                stack.pop()
            if fn is not None and len(stack) == fn[2]:
                found.append((fn[0], fn[1], line_of[i]))
                fn = None
            if fn is None and all(k == "scope" for k in stack):
                head_start = i + 1
        elif c == ";" and at_scope and init_depth == 0:
            head_start = i + 1
        i += 1
    return found


def scan(root):
    """(path, name, first line, lines) of every function definition under the checked folders."""
    out = []
    for d in DIRS:
        base = os.path.join(root, d)
        for dirpath, dirnames, names in os.walk(base):
            dirnames.sort()
            for nm in sorted(names):
                if nm.endswith(EXTENSIONS):
                    path = os.path.join(dirpath, nm)
                    rel = os.path.relpath(path, root).replace(os.sep, "/")
                    for name, first, last in functions(read_text(path)):
                        out.append((rel, name, first, last - first + 1))
    return out


def read_baseline(root):
    """{`path: name`: lines} of the baseline."""
    path = os.path.join(root, BASELINE)
    found = {}
    if os.path.isfile(path):
        for line in read_text(path).splitlines():
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            key, _, lines = line.rpartition(" ")
            found[key] = int(lines)
    return found


def main(argv):
    args = []
    top = None
    k = 0
    while k < len(argv):
        if argv[k] == "--top":
            top = int(argv[k + 1])
            k += 2
            continue
        if not argv[k].startswith("--"):
            args.append(argv[k])
        k += 1
    root = os.path.abspath(args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    every = scan(root)
    if top is not None:
        for path, name, first, lines in sorted(every, key=lambda f: -f[3])[:top]:
            print(f"{lines:5d} {path}:{first}: {name}")
        return 0
    long = [f for f in every if f[3] > LIMIT]
    longest = {}
    for path, name, first, lines in long:
        key = f"{path}: {name}"
        longest[key] = max(longest.get(key, 0), lines)
    if "--write-baseline" in argv:
        with open(os.path.join(root, BASELINE), "w", encoding="utf-8") as f:
            f.write("# scripts/check_function_length.py: functions over 100 lines being split (`path: name lines`).\n"
                    "# Split one and remove its line; never add one, never raise a length.\n")
            for key in sorted(longest):
                f.write(f"{key} {longest[key]}\n")
        print(f"check_function_length: {len(longest)} function(s) written to the baseline", file=sys.stderr)
        return 0
    baseline = read_baseline(root)
    bad = 0
    for path, name, first, lines in sorted(long, key=lambda f: (f[0], f[2])):
        key = f"{path}: {name}"
        allowed = baseline.get(key)
        if allowed is not None and lines <= allowed:
            if "--all" in argv:
                print(f"{path}:{first}: `{name}` is {lines} lines (over {LIMIT}) [baseline]")
            continue
        bad += 1
        grown = f", its baseline says {allowed}" if allowed is not None else ""
        print(f"{path}:{first}: `{name}` is {lines} lines (over {LIMIT}{grown}): split it into named steps")
    stale = sorted(k for k in baseline if k not in longest)
    for key in stale:  # not fatal: a function split in a parallel change must not fail the check
        print(f"{BASELINE}: `{key}` is {LIMIT} lines or fewer now (or gone): remove the line", file=sys.stderr)
    print(f"check_function_length: {len(long)} function(s) over {LIMIT} lines, {len(long) - bad} in the baseline, "
          f"{bad} not, {len(stale)} stale baseline line(s)", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
