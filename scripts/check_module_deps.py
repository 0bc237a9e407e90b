#!/usr/bin/env python3
"""Checks every #include of the tree against the module map, cmake/PiezobenchModules.cmake.

    python3 scripts/check_module_deps.py [ROOT]          # exit 0: clean; 1: violations, listed
    python3 scripts/check_module_deps.py --print-map     # the map as docs/design.md draws it

ctest runs it (check_module_deps); tests/scripts/check_module_deps_test.py checks it on a small fake tree.
The rules (docs/design.md, "Modules"):
  map       every module has a row, every dependency is a row of a lower layer, no cycle;
  public    a file of module M (src/M/, include/piezobench/M/, include/piezobench/M.hpp) includes
            the public headers (piezobench/X/... or piezobench/X.hpp) of M and of the modules M
            lists in DEPS only; every module M lists is included by some file of M (the map says
            neither more nor less than the code);
  private   a private header (src/X/*.hpp) is included by files of X and by tests/X/ only, never
            through a path that leaves the including file's module ("../io/mat_file.hpp");
  wraps     a third-party header a module WRAPS (<matio.h>: io) is included by that module's
            library code only (src/, include/); tests and tools may read the same files with it;
  tests     tests/M/ may include any module's public headers (a test builds its inputs and reads
            its fixtures with any module) and M's private headers only;
  docs      docs/design.md holds the map this script prints, between its markers.
"""
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)
SOURCE_EXT = (".cpp", ".hpp", ".h", ".cc")
MAP_BEGIN = "<!-- module-map: scripts/check_module_deps.py --print-map -->"
MAP_END = "<!-- /module-map -->"


