// The extension module piezobench._core: the exceptions and one submodule per library module.
#include "common.hpp"
#include "piezobench/version.hpp"

namespace py = pybind11;
using piezobench::InputError;
using piezobench::NumericalError;

namespace {

py::object g_input_error;
py::object g_numerical_error;

// The expected and found parts of an InputError's message "SOURCE: FIELD: expected E, found F"
// (core/error.cpp's format); both empty for a free-form message.
std::pair<std::string, std::string> expected_found(const InputError& e) {
  std::string prefix;
  if (!e.source().empty()) prefix += e.source() + ": ";
  if (!e.field().empty()) prefix += e.field() + ": ";
  prefix += "expected ";
  const std::string message = e.what();
  if (message.rfind(prefix, 0) != 0) return {};
  const std::string rest = message.substr(prefix.size());
  const auto split = rest.find(", found ");
  if (split == std::string::npos) return {};
  return {rest.substr(0, split), rest.substr(split + 8)};
}

// Raises the Python exception `type` built from the message, with its attributes set.
void raise(const py::object& type, const char* message, const py::dict& attributes) {
  py::object exc = type(message);
  for (auto item : attributes) py::setattr(exc, item.first, item.second);
  PyErr_SetObject(type.ptr(), exc.ptr());
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "piezobench's C++ library (the piezobench package re-exports it by module)";
  m.attr("__version__") = piezobench::kVersion;

  py::object errors = py::module_::import("piezobench._errors");
  g_input_error = errors.attr("InputError");
  g_numerical_error = errors.attr("NumericalError");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      py::dict a;
      a["source"] = e.source();
      a["field"] = e.field();
      auto [expected, found] = expected_found(e);
      a["expected"] = expected;
      a["found"] = found;
      raise(g_input_error, e.what(), a);
    } catch (const NumericalError& e) {
      py::dict a;
      a["method"] = e.method();
      a["retry_may_help"] = e.retry_may_help();
      raise(g_numerical_error, e.what(), a);
    }
  });

  using namespace piezobench::python;
  auto lti = m.def_submodule("lti", "Linear time-invariant systems: ss/tf/zpk, responses, c2d, root locus");
  bind_lti(lti);
  auto dsp = m.def_submodule("dsp", "Welch spectra, H1/H2 and coherence, excitation signals");
  bind_dsp(dsp);
  auto ident = m.def_submodule("ident", "Vector fitting, FRF features, fits, peak picking, LSCF, hysteresis and creep");
  bind_ident(ident);
  auto control = m.def_submodule("control", "Integral Force Feedback: plant, controller, root locus, discrete IFF");
  bind_control(control);
  auto apa = m.def_submodule("apa", "The 2-DoF APA model, its tuning to FRFs, piezo sensitivities");
  bind_apa(apa);
  auto fem = m.def_submodule("fem", "Super elements: import, modes, assembly, Craig-Bampton");
  bind_fem(fem);
  auto io = m.def_submodule("io", "Time-series and FRF files (.mat, .csv, .uff)");
  bind_io(io);
  // ident's hysteresis classes before the campaign's results that hold them (described.hpp binds a
  // declared struct in the first module that asks).
  bind_hysteresis(ident, control, io);
  auto bench = m.def_submodule("bench", "The virtual test bench: units, experiments, linear models");
  bind_bench(bench);
  auto campaign = m.def_submodule("campaign", "Run a campaign file and get its results");
  bind_campaign(campaign);
}
