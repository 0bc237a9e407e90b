#!/usr/bin/env python3
"""Writes the fuzzing seeds (fuzz/seeds/READER/) and the regression corpus of hostile files
(fuzz/regression/READER/) that CI replays every time (docs/fuzzing.md).

Seeds are small valid inputs in the layouts the readers accept; the fuzz runner adds the fixture
files of tests/fixtures (scipy .mat files, CalculiX dumps). The regression corpus holds the
reproducers of issue 21 and files like them; every one must end in exit 2, 3 or 4 (or 0 for a file
named valid_*; any of 0, 2, 3, 4 for heavy_*) within 20 s and 1 GB, never a signal, a sanitizer report or exit 1.

Multi-file readers (Ansys text, CalculiX, Matrix Market) take one input whose parts are separated
by lines "@@@@" (fuzz/readers_fuzz.cpp): K, M, DOF list (and for CalculiX the .inp).
Run from the repository root: python3 scripts/fuzz/make_corpus.py
"""
import os
import shutil

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
SEP = "\n@@@@\n"


def write(kind, reader, name, text):
    d = os.path.join(ROOT, "fuzz", kind, reader)
    os.makedirs(d, exist_ok=True)
    mode = "wb" if isinstance(text, bytes) else "w"
    with open(os.path.join(d, name), mode) as f:
        f.write(text)


def clean(kind):
    """Removes this script's folders of fuzz/KIND (udp_target's are make_udp_seeds.py's)."""
    top = os.path.join(ROOT, "fuzz", kind)
    for reader in os.listdir(top) if os.path.isdir(top) else []:
        if reader != "udp_target":
            shutil.rmtree(os.path.join(top, reader))


