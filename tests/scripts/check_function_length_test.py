#!/usr/bin/env python3
"""scripts/check_function_length.py on a fake tree: braces in strings, raw strings, characters and
comments do not count, a constructor's brace initialisers do not open its body, a function of 100
lines passes and one of 101 is listed with its name and line; the baseline keeps an old long function
as long as it does not grow, refuses a new one and names the ones split since."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "check_function_length.py")


def body(n):
    """n lines of statements full of braces that are not code."""
    pool = ['  s += "{{ not a brace";', "  c = '{';", "  // } a comment", '  s += R"x(}})x";',
            "  /* { */ ++k;", "  k += 1'000;"]
    return "\n".join(pool[k % len(pool)] for k in range(n))


def function(name, lines):
    """A definition of `lines` lines, signature and closing brace included."""
    return f"int {name}(int k) {{\n  std::string s; char c = 0;\n{body(lines - 4)}\n  return k;\n}}\n"


SOURCE = ("#include <string>\n#define OPEN {\nnamespace fake {\nnamespace {\n"
          + function("exactly_the_limit", 100)
          + "}  // namespace\n\n"
          "struct Holder {\n  Holder(int a) : a_{a}, b_(a) {\n" + body(99) + "\n  }\n  int a_, b_;\n};\n\n"
          "const auto table = std::string{\"}\"};\n"
          + function("too_long", 101) + "\n"
          "class Loop {\n public:\n  int cycle() noexcept\n  {\n" + body(120) + "\n    return 0;\n  }\n};\n"
          "}  // namespace fake\n")


def run(root, *flags):
    p = subprocess.run([sys.executable, SCRIPT, *flags, root], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


class CheckFunctionLength(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)
        self.root = self.dir.name
        for d in ("src/fake", "app", "python/src", "scripts", "tests/fake"):
            os.makedirs(os.path.join(self.root, d))
        self.source = os.path.join(self.root, "src", "fake", "fake.cpp")
        self.write(SOURCE)
        # Outside the checked folders: never listed.
        with open(os.path.join(self.root, "tests", "fake", "long_test.cpp"), "w", encoding="utf-8") as f:
            f.write(function("a_long_test", 300))

    def write(self, text):
        with open(self.source, "w", encoding="utf-8") as f:
            f.write(text)

    def test_lists_exactly_the_functions_over_100_lines(self):
        code, out, _ = run(self.root)
        self.assertEqual(code, 1)
        listed = out.splitlines()
        self.assertEqual(len(listed), 3, out)
        first_line = SOURCE.splitlines().index("int too_long(int k) {") + 1
        self.assertIn(f"src/fake/fake.cpp:{first_line}: `too_long` is 101 lines (over 100): split it into named steps",
                      listed)
        self.assertTrue(any("`Holder` is 101 lines" in l for l in listed), out)
        self.assertTrue(any("`cycle` is 124 lines" in l for l in listed), out)
        self.assertNotIn("exactly_the_limit", out)

    def test_top_lists_every_function_by_length(self):
        code, out, _ = run(self.root, "--top", "4")
        self.assertEqual(code, 0)
        self.assertEqual([l.split()[0] for l in out.splitlines()], ["124", "101", "101", "100"])
        self.assertTrue(out.splitlines()[3].endswith("exactly_the_limit"))

    def test_baseline_keeps_old_functions_refuses_growth_and_new_ones_and_names_split_ones(self):
        self.assertEqual(run(self.root, "--write-baseline")[0], 0)
        with open(os.path.join(self.root, "scripts", "function_length_baseline.txt"), encoding="utf-8") as f:
            self.assertIn("src/fake/fake.cpp: too_long 101\n", f.read())
        self.assertEqual(run(self.root)[:2], (0, ""))
        self.write(SOURCE.replace("int too_long(int k) {\n", "int too_long(int k) {\n  ++k;\n"))
        code, out, _ = run(self.root)
        self.assertEqual(code, 1)
        self.assertIn("`too_long` is 102 lines (over 100, its baseline says 101)", out)
        self.write(SOURCE + function("another", 150))
        code, out, _ = run(self.root)
        self.assertEqual((code, len(out.splitlines())), (1, 1))
        self.assertIn("`another` is 150 lines", out)
        self.write(SOURCE.replace(function("too_long", 101), function("too_long", 60)))
        code, out, err = run(self.root)
        self.assertEqual((code, out), (0, ""))  # split: named, not fatal
        self.assertIn("`src/fake/fake.cpp: too_long` is 100 lines or fewer now (or gone): remove the line", err)


if __name__ == "__main__":
    unittest.main()
