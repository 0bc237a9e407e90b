// piezobench.io: include/piezobench/io/{timeseries,frf_file}.hpp
#include "common.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/io/frf_file.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::python {
namespace {

using namespace piezobench::io;

const Options<ReadOptions>& read_options() {
  static const Options<ReadOptions> t = [] {
    Options<ReadOptions> o("ReadOptions");
    o.add("fs", &ReadOptions::fs, "Hz; 0 = from the time vector t (or the file's fs)")
        .add("channels", &ReadOptions::channels, "channels to read, in order; empty = every numeric vector but t")
        .add("group", &ReadOptions::group, ".mat: 1x1 struct whose fields are the channels (\"\" = top level)")
        .add("time_tolerance", &ReadOptions::time_tolerance, "largest jitter of t, fraction of the sample period");
    return o;
  }();
  return t;
}

const Options<MatWriteOptions>& mat_options() {
  static const Options<MatWriteOptions> t = [] {
    Options<MatWriteOptions> o("MatWriteOptions");
    o.add_enum("version", &MatWriteOptions::version, &io::to_string, &mat_version_from_string, "\"v5\" or \"v7.3\"")
        .add("compress", &MatWriteOptions::compress, "zlib compression of v5 variables");
    return o;
  }();
  return t;
}

const Options<FrfWriteOptions>& frf_write_options() {
  static const Options<FrfWriteOptions> t = [] {
    Options<FrfWriteOptions> o("FrfWriteOptions");
    o.add_enum("mat_version", &FrfWriteOptions::mat_version, &io::to_string, &mat_version_from_string,
               ".mat only: \"v5\" or \"v7.3\"")
        .add("reference_node", &FrfWriteOptions::reference_node, "UFF: node number of the input")
        .add("date", &FrfWriteOptions::date, "UFF ID line 3; \"\" = NONE");
    return o;
  }();
  return t;
}

py::dict settings_dict(const std::map<std::string, Setting>& s) {
  py::dict d;
  for (const auto& [k, v] : s) {
    if (std::holds_alternative<double>(v)) {
      d[py::str(k)] = std::get<double>(v);
    } else {
      d[py::str(k)] = std::get<std::string>(v);
    }
  }
  return d;
}

}  // namespace