def seeds():
    clean("seeds")
    # LTI TOML: the three forms of docs/formats.md.
    write("seeds", "lti_toml", "tf.toml", "num = [0.64, 0.0]\nden = [1.0, 2.5]\ndelay = 200e-6\n")
    write("seeds", "lti_toml", "zpk.toml", "zeros = [0.0, [-1.0, 2.0], [-1.0, -2.0]]\n"
          "poles = [-12.5, [-10.0, 3000.0], [-10.0, -3000.0], -12566.4]\ngain = -10.0\n")
    write("seeds", "lti_toml", "ss.toml", "A = [[0.0, 1.0], [-4.0, -0.4]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\n"
          "D = [[0.0]]\nsample_time = 1e-4\ndescription = \"any text\"\n")
    # 2-DoF parameters (SI).
    write("seeds", "two_dof_toml", "params.toml", "m = 5.7\nk1 = 0.4e6\nc1 = 20.0\nke = 4.3e6\nce = 10.0\n"
          "ka = 2.5e6\nca = 10.0\nga = 23.2\ngs = -0.5e6\n")
    # Campaign (docs/campaign.md); the reader is fuzzed without checking that the files exist.
    write("seeds", "campaign_toml", "campaign.toml", """title = "seed"
[bench]
amplifier_gain = 20.0
suspended_mass_kg = 5.7
[specs]
stroke_min_um = 200.0
flatness_um = 5.0
stiffness_N_per_um = [1.5, 2.5]
[analysis]
window = "hann"
nfft = 4096
overlap = 0.5
fmin_Hz = 10.0
fmax_Hz = 1000.0
[channels]
u = "u_dac"
de = "d_enc"
Vs = "V_sensor"
[[units]]
id = 1
frf = { file = "apa1_frf.csv", channels = { u = "dac", de = "encoder", Vs = "force_sensor" } }
stroke = "stroke.mat"
capacitance_uF = { sensor = 5.10, actuator = 10.03 }
iff = [{ file = "iff1.mat", gain = 30000.0 }]
[[units]]
id = 2
stiffness = "k.mat"
[superelement]
k_file = "K.txt"
m_file = "M.txt"
nodes_file = "nodes.txt"
fix = [1]
actuator = "2:3:x"
output = "2:y"
masses = ["2:5.7"]
ga_N_per_V = 23.2
""")
    # Time series CSV (LabVIEW-style: a time column, units in brackets) and with a rate comment.
    rows = "\n".join(f"{k * 1e-4:.4f},{0.1 * ((k * 7) % 5 - 2):.3f},{1e-6 * k:.3e},{0.01 * (k % 3):.3f}" for k in range(16))
    write("seeds", "csv_timeseries", "labview.csv", "t [s],u [V],de [m],Vs [V]\n" + rows + "\n")
    write("seeds", "csv_timeseries", "rate.csv", "# sample_rate_Hz: 10000\nu,de,Vs\n" +
          "\n".join(f"{0.1 * (k % 4)},{1e-6 * k},{0.02 * (k % 2)}" for k in range(16)) + "\n")
    # FRF CSV (docs/cli.md).
    write("seeds", "csv_frf", "frf.csv", "freq_Hz,re_de,im_de,coh_de,re_Vs,im_Vs,coh_Vs\n" +
          "\n".join(f"{f},{1e-6 / (1 + f / 100)},{-1e-7 * f / 100},0.99,{0.5},{0.01 * f},0.98" for f in range(10, 200, 10)) + "\n")
    # UFF58 (ASCII, complex real/imag pairs, even abscissa): one function.
    n = 8
    lines = ["    -1", "    58", "u -> de", "NONE", "NONE", "NONE", "NONE",
             "    4         1    1         0       de         1   3       u          1   3",
             f"         5{n:10d}         1  1.00000E+01  1.00000E+01  0.00000E+00",
             "        18    0    0    0                 Frequency                   Hz",
             "         8    0    0    0                  Response                    m",
             "        13    0    0    0                  Input                       V",
             "         0    0    0    0                     NONE                  NONE"]
    vals = []
    for k in range(n):
        vals += [1e-6 / (1 + k), -1e-7 * k]
    for i in range(0, len(vals), 6):
        lines.append("".join(f"{v:13.5E}" for v in vals[i:i + 6]))
    lines.append("    -1")
    write("seeds", "uff58", "frf.uff", "\n".join(lines) + "\n")
    # Ansys CMS text: a 2-node bar (UX of nodes 1 and 2) plus one modal coordinate.
    k = "MAT_K:\n[1,1]: 2.0E+06 [1,2]: -1.0E+06 [1,3]: 0.0\n[2,1]: -1.0E+06 [2,2]: 2.0E+06 [2,3]: 0.0\n" \
        "[3,1]: 0.0 [3,2]: 0.0 [3,3]: 4.0E+06\n"
    m = "MAT_M:\n[1,1]: 1.0 [1,2]: 0.0 [1,3]: 0.0\n[2,1]: 0.0 [2,2]: 1.0 [2,3]: 0.0\n[3,1]: 0.0 [3,2]: 0.0 [3,3]: 1.0\n"
    listing = "    1  UX\n    2  UX\n\n    NODE     X      Y      Z\n    1   0.0  0.0  0.0\n    2   0.01  0.0  0.0\n"
    write("seeds", "ansys_text", "bar.txt", k + SEP[1:] + m + SEP[1:] + listing)
    # Matrix Market K, M and a piezobench DOF list.
    kmm = "%%MatrixMarket matrix coordinate real symmetric\n2 2 3\n1 1 2.0e6\n2 1 -1.0e6\n2 2 2.0e6\n"
    mmm = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1.0\n2 2 1.0\n"
    dofs = "1 UX 0.0 0.0 0.0\n2 UX 0.01 0.0 0.0\n"
    write("seeds", "matrix_market", "bar.txt", kmm + SEP[1:] + mmm + SEP[1:] + dofs)
    # CalculiX dumps: .sti, .mas, .dof, .inp with the node coordinates.
    sti = "1 1 2.0e6\n1 2 -1.0e6\n2 2 2.0e6\n"
    mas = "1 1 1.0\n2 2 1.0\n"
    dof = "1.1\n2.1\n"
    inp = "*NODE\n1, 0.0, 0.0, 0.0\n2, 0.01, 0.0, 0.0\n"
    write("seeds", "calculix", "bar.txt", sti + SEP[1:] + mas + SEP[1:] + dof + SEP[1:] + inp)


