#!/usr/bin/python3
"""Prints what scipy.io.loadmat reads from a MAT file, as JSON (the reference reader of the MAT
tests: tests/io/mat_file_test.cpp checks that files piezobench writes read back exactly).

Every variable becomes {"class": C, "shape": [...], ...} with C one of "double", "logical", the
other numeric classes by numpy name, "char", "struct" or "cell":
  numeric  "re" (and "im" when complex): the values in MATLAB (column-major) order, non-finite
           values as the strings "nan", "inf", "-inf";
  char     "text";
  struct   "fields": the field names in order, "elements": one object per element (column-major)
           mapping each field to its value;
  cell     "cells": the cells in column-major order.

Usage: loadmat_json.py FILE.mat. Exit 77 when scipy is missing (the test then skips).
"""
import json
import math
import sys

try:
    import numpy as np
    import scipy.io
except ImportError:
    sys.exit(77)


def number(x):
    x = float(x)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x


def describe(v):
    if isinstance(v, np.ndarray) and v.dtype.names is not None:
        fields = list(v.dtype.names)
        elements = [{f: describe(e[f]) for f in fields} for e in v.flatten(order="F")]
        return {"class": "struct", "shape": list(v.shape), "fields": fields, "elements": elements}
    if isinstance(v, np.ndarray) and v.dtype == object:
        return {"class": "cell", "shape": list(v.shape), "cells": [describe(c) for c in v.flatten(order="F")]}
    if isinstance(v, np.ndarray) and v.dtype.kind == "U":
        return {"class": "char", "shape": list(v.shape), "text": "".join(v.flatten(order="F"))}
    a = np.asarray(v)
    names = {"float64": "double", "complex128": "double", "float32": "single", "complex64": "single", "bool": "logical"}
    out = {"class": names.get(a.dtype.name, a.dtype.name), "shape": list(a.shape)}
    flat = a.flatten(order="F")
    out["re"] = [number(x) for x in flat.real]
    if a.dtype.kind == "c":
        out["im"] = [number(x) for x in flat.imag]
    return out


def main():
    m = scipy.io.loadmat(sys.argv[1], squeeze_me=False, chars_as_strings=False)
    print(json.dumps({k: describe(v) for k, v in m.items() if not k.startswith("__")}))


if __name__ == "__main__":
    main()