def read_text(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


def parse_map(root):
    """{name: {layer, deps, dir, wraps}} from the piezobench_module(...) rows, in their order."""
    path = os.path.join(root, "cmake", "PiezobenchModules.cmake")
    text = re.sub(r"#[^\n]*", "", read_text(path))
    modules = {}
    for body in re.findall(r"piezobench_module\(([^)]*)\)", text):
        words = body.split()
        row = {"layer": None, "deps": [], "dir": words[0], "wraps": []}
        key = None
        for w in words[1:]:
            if w in ("LAYER", "DEPS", "DIR", "WRAPS"):
                key = w
            elif key == "LAYER":
                row["layer"] = int(w)
            elif key == "DIR":
                row["dir"] = w
            elif key in ("DEPS", "WRAPS"):
                row[key.lower()].append(w)
        modules[words[0]] = row
    return modules


def check_map(modules, root):
    errors = []
    for name, row in modules.items():
        if row["layer"] is None:
            errors.append(f"cmake/PiezobenchModules.cmake: {name} has no LAYER")
            continue
        for dep in row["deps"]:
            if dep not in modules:
                errors.append(f"cmake/PiezobenchModules.cmake: {name} uses {dep}, which has no row")
            elif modules[dep]["layer"] is None or modules[dep]["layer"] >= row["layer"]:
                errors.append(f"cmake/PiezobenchModules.cmake: {name} (layer {row['layer']}) uses {dep} "
                              f"(layer {modules[dep]['layer']}): a module uses lower layers only")
    # Cycles, whatever the layers say (depth-first search, the cycle named).
    state = {}

    def visit(name, stack):
        state[name] = "open"
        for dep in modules[name]["deps"]:
            if dep not in modules:
                continue
            if state.get(dep) == "open":
                cycle = stack[stack.index(dep):] + [dep]
                errors.append("cmake/PiezobenchModules.cmake: dependency cycle " + " -> ".join(cycle))
            elif dep not in state:
                visit(dep, stack + [dep])
        state[name] = "done"

    for name in modules:
        if name not in state:
            visit(name, [name])
    src = os.path.join(root, "src")
    dirs = {row["dir"] for row in modules.values()}
    for d in sorted(os.listdir(src)) if os.path.isdir(src) else []:
        if os.path.isdir(os.path.join(src, d)) and d not in dirs:
            errors.append(f"src/{d}/: a module folder without a row in cmake/PiezobenchModules.cmake")
    for name, row in modules.items():
        if not os.path.isdir(os.path.join(src, row["dir"])):
            errors.append(f"cmake/PiezobenchModules.cmake: {name} has no folder src/{row['dir']}/")
    return errors


def files_under(path):
    if os.path.isfile(path):
        return [path]
    out = []
    for dirpath, _, names in os.walk(path):
        if "node_modules" in dirpath:
            continue
        out += [os.path.join(dirpath, n) for n in sorted(names) if n.endswith(SOURCE_EXT)]
    return sorted(out)


def includes(path):
    text = read_text(path)
    for m in INCLUDE.finditer(text):
        yield text.count("\n", 0, m.start()) + 1, m.group(1), m.group(2)


def check_files(modules, root):
    errors = []
    by_dir = {}  # folder -> the modules whose sources live there (rt: rt and rt_comedi)
    for name, row in modules.items():
        by_dir.setdefault(row["dir"], []).append(name)
    folder_names = {d: (d if d in modules else names[0]) for d, names in by_dir.items()}
    # The modules of a folder share its files: their union of DEPS is what the files may include.
    allowed = {d: set().union(*(modules[n]["deps"] for n in names)) for d, names in by_dir.items()}
    wrapped = {w: row["dir"] for row in modules.values() for w in row["wraps"]}
    used = {d: set() for d in by_dir}
    src = os.path.join(root, "src")

    def module_of_public(inc):
        parts = inc.split("/")
        if parts[0] != "piezobench" or len(parts) < 2:
            return None
        name = parts[1][:-4] if len(parts) == 2 and parts[1].endswith(".hpp") else parts[1]
        for d, names in by_dir.items():
            if name in names or name == d:
                return d
        return None

    def private_owner(path, kind, inc):
        """The module folder of a private header this include reaches, or None."""
        candidates = []
        if kind == '"':
            candidates.append(os.path.normpath(os.path.join(os.path.dirname(path), inc)))
        candidates.append(os.path.normpath(os.path.join(src, inc)))  # "io/mat_file.hpp" with src/ as include path
        for c in candidates:
            rel = os.path.relpath(c, src)
            if os.path.isfile(c) and not rel.startswith(".."):
                return rel.split(os.sep)[0]
        return None

    def scan(files, folder, role):
        """role: 'library' (src/, include/) or 'test' (tests/<folder>/)."""
        for path in files:
            rel_path = os.path.relpath(path, root)
            for line, kind, inc in includes(path):
                where = f"{rel_path}:{line}: #include {kind}{inc}{'>' if kind == '<' else kind}"
                dep = module_of_public(inc)
                if dep is not None:
                    if dep == folder:
                        continue
                    if role == "library":
                        used[folder].add(dep)
                        if not any(n in allowed[folder] for n in by_dir[dep]):
                            errors.append(f"{where}: {folder_names[dep]} is not in {folder}'s dependencies "
                                          f"(cmake/PiezobenchModules.cmake: {sorted(allowed[folder])})")
                    continue
                owner = private_owner(path, kind, inc)
                if owner is not None and owner != folder:
                    errors.append(f"{where}: a private header of {owner} (src/{owner}/), which only {owner} sees")
                    continue
                if role == "library" and kind == "<":
                    for header, w_folder in wrapped.items():
                        hit = inc.startswith(header) if header.endswith("/") else inc == header
                        if hit and w_folder != folder:
                            errors.append(f"{where}: {header} is wrapped by {w_folder} (WRAPS in "
                                          f"cmake/PiezobenchModules.cmake); use {w_folder}'s public API")

    for d in by_dir:
        library = files_under(os.path.join(src, d)) + files_under(os.path.join(root, "include", "piezobench", d))
        library += files_under(os.path.join(root, "include", "piezobench", d + ".hpp"))
        for name in by_dir[d]:
            if name != d:
                library += files_under(os.path.join(root, "include", "piezobench", name))
        scan(library, d, "library")
        scan(files_under(os.path.join(root, "tests", d)), d, "test")
    # Everything else (app/, python/, bench/, fuzz/, tests/ outside a module's folder) uses public
    # headers only.
    for other in ("app", "python", "bench", "fuzz", "tests"):
        base = os.path.join(root, other)
        for path in files_under(base):
            rel = os.path.relpath(path, base).split(os.sep)
            if other == "tests" and len(rel) > 1 and rel[0] in by_dir:
                continue
            rel_path = os.path.relpath(path, root)
            for line, kind, inc in includes(path):
                owner = private_owner(path, kind, inc)
                if owner is not None:
                    errors.append(f"{rel_path}:{line}: #include {inc}: a private header of {owner} (src/{owner}/)")
    for d, names in by_dir.items():
        if len(names) > 1:
            continue  # a shared folder (rt, rt_comedi): its files cannot tell which module uses what
        for dep in sorted(set(modules[names[0]]["deps"]) - used[d]):
            errors.append(f"cmake/PiezobenchModules.cmake: {names[0]} lists {dep}, which no file of "
                          f"src/{d}/ or include/piezobench/{d}/ includes (the map says more than the code)")
    return errors


def map_markdown(modules):
    lines = ["| layer | module | uses |", "|---|---|---|"]
    for name, row in sorted(modules.items(), key=lambda kv: (kv[1]["layer"] or 0, list(modules).index(kv[0]))):
        lines.append(f"| {row['layer']} | {name} | {', '.join(row['deps']) or '-'} |")
    return "\n".join(lines)


def check_docs(modules, root):
    path = os.path.join(root, "docs", "design.md")
    if not os.path.isfile(path):
        return []
    text = read_text(path)
    if MAP_BEGIN not in text or MAP_END not in text:
        return [f"docs/design.md: no module map between '{MAP_BEGIN}' and '{MAP_END}'"]
    drawn = text.split(MAP_BEGIN, 1)[1].split(MAP_END, 1)[0].strip()
    if drawn != map_markdown(modules):
        return ["docs/design.md: its module map differs from cmake/PiezobenchModules.cmake; "
                "paste `python3 scripts/check_module_deps.py --print-map` between its markers"]
    return []


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    root = os.path.abspath(args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    modules = parse_map(root)
    if "--print-map" in argv:
        print(map_markdown(modules))
        return 0
    errors = check_map(modules, root)
    if not errors:  # the file checks assume a well-formed map
        errors += check_files(modules, root)
    errors += check_docs(modules, root)
    for e in errors:
        print(e)
    print(f"check_module_deps: {len(modules)} modules, {len(errors)} violation(s)", file=sys.stderr)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