# A station whose phases need values in the answers (fuzz/station_fuzz.cpp reads it as its second station).
VALUES_STATION = """name = "values"
[[phases]]
name = "flatness"
experiment = "flatness"
source = "file"
steps = ["put the actuator on the probe's table"]
[[phases.measurements]]
name = "flatness_um"
max = 25.0
[[phases]]
name = "capacitance"
experiment = "capacitance"
source = "typed"
[[phases.measurements]]
name = "capacitance_sensor_uF"
min = 4.0
max = 6.0
"""


def station_seeds():
    """The station file and the answers file (docs/station.md): the docs' examples and a station of values."""
    for name, reader in (("station.toml", "station_toml"), ("station-answers.toml", "answers_toml")):
        with open(os.path.join(ROOT, "docs", "examples", name)) as f:
            write("seeds", reader, name, f.read())
    write("seeds", "station_toml", "values.toml", VALUES_STATION)
    write("seeds", "answers_toml", "values_answers.toml", 'operator = "B"\n[phases.flatness]\nsteps = ["confirm"]\n'
          'file = "probe.csv"\n[phases.capacitance]\nsensor_uF = 4.95\nactuator_uF = 9.9\non_check_fail = ["retry", "abort"]\n')


def station_regression():
    """Hostile station and answers files (issue 35: a parser for every new file the station reads)."""
    deep = ".a" * 20000
    for reader in ("station_toml", "answers_toml"):
        write("regression", reader, "deep_header.toml", "[a" + deep + "]\nx = 1\n")
        write("regression", reader, "deep_arrays.toml", "v = " + "[" * 5000 + "]" * 5000 + "\n")
        write("regression", reader, "not_toml.toml", "\x00\xff[[[\n= = =\n")
    top = 'name = "hostile"\n'  # the station's name, so that the reader gets to the phases
    phase = '[[phases]]\nname = "stroke"\nexperiment = "stroke"\n'
    write("regression", "station_toml", "retries_int64.toml", top + phase + "retries = 9223372036854775807\n")
    write("regression", "station_toml", "retries_float.toml", top + phase + "retries = 1e300\n")
    write("regression", "station_toml", "clamped_negative.toml", top + phase + "max_clamped_samples = -9223372036854775808\n")
    write("regression", "station_toml", "duration_1e300.toml",
          top + '[[phases]]\nname = "frf"\nexperiment = "frf-noise"\nduration_s = 1e300\namplitude_V = nan\n')
    write("regression", "station_toml", "limit_min_above_max.toml",
          top + phase + '[[phases.measurements]]\nname = "stroke_um"\nmin = 300.0\nmax = 200.0\n')
    write("regression", "station_toml", "measurement_of_another_experiment.toml",
          top + phase + '[[phases.measurements]]\nname = "k1_N_per_um"\n')
    write("regression", "station_toml", "phase_twice.toml", top + phase + phase)
    write("regression", "station_toml", "campaign_gain_zero.toml", top + "[campaign.bench]\namplifier_gain = 0\n" + phase)
    write("regression", "station_toml", "campaign_unknown_table.toml", top + "[campaign.units]\nid = 1\n" + phase)
    write("regression", "station_toml", "steps_not_text.toml", top + phase + "steps = [1, [2], {a = 3}]\n")
    write("regression", "answers_toml", "phase_typo.toml", '[phases.stroek]\nsteps = ["confirm"]\n')
    write("regression", "answers_toml", "steps_too_many.toml", '[phases.stroke]\nsteps = ["confirm", "confirm", "confirm"]\n')
    write("regression", "answers_toml", "step_word.toml", '[phases.stroke]\nsteps = ["yes"]\n')
    write("regression", "answers_toml", "phases_not_table.toml", 'phases = 3\n')
    write("regression", "answers_toml", "typed_1e308.toml",
          '[phases.capacitance]\nsensor_uF = 1e308\nactuator_uF = -inf\n')
    write("regression", "answers_toml", "file_outside.toml", '[phases.flatness]\nsteps = ["confirm"]\nfile = "/dev/zero"\n')


