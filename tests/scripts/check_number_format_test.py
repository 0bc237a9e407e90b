#!/usr/bin/env python3
"""scripts/check_number_format.py on a fake tree: std::to_string of a floating expression and a
hand-written float format inside a message are listed, integers, tables and the formatter pass, the
allow-list keeps a listed finding and names a line nothing matches any more."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "check_number_format.py")

HEADER = """#pragma once
struct Options {
  double tolerance = 1e-12;  // relative
  int max_iterations = 10;
  double rate() const;
};
"""

SOURCE = """#include "options.hpp"
#include <cmath>
#include <complex>
#include <vector>

void check(const Options& o, double gain, int count, std::complex<double> s, const Eigen::VectorXd& freq_Hz,
           const std::vector<int>& ids) {
  throw InputError("", "gain", "a gain", std::to_string(gain));              // floating parameter
  throw InputError("", "n", "a count", std::to_string(count));               // integer: passes
  throw InputError("", "tol", "> 0", std::to_string(o.tolerance));           // member of a header
  throw InputError("", "rate", "> 0", std::to_string(o.rate()));             // getter of a header
  throw InputError("", "it", ">= 1", std::to_string(o.max_iterations));      // integer member: passes
  throw NumericalError("f", "pole at " + std::to_string(s.real()));          // complex part
  throw InputError("", "f", "rising", std::to_string(freq_Hz(3)));           // element of a vector
  throw InputError("", "id", "a unit", std::to_string(ids[0]));              // element of ints: passes
  throw InputError("", "x", "x", std::to_string(2.5 * count));               // floating literal
  throw InputError("", "x", "x", format_number(gain));                        // the formatter: passes
  quality.add_problem(fmt::format("residual {:.3g} %", 100.0 * gain));        // hand format in a message
  table += fmt::format("{:>10.3f}", gain);                                     // a table: passes
  throw InputError("", "x", fmt::format("at most {} points", count), "{:g}"); // a format in the found text
  for (const int k : ids) s += std::to_string(k);                              // range-for integer: passes
  v.reason = fmt::format("phase change {:.1f} deg", gain);                     // a message assembled in its field
  v.reason = fmt::format("phase change {} deg", format_number_fixed(gain, 1)); // the formatter: passes
}
"""


def run(root, *flags):
    p = subprocess.run([sys.executable, SCRIPT, *flags, root], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


class CheckNumberFormat(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)
        self.root = self.dir.name
        os.makedirs(os.path.join(self.root, "src", "fake"))
        os.makedirs(os.path.join(self.root, "scripts"))
        for name, text in (("options.hpp", HEADER), ("fake.cpp", SOURCE)):
            with open(os.path.join(self.root, "src", "fake", name), "w", encoding="utf-8") as f:
                f.write(text)

    def lines(self, out):
        return sorted(int(line.split(":")[1]) for line in out.splitlines() if line.startswith("src/fake/fake.cpp:"))

    def test_lists_exactly_the_floating_to_string_and_the_message_formats(self):
        code, out, _ = run(self.root)
        self.assertEqual(code, 1)
        # The last message's "{:g}" is a string literal of the message, so it is listed too: a format is a format.
        self.assertEqual(self.lines(out), [8, 10, 11, 13, 14, 16, 18, 20, 22])
        self.assertIn("src/fake/fake.cpp:8: std::to_string of a floating value: std::to_string(gain)", out)
        self.assertIn("src/fake/fake.cpp:18: a hand-written number format in a message: add_problem(... \"{:.3g}\" ...)", out)

    def test_the_allow_list_keeps_a_finding_and_names_a_stale_line(self):
        with open(os.path.join(self.root, "scripts", "number_format_allow.txt"), "w", encoding="utf-8") as f:
            f.write("# comment\nsrc/fake/fake.cpp: std::to_string(gain)\nsrc/fake/gone.cpp: std::to_string(x)\n")
        code, out, err = run(self.root)
        self.assertEqual(code, 1)
        self.assertNotIn(":8:", out)
        self.assertIn("src/fake/gone.cpp: std::to_string(x)", err)
        code, out, _ = run(self.root, "--all")
        self.assertIn("std::to_string(gain) (use format_number / format_number_exact of core/format.hpp) [allowed]", out)

    def test_a_clean_tree_passes(self):
        with open(os.path.join(self.root, "src", "fake", "fake.cpp"), "w", encoding="utf-8") as f:
            f.write(SOURCE.replace("std::to_string(", "format_number(").replace("{:.3g}", "{}").replace('"{:g}"', '"x"')
                    .replace("{:.1f}", "{}"))
        code, out, _ = run(self.root)
        self.assertEqual((code, out), (0, ""))


if __name__ == "__main__":
    unittest.main()
