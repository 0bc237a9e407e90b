// piezobench.campaign: include/piezobench/campaign/{campaign_file,pipeline,demo,results}.hpp
#include <iostream>
#include <nlohmann/json.hpp>

#include "common.hpp"
#include "described.hpp"
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/demo.hpp"
#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/campaign/results.hpp"
#include "piezobench/campaign/results_json.hpp"

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

// What campaign.run returns: the typed results and the files written.
struct CampaignRun {
  CampaignResult result;
  std::vector<std::string> written;
};

// Every struct a UnitAnalysis holds, from the field declarations beside them (results.hpp and the
// modules' headers), then the derived figures that are not fields.
void bind_unit_analysis(py::module_& m) {
  bind_described<UnitAnalysis>(m);
  bound_class<bench::TrackingFigures>().def_property_readonly("rms_reduction", &bench::TrackingFigures::rms_reduction, "rms_open / rms_ff");
  bound_class<ident::DominantPole>()
      .def_property_readonly("frequency_Hz", &ident::DominantPole::frequency_Hz, "Hz")
      .def_property_readonly("relative_rms_error", [](const ident::DominantPole& p) { return p.fit.relative_rms_error; },
                             "of the vector fit it comes from")
      .def_property_readonly("quality", [](const ident::DominantPole& p) { return p.fit.quality; }, "the vector fit's ident.FitQuality");
  bound_class<UnitAnalysis>().def("json", [](const UnitAnalysis& u) { return from_json(unit_json(u), "UnitResults", true); },
                                  "The unit's entry of results.json as Results (values in the units their keys name).");
}

// campaign.BatchAnalysis and campaign.IffStudy from their declarations (results.hpp), with the
// batch's look-up of a spread by quantity.
void bind_batch_and_iff(py::module_& m) {
  bind_described<BatchAnalysis>(m);
  bound_class<BatchAnalysis>().def("spread_of", [](const BatchAnalysis& a, const std::string& q) -> py::object {
    for (const auto& s : a.spread)
      if (s.quantity == q) return py::cast(s);
    return py::none();
  }, py::arg("quantity"), "The QuantitySpread of `quantity` (None when not in the batch).");
  bind_described<IffStudy>(m);
  bind_described<SuperElementComparison>(m);
}

// campaign.CampaignResult, what campaign.run returns: the fields of its declaration (results.hpp), the
// files written and results.json as Results.
void bind_campaign_result(py::module_& m) {
  py::class_<CampaignRun> c(m, "CampaignResult", R"(The results of campaign.run (campaign/results.hpp): units (campaign.UnitAnalysis),
batch (campaign.BatchAnalysis), iff (campaign.IffStudy), superelement (campaign.SuperElementComparison
or None), accepted, marginal, rejected and not_analysed (counts), written (the files, when out_dir was
given). results is the results.json document as Results (every analysis, the report's units: _um, _uF, _Hz, ...); to_dict()
is that document as plain dicts. fields() lists the declaration.)");
  def_fields<CampaignResult>(c, [](const CampaignRun& r) -> const CampaignResult& { return r.result; });
  c.def_readonly("written", &CampaignRun::written, "files written (empty without out_dir)")
      .def_property_readonly("results", [](const CampaignRun& r) {
        return from_json(results_json(r.result), "CampaignResults", true);
      }, "results.json as Results (r.results.units[0].frf.resonance_Hz)")
      .def("to_dict", [](const CampaignRun& r) { return from_json(results_json(r.result), "CampaignResults", false); },
           "results.json as plain dicts and lists (number arrays as numpy arrays)")
      .def("unit", [](const CampaignRun& r, int id) -> const UnitAnalysis& {
        for (const auto& u : r.result.units)
          if (u.id == id) return u;
        throw InputError("campaign.CampaignResult.unit", "id", "the id of a unit of the campaign", std::to_string(id));
      }, py::arg("id"), py::return_value_policy::reference_internal, "The UnitAnalysis of unit `id`.")
      .def("__repr__", [](const CampaignRun& r) {
        return "CampaignResult(units=" + std::to_string(r.result.units.size()) + ", accepted=" + std::to_string(r.result.accepted) +
               ", rejected=" + std::to_string(r.result.rejected) + ")";
      });
}

// The typed results of campaign/results.hpp as read-only classes (SI unless the name ends in a
// unit). Nested results are views that keep the run alive.
void bind_result_classes(py::module_& m) {
  bind_unit_analysis(m);
  bind_batch_and_iff(m);
  bind_campaign_result(m);
  m.def("declarations", [] {
    py::dict d = declarations_of<UnitAnalysis, BatchAnalysis, IffStudy, SuperElementComparison, DemoFiles>();
    const py::type run = py::type::of<CampaignRun>();  // campaign.CampaignResult: CampaignResult's fields, and `written`
    d["CampaignResult"] = py::make_tuple(run, run.attr("keys")());
    return d;
  },
        "{declared struct: (its Python class, [field names])} for CampaignResult and every declared struct it holds\n"
        "(its units, batch, iff and superelement; docs/fields.md), and DemoFiles (write_demo's).");
}

}  // namespace