def regression():
    # Not cleaned: files the fuzzer found are added to fuzz/regression/READER/ by hand (docs/fuzzing.md).
    # 21.2: a table header / dotted key of 100,000 parts recursed 30,000 frames deep in toml++;
    # 20,000 parts keep the files small and are as far past the limit (64).
    deep = ".a" * 20000
    for reader in ("lti_toml", "two_dof_toml", "campaign_toml"):
        write("regression", reader, "deep_header.toml", "[a" + deep + "]\nx = 1\n")
        write("regression", reader, "deep_dotted_key.toml", "a" + deep + " = 1\n")
        write("regression", reader, "deep_inline_key.toml", "t = { a" + deep[:2000] + " = 1 }\n")
        write("regression", reader, "deep_arrays.toml", "v = " + "[" * 5000 + "]" * 5000 + "\n")
    # 21.3: C = -2.5e308 overflows; the balancing looped forever.
    write("regression", "lti_toml", "balance_overflow.toml", "num = [1e308, 0.0]\nden = [1.0, 2.5]\n")
    write("regression", "lti_toml", "balance_overflow_ss.toml",
          "A = [[0.0, 1e308], [-1e308, -1.0]]\nB = [[0.0], [1e308]]\nC = [[1e308, 1e-308]]\n")
    # 21.8: an integer beyond double precision ("expected a number, found a number").
    write("regression", "lti_toml", "int64_max.toml", "num = [9223372036854775807]\nden = [1.0, 2.5]\n")
    write("regression", "two_dof_toml", "int64_max.toml", "m = 9223372036854775807\nk1 = -9223372036854775808\n")
    write("regression", "campaign_toml", "int64_id.toml", "[[units]]\nid = 9223372036854775807\nstroke = \"s.mat\"\n")
    # 21.5: a 100,000-coefficient denominator ran out of memory in the state-space conversion;
    # 20,000 are as far past the cap (201).
    write("regression", "lti_toml", "den_20000.toml", "num = [1]\nden = [1" + ",1" * 20000 + "]\n")
    # 21.7: a 1,000-pole zpk (over 150 s in the root locus); a 30th-order transfer function.
    poles = ", ".join(f"[{-1.0 - (k // 2) % 7}, {100.0 * (k // 2 + 1) * (1 if k % 2 == 0 else -1)}]" for k in range(1000))
    write("regression", "lti_toml", "zpk_1000_poles.toml", f"zeros = [0.0]\npoles = [{poles}]\ngain = 1.0\n")
    den = ", ".join(f"{1.0 + 0.1 * k}" for k in range(31))
    write("regression", "lti_toml", "heavy_tf_order30.toml", f"num = [1.0, 0.0]\nden = [{den}]\n")
    # 21.5: a 26-byte Ansys file declaring a 15000 x 15000 matrix (1.77 GB before exit 3).
    master = "    1  UX\n    2  UX\n"
    write("regression", "ansys_text", "declared_15000.txt",
          "MAT_K:\n[15000,15000]: 1.0\n" + SEP[1:] + "MAT_M:\n[15000,15000]: 1.0\n" + SEP[1:] + master)
    write("regression", "ansys_text", "declared_100000.txt",
          "MAT_K:\n[1,1]: 1.0\n[100000,100000]: 1.0\n" + SEP[1:] + "MAT_M:\n[1,1]: 1.0\n" + SEP[1:] + master)
    write("regression", "ansys_text", "overflow_index.txt",
          "MAT_K:\n[9223372036854775807,1]: 1.0\n" + SEP[1:] + "MAT_M:\n[1,1]: 1.0\n" + SEP[1:] + master)
    # Matrix Market: a size line declaring 10^7 x 10^7 with 10^8 entries, two given.
    write("regression", "matrix_market", "declared_nnz.txt",
          "%%MatrixMarket matrix coordinate real symmetric\n10000000 10000000 100000000\n1 1 1.0\n2 2 1.0\n" + SEP[1:] +
          "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1.0\n2 2 1.0\n" + SEP[1:] + "1 UX\n2 UX\n")
    write("regression", "matrix_market", "dense_too_large.txt",
          "%%MatrixMarket matrix coordinate real symmetric\n9000000 9000000 1\n1 1 1.0\n" + SEP[1:] +
          "%%MatrixMarket matrix coordinate real symmetric\n9000000 9000000 1\n1 1 1.0\n" + SEP[1:] + "1 UX\n")
    # CalculiX: a .dof that is fine, K entries outside it, an *INCLUDE of a directory (21.6).
    write("regression", "calculix", "include_directory.txt",
          "1 1 1.0\n" + SEP[1:] + "1 1 1.0\n" + SEP[1:] + "1.1\n" + SEP[1:] + "*INCLUDE, INPUT=.\n")
    write("regression", "calculix", "index_overflow.txt",
          "1 99999999999999999999 1.0\n" + SEP[1:] + "1 1 1.0\n" + SEP[1:] + "1.1\n" + SEP[1:] + "*NODE\n1, 0, 0, 0\n")


