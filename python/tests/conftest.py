"""pytest set-up: the module is taken from PYTHONPATH (ctest sets build/python); when it is not
importable from there, from build/python beside this source tree."""

import os
import sys

try:
    import piezobench  # noqa: F401
except ImportError:
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "build", "python"))