void bind_campaign(py::module_& m) {
  using py::arg;
  bind_result_classes(m);
  bind_described<DemoFiles>(m);  // write_demo's result (campaign/demo.hpp)

  m.def(
      "run",
      [](const std::string& file, int threads, py::object out_dir, bool progress) {
        auto c = read_campaign(file);
        PipelineOptions o;
        o.threads = threads;
        if (progress) {
          o.log = [](const std::string& line) { std::cerr << line << '\n'; };
        }
        CampaignRun run{without_gil([&] { return run_campaign(c, o); }), {}};
        if (!out_dir.is_none()) {
          const std::string dir = py::str(out_dir);
          auto paths = without_gil([&] { return write_outputs(run.result, dir); });
          for (const auto& p : paths) run.written.push_back(p.string());
        }
        return run;
      },
      arg("file"), arg("threads") = 0, arg("out_dir") = py::none(), arg("progress") = false,
      "Runs a campaign file (TOML, docs/campaign.md): every unit analysed, then the batch, the IFF study and\n"
      "the acceptance. Returns a campaign.CampaignResult: units (campaign.UnitAnalysis: k1, resonance_Hz,\n"
      "frf_analysis, model_2dof, accepted, reasons, ...), batch, iff, accepted, rejected, results (results.json\n"
      "as Results) and `written` (the files) when out_dir is given (results.mat, report.html, results.json).\n"
      "progress=True prints the progress lines on stderr.");
  m.def(
      "write_demo",
      [](const std::string& dir, std::uint64_t seed, bool fast, const std::vector<int>& units,
         const std::vector<double>& hysteresis_amplitudes, const std::vector<double>& iff_gains, int iff_unit,
         int tracking_unit, int threads) {
        DemoOptions o;
        o.seed = seed;
        o.fast = fast;
        o.units = units;
        o.hysteresis_amplitudes = hysteresis_amplitudes;
        o.iff_gains = iff_gains;
        o.iff_unit = iff_unit;
        o.tracking_unit = tracking_unit;
        o.threads = threads;
        return without_gil([&] { return write_demo_campaign(dir, o); });
      },
      arg("dir"), arg("seed") = DemoOptions{}.seed, arg("fast") = DemoOptions{}.fast, arg("units") = DemoOptions{}.units,
      arg("hysteresis_amplitudes") = DemoOptions{}.hysteresis_amplitudes, arg("iff_gains") = DemoOptions{}.iff_gains,
      arg("iff_unit") = DemoOptions{}.iff_unit, arg("tracking_unit") = DemoOptions{}.tracking_unit, arg("threads") = DemoOptions{}.threads,
      "Simulates the report's campaign on the virtual bench into DIR (data files, campaign.toml,\n"
      "data/truth.json): a campaign.DemoFiles(campaign, truth, superelement, data), paths as str. fast = shorter records for tests; tracking_unit: the unit\n"
      "with a tracking record (0: none).");
}

}  // namespace piezobench::python
