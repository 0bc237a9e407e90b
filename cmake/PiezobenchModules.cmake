# The module map: the one list of which piezobench module may use which. CMake links each module to
# the modules listed here (piezobench_add_module reads this table; a src/<module>/CMakeLists.txt names
# only third-party libraries), scripts/check_module_deps.py checks every #include of src/,
# include/piezobench/ and tests/ against it (ctest: check_module_deps), and docs/design.md draws it.
#
# piezobench_module(<name> LAYER <n> [DEPS <modules...>] [DIR <folder>])
#   DEPS   the modules whose public headers (include/piezobench/<dep>/) the module's sources and
#          public headers include: every one of them, and no other (the check fails on an include of
#          a module not listed here, and on a listed module never included).
#   LAYER  a module uses modules of lower layers only, so the map has no cycle (checked too).
#   DIR    the folder of its sources when it is not src/<name> (rt_comedi lives in src/rt).
#   WRAPS  third-party headers only this module's library code includes: the module wraps that
#          library for the others (<matio.h> is io's; another module reads .mat files through io).
# A module's private headers (src/<module>/*.hpp) are visible to that module (and its tests) only.
#
# Layers and their rules (docs/design.md, "Modules"):
#   0 foundation   core: errors, numbers, formatting, files on disk, threads; no physics.
#   1 kernels      linear systems and metrology maths on the foundation only; no file formats.
#   2 domains      signals (dsp), structures (fem), the controller's plant model (plant).
#   3 estimation   ident: fits models of layer 2 to measured signals.
#   4 use          control (loops around the plant and the identified hysteresis); io (every file
#                  format of the types below: time series, FRFs, LTI and hysteresis TOML, JSON, .mat).
#   5 actuator     apa (2-DoF model, tuning, its TOML), report (the HTML page of a JSON document).
#   6 bench        the virtual bench (experiments, batch, twin).
#   7 programs     rt (the real-time loop and its backends), campaign (the offline pipeline).
#   8 station      the station (campaign + rt), rt_comedi (a card backend).
#   9 live page    web.

piezobench_module(core      LAYER 0)
piezobench_module(lti       LAYER 1 DEPS core)
piezobench_module(metrology LAYER 1 DEPS core)
piezobench_module(dsp       LAYER 2 DEPS core lti)
piezobench_module(fem       LAYER 2 DEPS core lti WRAPS cholmod.h)
piezobench_module(plant     LAYER 2 DEPS core lti)
piezobench_module(ident     LAYER 3 DEPS core lti dsp metrology plant)
piezobench_module(control   LAYER 4 DEPS core lti ident plant)
piezobench_module(io        LAYER 4 DEPS core lti dsp ident WRAPS matio.h hdf5.h)
piezobench_module(apa       LAYER 5 DEPS core lti dsp ident io)
piezobench_module(report    LAYER 5 DEPS core io)
piezobench_module(bench     LAYER 6 DEPS core lti dsp fem ident control io apa)
piezobench_module(rt        LAYER 7 DEPS core lti dsp ident control io bench)
piezobench_module(campaign  LAYER 7 DEPS core lti dsp fem ident control io apa metrology report bench)
piezobench_module(station   LAYER 8 DEPS core io metrology bench rt campaign WRAPS sqlite3.h)
piezobench_module(rt_comedi LAYER 8 DEPS core rt DIR rt WRAPS comedilib.h)
piezobench_module(web       LAYER 9 DEPS core dsp io report rt station WRAPS boost/)
