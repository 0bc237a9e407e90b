// piezobench.dsp: include/piezobench/dsp/*.hpp
#include "common.hpp"
#include "described.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/dsp/excitation.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/dsp/window.hpp"

namespace piezobench::python {
namespace {

using namespace piezobench::dsp;
using Eigen::Index;

const Options<WelchOptions>& welch_options() {
  static const Options<WelchOptions> t = [] {
    Options<WelchOptions> o("WelchOptions");
    o.add_enum("window", &WelchOptions::window, &dsp::to_string, &window_type_from_string,
               "\"hann-periodic\" (scipy's \"hann\"), \"hann-symmetric\", \"hamming-periodic\", ..., \"rectangular\"")
        .add("nfft", &WelchOptions::nfft, "segment length = FFT length, samples (>= 2)")
        .add("overlap", &WelchOptions::overlap,
             "fraction of nfft shared by consecutive segments, in [0, 1) (scipy noverlap = floor(overlap*nfft))")
        .add_enum("detrend", &WelchOptions::detrend, &dsp::to_string, &detrend_from_string,
                  "\"none\", \"mean\" (scipy \"constant\", its default) or \"linear\"")
        .add_enum("estimator", &WelchOptions::estimator, &dsp::to_string, &frf_estimator_from_string,
                  "\"H1\" (Suy/Suu) or \"H2\" (Syy/Syu), for frf()")
        .add("threads", &WelchOptions::threads, "worker threads; 0 = all cores");
    return o;
  }();
  return t;
}

const Options<VoltageBounds>& bounds_options() {
  static const Options<VoltageBounds> t = [] {
    Options<VoltageBounds> o("VoltageBounds");
    o.add("min", &VoltageBounds::min, "V, lowest sample")
        .add("max", &VoltageBounds::max, "V, highest sample")
        .add_enum("policy", &VoltageBounds::policy, &dsp::to_string, &bounds_policy_from_string,
                  "\"scale\" the varying part, \"clip\" samples, or \"reject\" (InputError)");
    return o;
  }();
  return t;
}

const Options<NoiseOptions>& noise_options() {
  static const Options<NoiseOptions> t = [] {
    Options<NoiseOptions> o("NoiseOptions");
    o.add("sample_rate", &NoiseOptions::sample_rate, "Hz")
        .add("samples", &NoiseOptions::samples, "length (>= 2)")
        .add("f_low", &NoiseOptions::f_low, "Hz, lowest excited line (>= 0)")
        .add("f_high", &NoiseOptions::f_high, "Hz, highest excited line (<= sample_rate / 2)")
        .add("rms", &NoiseOptions::rms, "V, rms of the varying part before scaling")
        .add("offset", &NoiseOptions::offset, "V")
        .add("seed", &NoiseOptions::seed, "random seed (mt19937_64)");
    return o;
  }();
  return t;
}

const Options<MultisineOptions>& multisine_options() {
  static const Options<MultisineOptions> t = [] {
    Options<MultisineOptions> o("MultisineOptions");
    o.add("sample_rate", &MultisineOptions::sample_rate, "Hz")
        .add("period_samples", &MultisineOptions::period_samples, "N, samples per period (>= 2)")
        .add("periods", &MultisineOptions::periods, "periods generated (>= 1)")
        .add("lines_Hz", &MultisineOptions::lines_Hz, "Hz, each a multiple k sample_rate / N, 1 <= k < N/2")
        .add("amplitudes", &MultisineOptions::amplitudes, "relative amplitude per line; empty = equal")
        .add("rms", &MultisineOptions::rms, "V, rms of the varying part before scaling")
        .add("offset", &MultisineOptions::offset, "V")
        .add_enum("phases", &MultisineOptions::phases, &dsp::to_string, &multisine_phases_from_string,
                  "\"schroeder\" (low crest factor) or \"random\"")
        .add("seed", &MultisineOptions::seed, "random phases' seed");
    return o;
  }();
  return t;
}

const Options<SweepOptions>& sweep_options() {
  static const Options<SweepOptions> t = [] {
    Options<SweepOptions> o("SweepOptions");
    o.add("sample_rate", &SweepOptions::sample_rate, "Hz")
        .add("duration", &SweepOptions::duration, "s")
        .add("f_start", &SweepOptions::f_start, "Hz")
        .add("f_end", &SweepOptions::f_end, "Hz")
        .add("amplitude", &SweepOptions::amplitude, "V")
        .add("offset", &SweepOptions::offset, "V")
        .add("ramp_time", &SweepOptions::ramp_time, "s, raised-cosine taper at each end")
        .add_enum("type", &SweepOptions::type, &dsp::to_string, &sweep_type_from_string, "\"linear\" or \"log\"");
    return o;
  }();
  return t;
}

const Options<OffsetSineOptions>& offset_sine_options() {
  static const Options<OffsetSineOptions> t = [] {
    Options<OffsetSineOptions> o("OffsetSineOptions");
    o.add("sample_rate", &OffsetSineOptions::sample_rate, "Hz")
        .add("rest", &OffsetSineOptions::rest, "V, level before and after")
        .add("offset", &OffsetSineOptions::offset, "V")
        .add("amplitude", &OffsetSineOptions::amplitude, "V")
        .add("frequency", &OffsetSineOptions::frequency, "Hz")
        .add("cycles", &OffsetSineOptions::cycles, "periods at full amplitude")
        .add("ramp_time", &OffsetSineOptions::ramp_time, "s, raised-cosine ramp in and out");
    return o;
  }();
  return t;
}

const Options<StepOptions>& step_options() {
  static const Options<StepOptions> t = [] {
    Options<StepOptions> o("StepOptions");
    o.add("sample_rate", &StepOptions::sample_rate, "Hz")
        .add("rest", &StepOptions::rest, "V")
        .add("levels", &StepOptions::levels, "V, the staircase's levels (at least one)")
        .add("hold_time", &StepOptions::hold_time, "s")
        .add("ramp_time", &StepOptions::ramp_time, "s (0: a jump)");
    return o;
  }();
  return t;
}

// The outputs of a Welch call: one 1-D array, a sequence of 1-D arrays, or a 2-D array of shape
// (outputs, samples) (time on the last axis, as scipy's default axis=-1).
struct Outputs {
  std::vector<DoubleArray> arrays;
  std::vector<std::string> names;
  bool single = false;
};

Outputs outputs_arg(py::handle y, const std::string& source, py::handle names) {
  Outputs out;
  py::array probe = py::array::ensure(y);
  if (probe && probe.ndim() == 1) {
    out.arrays.push_back(vector_arg(y, source, "y", false));
    out.single = true;
  } else if (probe && probe.ndim() == 2 && !py::isinstance<py::list>(y) && !py::isinstance<py::tuple>(y)) {
    DoubleArray all(DoubleArray::ensure(y));
    for (py::ssize_t i = 0; i < all.shape(0); ++i) {
      out.arrays.push_back(vector_arg(all[py::int_(i)], source, "y[" + std::to_string(i) + "]", false));
    }
  } else if (py::isinstance<py::sequence>(y) && !py::isinstance<py::str>(y)) {
    py::ssize_t i = 0;
    for (auto item : y) out.arrays.push_back(vector_arg(item, source, "y[" + std::to_string(i++) + "]", false));
  } else {
    PyErr_Clear();
    throw InputError(source, "y", "a 1-D array, a list of them or a 2-D array (outputs, samples)", short_repr(y));
  }
  if (names.is_none()) {
    for (std::size_t i = 0; i < out.arrays.size(); ++i) out.names.push_back(out.single ? "y" : "y" + std::to_string(i));
  } else {
    for (auto n : names) out.names.push_back(string_arg(n, source, "outputs"));
    if (out.names.size() != out.arrays.size()) {
      throw InputError(source, "outputs", std::to_string(out.arrays.size()) + " names", std::to_string(out.names.size()));
    }
  }
  return out;
}

// Runs the estimate over the arrays in place (no copy of the samples), without the GIL.
FrfEstimate estimate(const DoubleArray& u, const Outputs& y, double fs, const WelchOptions& options,
                     const std::string& input_name, const std::string& source) {
  std::vector<Channel> outs;
  for (std::size_t i = 0; i < y.arrays.size(); ++i) outs.push_back(Channel{y.names[i], span(y.arrays[i])});
  Channel in{input_name, span(u)};
  return without_gil([&] { return estimate_frf(in, outs, fs, options, source); });
}

py::array stack(const std::vector<Eigen::VectorXcd>& v, bool single) {
  if (single) return to_numpy(v.front());
  const Index n = v.empty() ? 0 : v.front().size();
  py::array_t<Complex> out({static_cast<Index>(v.size()), n});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (Index k = 0; k < n; ++k) a(static_cast<Index>(i), k) = v[i](k);
  return out;
}
py::array stack(const std::vector<Eigen::VectorXd>& v, bool single) {
  if (single) return to_numpy(v.front());
  const Index n = v.empty() ? 0 : v.front().size();
  py::array_t<double> out({static_cast<Index>(v.size()), n});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (Index k = 0; k < n; ++k) a(static_cast<Index>(i), k) = v[i](k);
  return out;
}

// dsp.frf's result: the estimate, and whether y was one 1-D output (then H, coherence, std_H, Syy and
// Suy are 1-D, else (outputs, points)).
struct FrfEstimateResult {
  FrfEstimate estimate;
  bool single = false;
};

// dsp.FrfEstimate from FrfEstimate's declaration (dsp/welch.hpp), its per-output arrays stacked as above.
void bind_frf_estimate_class(py::module_& m) {
  constexpr auto& decl = core::kFields<FrfEstimate>;
  py::class_<FrfEstimateResult> c(m, std::string(decl.name).c_str(), std::string(decl.meaning).c_str());
  def_fields<FrfEstimate>(c, [](const FrfEstimateResult& r) -> const FrfEstimate& { return r.estimate; },
                          {"H", "coherence", "std_H", "Syy", "Suy"});
  const auto stacked = [&c](auto getter) {
    const core::Declared d = core::declared<FrfEstimate>(getter);
    const std::string doc = std::string(d.meaning) + "; 1-D for one 1-D output, else (outputs, points)";
    c.def_property_readonly(std::string(d.name).c_str(), [getter](const FrfEstimateResult& r) { return stack(*getter(r.estimate), r.single); },
                            doc.c_str());
  };
  stacked(&estimate_H);
  stacked(&estimate_coherence);
  stacked(&estimate_std_H);
  stacked(&estimate_Syy);
  stacked(&estimate_Suy);
  typed(c);
  bind_held<FrfEstimate>(m);
}

template <class O>
void def_excitation(py::module_& m, const char* name, const Options<O>& table, Excitation (*f)(const O&, const VoltageBounds&),
                    const std::string& doc) {
  const std::string source = std::string("dsp.") + name;
  m.def(
      name,
      [&table, f, source](py::object bounds, const py::kwargs& kw) {
        auto o = table.from_kwargs(kwargs_dict(kw), source);
        VoltageBounds b;
        if (!bounds.is_none()) {
          if (!py::isinstance<py::dict>(bounds)) throw InputError(source, "bounds", "a dict (min, max, policy)", short_repr(bounds));
          b = bounds_options().from_kwargs(py::reinterpret_borrow<py::dict>(bounds), source);
        }
        return without_gil([&] { return f(o, b); });
      },
      py::arg("bounds") = py::none(),
      (doc + "\nReturns a dsp.Excitation: u (V), t (s), sample_rate (Hz), kind, scaled, scale, clipped, lines_Hz, seed.\n\n"
             "bounds: dict of\n" + bounds_options().doc("    ") + "\nKeywords:\n" + table.doc())
          .c_str());
}

}  // namespace

const Frf& frf_arg(py::handle obj, const std::string& source, const std::string& field) {
  if (!py::isinstance<Frf>(obj)) throw InputError(source, field, "a dsp.Frf (dsp.frf(...).frf, io.read_frf, dsp.Frf(...))", short_repr(obj));
  return obj.cast<const Frf&>();
}

namespace {

// The keywords of every Welch estimate, for their docstrings.
std::string welch_keywords() { return "\nKeywords (WelchOptions):\n" + welch_options().doc(); }

// dsp.Frf (dsp/frf.hpp): its fields from the declaration but H, coherence and std_H, which Python
// holds stacked as one array (1-D for one output, else (outputs, points)).
void bind_frf_class(py::module_& m) {
  using py::arg;
  bind_described<FrfProvenance>(m);
  py::class_<Frf> c(m, "Frf", R"(A frequency response: one input, named outputs, a common grid (dsp/frf.hpp).

H[i][k] = output i / input at freq_Hz[k]; coherence where known; std_H the standard deviation of the
random error of H's real and imaginary parts (std |H|, and std phase = std_H / |H| rad; Bendat & Piersol,
dsp/frf_variance.hpp) where known; provenance (dsp.FrfProvenance) says how it was estimated.)");
  c.def(py::init([](py::object freq_Hz, py::object H, py::object outputs, const std::string& input,
                       py::object coherence, py::object std_H, py::object provenance) {
             const std::string src = "dsp.Frf";
             Frf f;
             f.freq_Hz = to_vector(freq_Hz, src, "freq_Hz");
             f.input = input;
             auto h = to_complex_matrix(H, src, "H");
             // H: (points,) for one output, or (outputs, points).
             if (h.cols() == 1 && h.rows() == f.freq_Hz.size()) h.transposeInPlace();
             for (Index i = 0; i < h.rows(); ++i) f.H.push_back(h.row(i).transpose());
             if (outputs.is_none()) {
               for (Index i = 0; i < h.rows(); ++i) f.outputs.push_back(h.rows() == 1 ? "y" : "y" + std::to_string(i));
             } else {
               for (auto n : outputs) f.outputs.push_back(string_arg(n, src, "outputs"));
             }
             if (!coherence.is_none()) {
               auto gamma2 = to_matrix(coherence, src, "coherence", true);
               if (gamma2.cols() == 1 && gamma2.rows() == f.freq_Hz.size()) gamma2.transposeInPlace();
               for (Index i = 0; i < gamma2.rows(); ++i) f.coherence.push_back(gamma2.row(i).transpose());
             }
             if (!std_H.is_none()) {
               auto sd = to_matrix(std_H, src, "std_H", true);
               if (sd.cols() == 1 && sd.rows() == f.freq_Hz.size()) sd.transposeInPlace();
               for (Index i = 0; i < sd.rows(); ++i) f.std_H.push_back(sd.row(i).transpose());
             }
             if (!provenance.is_none()) {
               // Another Frf's provenance (or a mapping of its keys): how these lines were estimated, which the
               // fits read (n_d, and the Welch settings of the resolution kernel, dsp/resolution_kernel.hpp).
               const py::dict d = py::module_::import("builtins").attr("dict")(provenance);
               FrfProvenance& p = f.provenance;
               for (const auto& item : d) {
                 const std::string key = py::str(item.first);
                 const py::handle v = item.second;
                 if (v.is_none()) continue;
                 if (key == "source") p.source = string_arg(v, src, "provenance.source");
                 else if (key == "estimator") p.estimator = string_arg(v, src, "provenance.estimator");
                 else if (key == "window") p.window = string_arg(v, src, "provenance.window");
                 else if (key == "detrend") p.detrend = string_arg(v, src, "provenance.detrend");
                 else if (key == "nfft") p.nfft = static_cast<Index>(integer_arg(v, src, "provenance.nfft"));
                 else if (key == "averages") p.averages = static_cast<Index>(integer_arg(v, src, "provenance.averages"));
                 else if (key == "overlap") p.overlap = number_arg(v, src, "provenance.overlap");
                 else if (key == "sample_rate") p.sample_rate = number_arg(v, src, "provenance.sample_rate");
                 else if (key == "effective_averages") p.effective_averages = number_arg(v, src, "provenance.effective_averages");
                 else throw InputError(src, "provenance", "keys of dsp.FrfProvenance", "'" + key + "'");
               }
             }
             f.validate(src);
             return f;
           }),
           arg("freq_Hz"), arg("H"), arg("outputs") = py::none(), arg("input") = "u", arg("coherence") = py::none(),
           arg("std_H") = py::none(), arg("provenance") = py::none(),
           "freq_Hz (Hz, increasing); H: 1-D for one output or (outputs, points); outputs: names; coherence "
           "and std_H like H (None = unknown); provenance: another Frf's (or a dict of dsp.FrfProvenance's keys), "
           "how the lines were estimated (the fits take n_d and the Welch resolution kernel from it).")
      .def_property_readonly("omega", [](const Frf& f) { return to_numpy(Eigen::VectorXd(kTwoPi * f.freq_Hz)); }, "rad/s, 2 pi freq_Hz")
      .def_property_readonly("H", [](const Frf& f) { return stack(f.H, f.H.size() == 1); },
                             "1-D complex array for one output, else (outputs, points)")
      .def_property_readonly("coherence", [](const Frf& f) -> py::object {
        if (f.coherence.empty()) return py::none();
        return stack(f.coherence, f.coherence.size() == 1);
      }, "like H (None when unknown)")
      .def_property_readonly("std_H", [](const Frf& f) -> py::object {
        if (f.std_H.empty()) return py::none();
        return stack(f.std_H, f.std_H.size() == 1);
      }, "standard deviation of Re H and of Im H, H's units, like H (None when unknown); 95 % band |H| +- band_factor std_H")
      .def_property_readonly("band_factor", [](const Frf& f) -> py::object {
        if (!(f.provenance.effective_averages > 1.0)) return py::none();
        return py::float_(frf_band_factor(f.provenance.effective_averages));
      }, "k of the 95 % band H +- k std_H from the estimate's n_d (Student's t, dsp/frf_variance.hpp; None when n_d is unknown)")
      .def("response", [](const Frf& f, const std::string& name) { return to_numpy(f.H[static_cast<std::size_t>(f.output_index(name))]); },
           arg("output"), "H of the named output (InputError listing the names when unknown).")
      .def("__repr__", [](const Frf& f) {
        std::string outs;
        for (const auto& o : f.outputs) outs += (outs.empty() ? "" : ", ") + o;
        return "Frf(input=" + f.input + ", outputs=[" + outs + "], points=" + std::to_string(f.freq_Hz.size()) + ")";
      });
  def_fields<Frf>(c, [](const Frf& f) -> const Frf& { return f; }, {"H", "coherence", "std_H"});
}

// window, and the spectra of dsp/welch.hpp: welch, csd and frf.
void bind_spectra(py::module_& m) {
  using py::arg;
  m.def("band_factor", [](double effective_averages, double level) { return frf_band_factor(effective_averages, level); },
        arg("effective_averages"), arg("level") = 0.95,
        "k of the band H +- k std_H at `level` for n_d effective averages: sqrt(n_d / (n_d - 1)) t(2 n_d - 2) (Goodman 1963).");
  m.def("window", [](const std::string& type, Index length) { return to_numpy(make_window(window_type_from_string(type), length)); },
        arg("type"), arg("length"), "The window of `length` samples, sample for sample scipy.signal.get_window's.");

  const std::string keywords = welch_keywords();
  m.def(
      "welch",
      [](py::object x, double fs, const py::kwargs& kw) {
        auto o = welch_options().from_kwargs(kwargs_dict(kw), "dsp.welch");
        auto a = vector_arg(x, "dsp.welch", "x", false);
        Channel in{"x", span(a)};
        auto s = without_gil([&] { return cross_spectra(in, {}, fs, o, "dsp.welch"); });
        return py::make_tuple(to_numpy(std::move(s.freq_Hz)), to_numpy(std::move(s.Suu)));
      },
      arg("x"), arg("fs"),
      ("(f, Pxx): one-sided power spectral density of x, [x]^2/Hz, at f (Hz), as scipy.signal.welch with\n"
       "the same window, nperseg = nfft, noverlap = floor(overlap * nfft) and detrend." + keywords).c_str());
  m.def(
      "csd",
      [](py::object x, py::object y, double fs, const py::kwargs& kw) {
        auto o = welch_options().from_kwargs(kwargs_dict(kw), "dsp.csd");
        auto a = vector_arg(x, "dsp.csd", "x", false);
        auto ys = outputs_arg(y, "dsp.csd", py::none());
        std::vector<Channel> outs;
        for (std::size_t i = 0; i < ys.arrays.size(); ++i) outs.push_back(Channel{ys.names[i], span(ys.arrays[i])});
        Channel in{"x", span(a)};
        auto s = without_gil([&] { return cross_spectra(in, outs, fs, o, "dsp.csd"); });
        return py::make_tuple(to_numpy(std::move(s.freq_Hz)), stack(s.Suy, ys.single));
      },
      arg("x"), arg("y"), arg("fs"),
      ("(f, Pxy): cross spectral density conj(X) Y, [x][y]/Hz, as scipy.signal.csd(x, y). y may hold\n"
       "several outputs (list or (outputs, samples)): then Pxy is (outputs, points)." + keywords).c_str());
  m.def(
      "frf",
      [](py::object u, py::object y, double fs, py::object names, const std::string& input, const py::kwargs& kw) {
        auto o = welch_options().from_kwargs(kwargs_dict(kw), "dsp.frf");
        auto a = vector_arg(u, "dsp.frf", "u", false);
        auto ys = outputs_arg(y, "dsp.frf", names);
        return FrfEstimateResult{estimate(a, ys, fs, o, input, "dsp.frf"), ys.single};
      },
      arg("u"), arg("y"), arg("fs"), arg("outputs") = py::none(), arg("input") = "u",
      ("H1 (or H2) and coherence of every output in one pass over the data (the samples are read in\n"
       "place, without copies, and the GIL is released). u: input (1-D), y: one output (1-D), a list,\n"
       "or (outputs, samples); fs: Hz; outputs: names. Returns a dsp.FrfEstimate: freq_Hz, H, coherence,\n"
       "Suu, Syy, Suy (1-D for one output, else (outputs, points)), averages, and frf (a dsp.Frf)." + keywords)
          .c_str());
}

// h1, h2 and coherence (dsp/welch.hpp).
void bind_frf_estimators(py::module_& m) {
  using py::arg;
  const std::string keywords = welch_keywords();
  m.def(
      "h1",
      [](py::object u, py::object y, double fs, const py::kwargs& kw) {
        auto o = welch_options().from_kwargs(kwargs_dict(kw), "dsp.h1");
        o.estimator = FrfEstimator::kH1;
        auto a = vector_arg(u, "dsp.h1", "u", false);
        auto ys = outputs_arg(y, "dsp.h1", py::none());
        auto e = estimate(a, ys, fs, o, "u", "dsp.h1");
        return py::make_tuple(to_numpy(std::move(e.frf.freq_Hz)), stack(e.frf.H, ys.single));
      },
      arg("u"), arg("y"), arg("fs"), ("(f, H1): H1 = Suy / Suu (scipy: csd(u, y) / welch(u))." + keywords).c_str());
  m.def(
      "h2",
      [](py::object u, py::object y, double fs, const py::kwargs& kw) {
        auto o = welch_options().from_kwargs(kwargs_dict(kw), "dsp.h2");
        o.estimator = FrfEstimator::kH2;
        auto a = vector_arg(u, "dsp.h2", "u", false);
        auto ys = outputs_arg(y, "dsp.h2", py::none());
        auto e = estimate(a, ys, fs, o, "u", "dsp.h2");
        return py::make_tuple(to_numpy(std::move(e.frf.freq_Hz)), stack(e.frf.H, ys.single));
      },
      arg("u"), arg("y"), arg("fs"), ("(f, H2): H2 = Syy / Syu (scipy: welch(y) / conj(csd(u, y)))." + keywords).c_str());
  m.def(
      "coherence",
      [](py::object u, py::object y, double fs, const py::kwargs& kw) {
        auto o = welch_options().from_kwargs(kwargs_dict(kw), "dsp.coherence");
        auto a = vector_arg(u, "dsp.coherence", "u", false);
        auto ys = outputs_arg(y, "dsp.coherence", py::none());
        auto e = estimate(a, ys, fs, o, "u", "dsp.coherence");
        return py::make_tuple(to_numpy(std::move(e.frf.freq_Hz)), stack(e.frf.coherence, ys.single));
      },
      arg("u"), arg("y"), arg("fs"),
      ("(f, Cuy): magnitude-squared coherence |Suy|^2 / (Suu Syy), as scipy.signal.coherence." + keywords).c_str());
}

// The excitations of dsp/excitation.hpp.
void bind_excitations(py::module_& m) {
  def_excitation(m, "band_limited_noise", noise_options(), &band_limited_noise,
                 "Gaussian noise, white on the DFT lines inside [f_low, f_high] (periodic over `samples`).");
  def_excitation(m, "multisine", multisine_options(), &multisine,
                 "Sum of cosines on exact DFT lines (Schroeder or random phases), repeated `periods` times.");
  def_excitation(m, "sine_sweep", sweep_options(), &sine_sweep, "Linear or logarithmic sine sweep with end tapers.");
  def_excitation(m, "offset_sine", offset_sine_options(), &offset_sine,
                 "Quasi-static offset sine (hysteresis, stroke tests), ramped in and out from `rest`.");
  def_excitation(m, "steps", step_options(), &steps, "Staircase of held levels with linear ramps.");
}

}  // namespace

void bind_dsp(py::module_& m) {
  bind_frf_class(m);
  bind_frf_estimate_class(m);
  bind_described<Excitation>(m);
  m.def("declarations", [] {
    py::dict d = declarations_of<Frf, Excitation>();
    const py::type estimate = py::type::of<FrfEstimateResult>();  // dsp.FrfEstimate: FrfEstimate's fields
    d["FrfEstimate"] = py::make_tuple(estimate, estimate.attr("keys")());
    return d;
  }, "{declared struct: (its Python class, [field names])} for every declared result dsp returns (dsp/*.hpp).");
  bind_spectra(m);
  bind_frf_estimators(m);
  bind_excitations(m);
}

}  // namespace piezobench::python
