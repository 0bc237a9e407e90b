#!/usr/bin/env python3
"""scripts/check_module_deps.py on a small fake tree: clean, then each kind of violation injected
(another module's private header, by its module path and by a relative path; a public header of a
module that is not a dependency; a wrapped library; a cycle; a dependency the code never uses; a
private header from the app; a stale map in docs/design.md)."""
import importlib.util
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "check_module_deps.py")
spec = importlib.util.spec_from_file_location("check_module_deps", SCRIPT)
checker = importlib.util.module_from_spec(spec)
spec.loader.exec_module(checker)

MAP = """# a comment piezobench_module(ignored LAYER 9)
piezobench_module(core     LAYER 0)
piezobench_module(io       LAYER 1 DEPS core WRAPS matio.h)
piezobench_module(ident    LAYER 1 DEPS core)
piezobench_module(campaign LAYER 2 DEPS core io)
"""

FILES = {
    "include/piezobench/core/error.hpp": "#pragma once\n",
    "src/core/error.cpp": '#include "piezobench/core/error.hpp"\n',
    "include/piezobench/io/timeseries.hpp": '#pragma once\n#include "piezobench/core/error.hpp"\n',
    "src/io/mat_file.hpp": "#pragma once\n#include <matio.h>\n",
    "src/io/timeseries.cpp": '#include "piezobench/io/timeseries.hpp"\n#include "mat_file.hpp"\n',
    "include/piezobench/ident/fit.hpp": '#pragma once\n#include <vector>\n#include "piezobench/core/error.hpp"\n',
    "src/ident/fit.cpp": '#include "piezobench/ident/fit.hpp"\n',
    "include/piezobench/campaign/unit.hpp": '#pragma once\n#include "piezobench/io/timeseries.hpp"\n',
    "src/campaign/unit.cpp": '#include "piezobench/campaign/unit.hpp"\n#include "piezobench/core/error.hpp"\n',
    "tests/io/timeseries_test.cpp": '#include "mat_file.hpp"\n#include <matio.h>\n',
    "tests/campaign/unit_test.cpp": '#include "piezobench/ident/fit.hpp"\n',
    "app/main.cpp": '#include "piezobench/campaign/unit.hpp"\n',
}


class FakeTree:
    def __init__(self, map_text=MAP):
        self.dir = tempfile.TemporaryDirectory()
        self.root = self.dir.name
        self.write("cmake/PiezobenchModules.cmake", map_text)
        for path, text in FILES.items():
            self.write(path, text)
        self.write("docs/design.md", self.docs())

    def write(self, path, text):
        full = os.path.join(self.root, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w", encoding="utf-8") as f:
            f.write(text)

    def append(self, path, text):
        with open(os.path.join(self.root, path), "a", encoding="utf-8") as f:
            f.write(text)

    def docs(self):
        table = checker.map_markdown(checker.parse_map(self.root))
        return f"# Design\n\n{checker.MAP_BEGIN}\n{table}\n{checker.MAP_END}\n"

    def run(self):
        """(exit code, stdout) of the script on the tree, as ctest runs it."""
        p = subprocess.run([sys.executable, SCRIPT, self.root], capture_output=True, text=True)
        return p.returncode, p.stdout


class CheckModuleDeps(unittest.TestCase):
    def tree(self, map_text=MAP):
        tree = FakeTree(map_text)
        self.addCleanup(tree.dir.cleanup)
        return tree

    def assert_fails(self, tree, *needles):
        code, out = tree.run()
        self.assertEqual(code, 1, out)
        for needle in needles:
            self.assertIn(needle, out)
        return out

    def test_clean_tree_passes(self):
        code, out = self.tree().run()
        self.assertEqual((code, out), (0, ""))

    def test_private_header_of_another_module_by_module_path(self):
        tree = self.tree()
        tree.append("src/campaign/unit.cpp", '#include "io/mat_file.hpp"\n')
        self.assert_fails(tree, 'src/campaign/unit.cpp:3: #include "io/mat_file.hpp": a private header of io')

    def test_private_header_of_another_module_by_relative_path(self):
        tree = self.tree()
        tree.append("include/piezobench/campaign/unit.hpp", '#include "../../../src/io/mat_file.hpp"\n')
        self.assert_fails(tree, "include/piezobench/campaign/unit.hpp:3:", "a private header of io")

    def test_private_header_of_another_module_from_its_tests_and_the_app(self):
        tree = self.tree()
        tree.append("tests/campaign/unit_test.cpp", '#include "io/mat_file.hpp"\n')
        tree.append("app/main.cpp", '#include "io/mat_file.hpp"\n')
        self.assert_fails(tree, "tests/campaign/unit_test.cpp:2:", "app/main.cpp:2:")

    def test_public_header_of_a_module_that_is_not_a_dependency(self):
        tree = self.tree()
        tree.append("src/campaign/unit.cpp", "#include <piezobench/ident/fit.hpp>\n")
        self.assert_fails(tree, "src/campaign/unit.cpp:3: #include <piezobench/ident/fit.hpp>: ident is not in "
                                "campaign's dependencies")
        tree = self.tree()
        tree.append("src/campaign/unit.cpp", '#include "piezobench/ident.hpp"\n')  # the umbrella header
        self.assert_fails(tree, "ident is not in campaign's dependencies")

    def test_wrapped_library_outside_its_module(self):
        tree = self.tree()
        tree.append("src/campaign/unit.cpp", "#include <matio.h>\n")
        self.assert_fails(tree, "src/campaign/unit.cpp:3: #include <matio.h>: matio.h is wrapped by io")

    def test_cycle_and_upward_dependency(self):
        tree = self.tree(MAP.replace("piezobench_module(core     LAYER 0)", "piezobench_module(core     LAYER 0 DEPS io)"))
        self.assert_fails(tree, "dependency cycle core -> io -> core", "core (layer 0) uses io (layer 1)")
        tree = self.tree(MAP.replace("LAYER 1 DEPS core WRAPS", "LAYER 3 DEPS core WRAPS"))
        self.assert_fails(tree, "campaign (layer 2) uses io (layer 3): a module uses lower layers only")

    def test_dependency_the_code_does_not_use(self):
        tree = self.tree(MAP.replace("LAYER 2 DEPS core io", "LAYER 2 DEPS core io ident"))
        self.assert_fails(tree, "campaign lists ident, which no file of src/campaign/ or include/piezobench/campaign/ "
                                "includes")

    def test_module_folder_without_a_row(self):
        tree = self.tree()
        tree.write("src/station/a.cpp", "\n")
        self.assert_fails(tree, "src/station/: a module folder without a row")

    def test_docs_map_out_of_date(self):
        tree = self.tree()
        tree.write("docs/design.md", tree.docs().replace("| 2 | campaign | core, io |", "| 2 | campaign | core |"))
        self.assert_fails(tree, "docs/design.md: its module map differs from cmake/PiezobenchModules.cmake")


if __name__ == "__main__":
    unittest.main()