# A twin as include/piezobench/bench/twin.hpp documents its layout (the 2-DoF values of the seed
# above, the report's chain: gain 20, 5.7 kg, a 10 kHz ADC with a 1 kHz filter), written by hand.
TWIN = """format = "piezobench-twin-1"
name = "APA 9"
unit = 9
[model]
k1 = 0.4e6
c1 = 20.0
ke = 4.3e6
ce = 10.0
ka = 2.5e6
ca = 10.0
ga = 23.2
gs = -0.5e6
[chain]
amplifier_gain_V_per_V = 20.0
suspended_mass_kg = 5.7
delay_s = 200e-6
hpf_resistance_ohm = 68e3
ground_resistance_ohm = 0.0
adc_bandwidth_Hz = 1000.0
sample_rate_Hz = 10000.0
capacitance_sensor_F = 5.1e-6
capacitance_actuator_F = 10.0e-6
[hysteresis]
thresholds_V = [10.0, 20.0, 30.0]
weights = [0.1, 0.05, 0.02]
[creep]
voltage_per_decade = 0.02
load_per_decade = 0.1
[noise]
de_m_rms = 2e-9
Vs_V_rms = 2.5e-3
"""


def twin_seeds():
    """The twin file (`simulate --twin`, `bench serve --twin`): the documented layout, with and without spectra."""
    write("seeds", "twin_toml", "apa9.toml", TWIN)
    write("seeds", "twin_toml", "apa9_spectra.toml", TWIN + "freq_Hz = [2.0, 20.0, 200.0]\nde_psd_m2_per_Hz = [1e-21, 1e-21, 1e-21]\n"
          "Vs_psd_V2_per_Hz = [1e-9, 1e-9, 1e-9]\n[sources]\nfrf = \"apa9_frf.csv\"\n")


def twin_regression():
    """Hostile twins: every one is refused (exit 3) before a bench is built from it."""
    def key(k, v):
        """The seed with key `k` (its first line `k = ...`) set to `v`."""
        lines = TWIN.splitlines(keepends=True)
        i = next(n for n, line in enumerate(lines) if line.startswith(k + " = "))
        lines[i] = f"{k} = {v}\n"
        return "".join(lines)
    write("regression", "twin_toml", "sample_rate_1e300.toml", key("sample_rate_Hz", "1e300"))
    write("regression", "twin_toml", "sample_rate_1e12.toml", key("sample_rate_Hz", "1e12"))   # a 1 s delay line of 10^12 samples
    write("regression", "twin_toml", "delay_1e300.toml", key("delay_s", "1e300"))
    write("regression", "twin_toml", "k1_nan.toml", key("k1", "nan"))
    write("regression", "twin_toml", "ga_inf.toml", key("ga", "-inf"))
    write("regression", "twin_toml", "unit_int64.toml", key("unit", "9223372036854775807"))
    write("regression", "twin_toml", "unit_1e300.toml", key("unit", "1e300"))
    write("regression", "twin_toml", "capacitance_negative.toml", key("capacitance_sensor_F", "-5.1e-6"))
    write("regression", "twin_toml", "thresholds_100.toml",
          key("thresholds_V", "[" + ", ".join(str(float(i + 1)) for i in range(100)) + "]"))
    write("regression", "twin_toml", "weights_short.toml", key("weights", "[0.1]"))
    write("regression", "twin_toml", "spectrum_mismatch.toml", TWIN + "freq_Hz = [2.0, 20.0]\nde_psd_m2_per_Hz = [1e-21]\n")
    write("regression", "twin_toml", "missing_chain.toml", TWIN.split("[chain]")[0] + "[hysteresis]\nthresholds_V = []\nweights = []\n")
    write("regression", "twin_toml", "name_bad_utf8.toml", key("name", '"APA \xff\xfe 9"').encode("latin-1"))
    write("regression", "twin_toml", "format_other.toml", key("format", '"piezobench-twin-2"'))
    write("regression", "twin_toml", "deep_arrays.toml", key("weights", "[" * 5000 + "]" * 5000))
    # Found by the fuzzer: -0.0 was written back as "-0", a TOML integer read as 0 (valid: exit 0).
    write("regression", "twin_toml", "valid_negative_zero.toml", key("ground_resistance_ohm", "-0.0"))