namespace {

// A TimeSeries from Python: channels (dict name -> 1-D array), sample rate, t, units and settings.
TimeSeries timeseries_from_python(py::dict channels, double sample_rate, py::object t, py::object units,
                                  py::object settings) {
  const std::string src = "io.TimeSeries";
  TimeSeries ts;
  ts.sample_rate = sample_rate;
  std::vector<Eigen::VectorXd> cols;
  for (auto item : channels) {
    const std::string name = string_arg(item.first, src, "channels");
    ts.names.push_back(name);
    cols.push_back(to_vector(item.second, src, name));
  }
  const Eigen::Index n = cols.empty() ? 0 : cols.front().size();
  ts.data.resize(n, static_cast<Eigen::Index>(cols.size()));
  for (std::size_t j = 0; j < cols.size(); ++j) {
    if (cols[j].size() != n) {
      throw InputError(src, ts.names[j], std::to_string(n) + " samples", std::to_string(cols[j].size()));
    }
    ts.data.col(static_cast<Eigen::Index>(j)) = cols[j];
  }
  if (!t.is_none()) ts.t = to_vector(t, src, "t");
  if (!units.is_none()) {
    auto u = py::reinterpret_borrow<py::dict>(units);
    for (const auto& name : ts.names) ts.units.push_back(u.contains(name) ? string_arg(u[py::str(name)], src, "units") : "");
  }
  if (!settings.is_none()) {
    for (auto item : py::reinterpret_borrow<py::dict>(settings)) {
      const std::string key = string_arg(item.first, src, "settings");
      if (py::isinstance<py::str>(item.second)) {
        ts.settings[key] = item.second.cast<std::string>();
      } else {
        ts.settings[key] = number_arg(item.second, src, "settings." + key);
      }
    }
  }
  ts.validate();
  return ts;
}

// io.TimeSeries (io/timeseries.hpp).
void bind_timeseries(py::module_& m) {
  using py::arg;
  py::class_<TimeSeries>(m, "TimeSeries", R"(A sampled measurement record (io/timeseries.hpp): named channels of
equal length (SI units), the sample rate (Hz), the time vector t (s) when known, units and settings.
data is samples x channels; channel(name) / ts[name] give one channel without a copy.)")
      .def(py::init(&timeseries_from_python),
           arg("channels"), arg("sample_rate"), arg("t") = py::none(), arg("units") = py::none(),
           arg("settings") = py::none(),
           "channels: dict name -> 1-D array (SI); sample_rate: Hz; t: s (optional); units: dict name -> unit; "
           "settings: dict of numbers or strings.")
      .def_readonly("names", &TimeSeries::names)
      .def_property_readonly("data", [](py::object self) { return view(self.cast<const TimeSeries&>().data, self); },
                             "samples x channels (read-only view)")
      .def_readonly("sample_rate", &TimeSeries::sample_rate, "Hz")
      .def_property_readonly("t", [](py::object self) -> py::object {
        const auto& ts = self.cast<const TimeSeries&>();
        if (ts.t.size() == 0) return py::none();
        return view(ts.t, self);
      }, "s (None when the file has none)")
      .def_property_readonly("units", [](const TimeSeries& ts) {
        py::dict d;
        for (const auto& n : ts.names) d[py::str(n)] = ts.unit(n);
        return d;
      })
      .def_property_readonly("settings", [](const TimeSeries& ts) { return settings_dict(ts.settings); })
      .def_readonly("source", &TimeSeries::source)
      .def_property_readonly("samples", &TimeSeries::samples)
      .def(
          "channel",
          [](py::object self, const std::string& name) {
            const auto& ts = self.cast<const TimeSeries&>();
            const Eigen::Index j = ts.index(name);
            const py::ssize_t n = ts.samples();
            py::array a = py::array_t<double>({n}, {static_cast<py::ssize_t>(sizeof(double))}, ts.data.col(j).data(), self);
            py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
            return a;
          },
          arg("name"), "The samples of one channel (a read-only view; InputError listing the names when unknown).")
      .def("__getitem__", [](py::object self, const std::string& name) { return self.attr("channel")(name); })
      .def("__repr__", [](const TimeSeries& ts) {
        std::string names;
        for (const auto& n : ts.names) names += (names.empty() ? "" : ", ") + n;
        return "TimeSeries([" + names + "], samples=" + std::to_string(ts.samples()) +
               ", sample_rate=" + format_number(ts.sample_rate, 10) + ")";
      });
}

// read_timeseries, write_timeseries, read_frf and write_frf.
void bind_files(py::module_& m) {
  using py::arg;
  m.def(
      "read_timeseries",
      [](const std::string& file, const py::kwargs& kw) {
        auto o = read_options().from_kwargs(kwargs_dict(kw), "io.read_timeseries");
        return without_gil([&] { return read_timeseries(file, o); });
      },
      arg("file"),
      ("Reads a .mat (v5/v7 and v7.3) or .csv time series (format from the extension), validated: unknown\n"
       "channels, differing lengths, NaN/Inf, a bad time vector are InputErrors naming file and channel.\n\n"
       "Keywords (ReadOptions):\n" + read_options().doc())
          .c_str());
  m.def(
      "write_timeseries",
      [](const TimeSeries& ts, const std::string& file, const py::kwargs& kw) {
        auto o = mat_options().from_kwargs(kwargs_dict(kw), "io.write_timeseries");
        without_gil([&] { write_timeseries(ts, file, o); return 0; });
      },
      arg("ts"), arg("file"),
      ("Writes a time series as .mat or .csv (from the extension), atomically.\n\nKeywords (MatWriteOptions):\n" +
       mat_options().doc())
          .c_str());
  m.def(
      "read_frf", [](const std::string& file) { return without_gil([&] { return read_frf(file); }); }, arg("file"),
      "Reads an FRF (.csv, .mat, .uff/.unv 58 ASCII or binary) as a dsp.Frf, validated.");
  m.def(
      "write_frf",
      [](py::object frf, const std::string& file, const py::kwargs& kw) {
        const auto& f = frf_arg(frf, "io.write_frf", "frf");
        auto o = frf_write_options().from_kwargs(kwargs_dict(kw), "io.write_frf");
        without_gil([&] { write_frf(f, file, o); return 0; });
      },
      arg("frf"), arg("file"),
      ("Writes a dsp.Frf as .csv, .mat or UFF 58 (from the extension), atomically.\n\nKeywords (FrfWriteOptions):\n" +
       frf_write_options().doc())
          .c_str());
}

}  // namespace

void bind_io(py::module_& m) {
  bind_timeseries(m);
  bind_files(m);
}

}  // namespace piezobench::python
