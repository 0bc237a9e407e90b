// piezobench.campaign: include/piezobench/campaign/{campaign_file,pipeline,demo}.hpp
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "common.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/demo.hpp"
#include "piezobench/campaign/pipeline.hpp"
#if __has_include("piezobench/campaign/results_json.hpp")
#include "piezobench/campaign/results_json.hpp"
#endif

namespace piezobench::python {

py::object from_json(const nlohmann::json& j, const std::string& type, bool as_results) {
  switch (j.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(j.get<long long>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<unsigned long long>());
    case nlohmann::json::value_t::number_float:
      return py::float_(j.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      // Arrays of numbers become numpy arrays; others lists.
      bool numeric = !j.empty();
      for (const auto& e : j) numeric = numeric && e.is_number();
      if (numeric) {
        Eigen::VectorXd v(static_cast<Eigen::Index>(j.size()));
        for (std::size_t i = 0; i < j.size(); ++i) v(static_cast<Eigen::Index>(i)) = j[i].get<double>();
        return to_numpy(std::move(v));
      }
      py::list l;
      for (const auto& e : j) l.append(from_json(e, type, as_results));
      return l;
    }
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = from_json(v, k, as_results);
      return as_results ? result(type, d) : py::object(d);
    }
    default:
      return py::none();
  }
}

namespace {

using namespace piezobench::campaign;

// The results.json document of a run (CLI.md keys), whether the pipeline keeps it as JSON or as
// typed results with one serializer (campaign/results_json.hpp).
template <class R>
nlohmann::json results_document(const R& r) {
  if constexpr (requires { r.results.dump(); }) {
    return r.results;
  } else {
    return results_json(r);
  }
}

}  // namespace

void bind_campaign(py::module_& m) {
  using py::arg;

  m.def(
      "run",
      [](const std::string& file, int threads, py::object out_dir, bool progress) {
        auto c = read_campaign(file);
        PipelineOptions o;
        o.threads = threads;
        if (progress) {
          o.log = [](const std::string& line) { std::cerr << line << '\n'; };
        }
        auto r = without_gil([&] { return run_campaign(c, o); });
        py::dict d;
        d["accepted"] = r.accepted;
        d["rejected"] = r.rejected;
        d["results"] = from_json(results_document(r), "CampaignResults", true);
        if (!out_dir.is_none()) {
          const std::string dir = py::str(out_dir);
          auto paths = without_gil([&] { return write_outputs(r, dir); });
          py::list written;
          for (const auto& p : paths) written.append(p.string());
          d["written"] = written;
        }
        return result("CampaignResult", d);
      },
      arg("file"), arg("threads") = 0, arg("out_dir") = py::none(), arg("progress") = false,
      "Runs a campaign file (TOML, docs/campaign.md): every unit analysed, then the batch and the\n"
      "acceptance. Returns a Result: accepted, rejected, results (results.json as Results: units[i].frf,\n"
      ".stiffness, ..., with to_dict()), and `written` (the files) when out_dir is given (results.mat,\n"
      "report.html, results.json). progress=True prints the progress lines on stderr.");
  m.def(
      "write_demo",
      [](const std::string& dir, std::uint64_t seed, bool fast, const std::vector<int>& units,
         const std::vector<double>& hysteresis_amplitudes, const std::vector<double>& iff_gains, int iff_unit,
         int threads) {
        DemoOptions o;
        o.seed = seed;
        o.fast = fast;
        o.units = units;
        o.hysteresis_amplitudes = hysteresis_amplitudes;
        o.iff_gains = iff_gains;
        o.iff_unit = iff_unit;
        o.threads = threads;
        auto f = without_gil([&] { return write_demo_campaign(dir, o); });
        py::dict d;
        d["campaign"] = f.campaign.string();
        d["truth"] = f.truth.string();
        py::list data;
        for (const auto& p : f.data) data.append(p.string());
        d["data"] = data;
        return result("DemoFiles", d);
      },
      arg("dir"), arg("seed") = DemoOptions{}.seed, arg("fast") = DemoOptions{}.fast, arg("units") = DemoOptions{}.units,
      arg("hysteresis_amplitudes") = DemoOptions{}.hysteresis_amplitudes, arg("iff_gains") = DemoOptions{}.iff_gains,
      arg("iff_unit") = DemoOptions{}.iff_unit, arg("threads") = DemoOptions{}.threads,
      "Simulates the report's campaign on the virtual bench into DIR (data files, campaign.toml,\n"
      "data/truth.json): Result(campaign, truth, data). fast = shorter records for tests.");
}

}  // namespace piezobench::python