# The station's web server (fuzz/http_request_fuzz.cpp): requests to a server on 127.0.0.1:8080 as
# the tests (tests/web/http_server_test.cpp, station_site_test.cpp) and the page (station.js) send
# them. The harness opens prompt 1 of the capacitances (even input sizes) or of a file (odd).
HOST = "Host: 127.0.0.1:8080\r\n"
OPERATOR = "0123456789abcdef0123456789abcdef"
VIEW = "fedcba9876543210fedcba9876543210"


def get(target, extra=""):
    return f"GET {target} HTTP/1.1\r\n{HOST}Connection: close\r\n{extra}\r\n"


def post(body, parity=None, extra=f"Authorization: Bearer {OPERATOR}\r\n", target="/api/answer"):
    """A POST of `body`; padded with a space in the body to an even (capacitances) or odd (file) size."""
    def text(b):
        return f"POST {target} HTTP/1.1\r\n{HOST}{extra}Content-Type: application/json\r\nContent-Length: {len(b.encode('latin-1'))}\r\n\r\n{b}"
    if parity is not None and len(text(body).encode("latin-1")) % 2 != parity:
        body = " " + body
    return text(body)


def http_seeds():
    for name, target in (("page", "/"), ("state", "/api/state"), ("events", "/api/events"), ("script", "/station.js"),
                         ("qualifications", "/api/qualifications?batch=B1"), ("unit", "/api/units/SN1"),
                         ("certificate", "/api/certificate/SN1"), ("charts", "/api/charts")):
        write("seeds", "http_request", name + ".txt", get(target))
    write("seeds", "http_request", "head.txt", get("/").replace("GET", "HEAD", 1))
    write("seeds", "http_request", "origin.txt", get("/api/state", "Origin: http://127.0.0.1:8080\r\n"))
    write("seeds", "http_request", "view_token.txt", get(f"/api/state?token={VIEW}"))
    write("seeds", "http_request", "keep_alive.txt", get("/api/state").replace("close", "keep-alive") + get("/"))
    write("seeds", "http_request", "answer_no_values.txt", post('{"id": 1, "answer": "confirm"}'))
    write("seeds", "http_request", "answer_capacitances.txt",
          post('{"id": 1, "answer": "confirm", "values": {"sensor_uF": "5.1", "actuator_uF": "10.03"}}', parity=0))
    write("seeds", "http_request", "answer_file.txt", post('{"id": 1, "answer": "confirm", "values": {"file": "flatness.csv"}}', parity=1))
    write("seeds", "http_request", "answer_token_query.txt",
          post('{"id": 1, "answer": "confirm", "values": {"file": "f.csv"}}', parity=1, extra="", target=f"/api/answer?token={OPERATOR}"))


