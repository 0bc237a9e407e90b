#!/usr/bin/env python3
"""scripts/check_header_units.py on a fake header: the ways a field or parameter names its unit
pass, a bare one is listed, the baseline keeps old violations, refuses new ones and names the fixed ones."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "check_header_units.py")

HEADER = """#pragma once
// A fake module.
#include <vector>

struct Options {
  double fmin_Hz = 20.0;
  double duration_s = 1.0, stiffness_N_per_m = 1e6;
  double wz = 1.0;                 // rad/s, anti-resonance
  double overlap = 0.5;
  double damping_ratio = 0.01;
  // Thresholds of the play operators, in V.
  std::vector<double> thresholds;
  double creep = 0.0;              // per decade of time,
                                   // relative to the step
  double bare = 0.0;
  double a = 0.0, b_m = 0.0;       // (the comment names no unit)
  double trailing_ = 0.0;
  double y = 0.0;                  // output unit (the caller's)
};

// The response at omega (rad/s); `gain` in V/V.
double response(double omega, double gain, double bare_parameter);
double delayed(double delay_s, double bare_too);
"""


def run(root, *flags):
    p = subprocess.run([sys.executable, SCRIPT, *flags, root], capture_output=True, text=True)
    return p.returncode, p.stdout


class CheckHeaderUnits(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)
        self.root = self.dir.name
        os.makedirs(os.path.join(self.root, "include", "piezobench", "fake"))
        os.makedirs(os.path.join(self.root, "scripts"))
        self.header = os.path.join(self.root, "include", "piezobench", "fake", "options.hpp")
        with open(self.header, "w", encoding="utf-8") as f:
            f.write(HEADER)

    def listed(self, out):
        return sorted(line.split("`")[1] for line in out.splitlines() if "names no unit" in line)

    def test_lists_exactly_the_bare_fields_and_parameters(self):
        code, out = run(self.root)
        self.assertEqual(code, 1)
        self.assertEqual(self.listed(out), ["a", "bare", "bare_parameter", "bare_too", "trailing"])
        self.assertIn("include/piezobench/fake/options.hpp:15: `bare` names no unit", out)

    def test_baseline_keeps_old_violations_refuses_new_ones_and_names_fixed_ones(self):
        self.assertEqual(run(self.root, "--write-baseline")[0], 0)
        self.assertEqual(run(self.root), (0, ""))
        with open(self.header, "a", encoding="utf-8") as f:
            f.write("double another(double x);\n")
        code, out = run(self.root)
        self.assertEqual((code, self.listed(out)), (1, ["x"]))
        with open(self.header, "w", encoding="utf-8") as f:
            f.write(HEADER.replace("double bare = 0.0;", "double bare_V = 0.0;"))
        p = subprocess.run([sys.executable, SCRIPT, self.root], capture_output=True, text=True)
        self.assertEqual((p.returncode, p.stdout), (0, ""))  # fixed: named, not fatal
        self.assertIn("`include/piezobench/fake/options.hpp: bare` names its unit now (or is gone): remove the line",
                      p.stderr)

    def test_a_generic_header_is_skipped(self):
        with open(self.header, "w", encoding="utf-8") as f:
            f.write(HEADER.replace("// A fake module.", "// A fake module.\n// Units: the caller's."))
        self.assertEqual(run(self.root), (0, ""))


if __name__ == "__main__":
    unittest.main()
