"""piezobench from Python: characterize, model and damp amplified piezoelectric actuators.

The C++ library behind the `piezobench` command, with numpy arrays in and out:

    piezobench.lti       state space, transfer functions, zpk; responses, poles/zeros, c2d, root locus
    piezobench.dsp       Welch spectra, H1/H2 and coherence, excitation signals
    piezobench.ident     vector fitting, FRF features (NMP check), fits, peak picking, LSCF
    piezobench.control   IFF plant and controller, IFF root locus, the discrete IFF controller
    piezobench.apa       the 2-DoF APA model, its tuning to measured FRFs, piezo sensitivities
    piezobench.fem       super elements (Ansys, CalculiX, Matrix Market), modes, Craig-Bampton
    piezobench.io        time-series and FRF files (.mat v5/v7.3, .csv, UFF 58)
    piezobench.bench     the virtual test bench: units, experiments as arrays, linear models
    piezobench.campaign  run a campaign file; typed results with to_dict()

Units are SI (frequencies in rad/s unless a name ends in _Hz). Errors are
piezobench.InputError (bad data or argument: .source, .field, .expected, .found) and
piezobench.NumericalError (a method failed: .method, .retry_may_help). See docs/python.md.
"""

import sys as _sys

from ._errors import Error, InputError, NumericalError
from ._result import Result
from . import _core

__version__ = _core.__version__

lti = _core.lti
dsp = _core.dsp
ident = _core.ident
control = _core.control
apa = _core.apa
fem = _core.fem
io = _core.io
bench = _core.bench
campaign = _core.campaign

# Super elements are files too: io.read_super_element is fem.read_super_element.
io.read_super_element = fem.read_super_element

for _name in ("lti", "dsp", "ident", "control", "apa", "fem", "io", "bench", "campaign"):
    _sys.modules[f"{__name__}.{_name}"] = getattr(_core, _name)

__all__ = ["Error", "InputError", "NumericalError", "Result", "lti", "dsp", "ident", "control", "apa", "fem",
           "io", "bench", "campaign", "__version__"]