def http_regression():
    """Hostile requests: each is refused (4xx) or answered, never a crash or an exception."""
    w = lambda name, text: write("regression", "http_request", name, text.encode("latin-1") if isinstance(text, str) else text)
    for i, target in enumerate(("/../etc/passwd", "/a/%2e%2e/b", "/%2E%2E/x", "/api/units/..", "/api/units/%2e%2e",
                                "/api/certificate/..%2f..%2fetc%2fpasswd", "/a%00b", "/a\\..\\b", "/x/%2", "/x/%zz")):
        w(f"traversal_{i}.txt", get(target))
    w("header_9000.txt", get("/", "X-Pad: " + "a" * 9000 + "\r\n"))
    w("request_line_9000.txt", get("/" + "a" * 9000))
    w("headers_many.txt", get("/", "X: y\r\n" * 2000))
    w("content_length_huge.txt", f"POST /api/answer HTTP/1.1\r\n{HOST}Content-Length: 100000000\r\n\r\n")
    w("content_length_overflow.txt", f"POST /api/answer HTTP/1.1\r\n{HOST}Content-Length: 18446744073709551616\r\n\r\n{{}}")
    w("content_length_twice.txt", f"POST /api/answer HTTP/1.1\r\n{HOST}Content-Length: 2\r\nContent-Length: 3\r\n\r\n{{}}")
    w("chunk_overflow.txt", f"POST /api/answer HTTP/1.1\r\n{HOST}Authorization: Bearer {OPERATOR}\r\n"
      "Transfer-Encoding: chunked\r\n\r\nffffffffffffffffffff\r\n{}\r\n0\r\n\r\n")
    w("id_huge.txt", post('{"id": 1e400, "answer": "confirm"}'))
    w("id_uint64_overflow.txt", post('{"id": 18446744073709551616, "answer": "confirm"}'))
    w("id_negative.txt", post('{"id": -1, "answer": "confirm"}'))
    w("id_nan.txt", post('{"id": NaN, "answer": "confirm"}'))
    w("answer_missing.txt", post('{"id": 1}'))
    w("values_not_text.txt", post('{"id": 1, "answer": "confirm", "values": {"sensor_uF": 5.1, "actuator_uF": [10]}}', parity=0))
    for name, value in (("nan", "nan"), ("inf", "inf"), ("1e999", "1e999"), ("hex", "0x1p3"), ("empty", ""), ("space", " 5")):
        w(f"typed_{name}.txt", post(f'{{"id": 1, "answer": "confirm", "values": {{"sensor_uF": "{value}", "actuator_uF": "10"}}}}', parity=0))
    w("typed_file_traversal.txt", post('{"id": 1, "answer": "confirm", "values": {"file": "../../../etc/passwd"}}', parity=1))
    w("typed_bad_utf8.txt", post('{"id": 1, "answer": "confirm", "values": {"sensor_uF": "\xff\xfe", "actuator_uF": "10"}}', parity=0))
    w("body_deep.txt", post("[" * 3000 + "]" * 3000))
    w("body_bad_utf8.txt", post('{"id": 1, "answer": "confirm\xc3\x28"}'))
    w("post_no_token.txt", post('{"id": 1, "answer": "abort"}', extra=""))
    w("post_view_token.txt", post('{"id": 1, "answer": "abort"}', extra=f"Authorization: Bearer {VIEW}\r\n"))
    w("post_elsewhere.txt", post('{"id": 1, "answer": "abort"}', target="/api/state"))
    w("host_missing.txt", "GET / HTTP/1.1\r\nConnection: close\r\n\r\n")
    w("host_foreign.txt", "GET / HTTP/1.1\r\nHost: evil.example:8080\r\n\r\n")
    w("origin_foreign.txt", get("/", "Origin: http://evil.example\r\n"))
    w("method_delete.txt", get("/").replace("GET", "DELETE", 1))
    w("not_http.txt", "NONSENSE\r\n\r\n")
    w("nul_in_header.txt", get("/", "X-A: a\x00b\r\n"))
    w("bad_utf8_path.txt", get("/api/units/%ff%fe"))
    w("query_malformed.txt", get("/api/qualifications?batch=%zz&token"))
    w("serial_long.txt", get("/api/units/" + "A" * 900))
    w("truncated.txt", "GET / HTTP/1.1\r\nHost: 127.0")
    # Found by the fuzzer: a refusal quoting bytes that are not UTF-8 threw from the JSON writer,
    # which on the server's thread ended the process.
    w("not_utf8_path.txt", get("/" + "\xe2" * 40))
    w("not_utf8_path_escaped.txt", get("/%e2%ff"))
    w("not_utf8_host.txt", "GET /station.js HTTP/1.1\r\nHost: 127.0.0,1:" + "\xff" * 40 + "\r\n\r\n")
    w("not_utf8_origin.txt", get("/", "Origin: http://\xc3\x28\r\n"))


if __name__ == "__main__":
    seeds()
    station_seeds()
    twin_seeds()
    http_seeds()
    regression()
    station_regression()
    twin_regression()
    http_regression()
