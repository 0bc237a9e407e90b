// piezobench.campaign: include/piezobench/campaign/{campaign_file,pipeline,demo,results}.hpp
#include <iostream>
#include <nlohmann/json.hpp>

#include "common.hpp"
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

py::array complex_array(const std::vector<std::complex<double>>& v) {
  return to_numpy(Eigen::VectorXcd(Eigen::Map<const Eigen::VectorXcd>(v.data(), static_cast<Eigen::Index>(v.size()))));
}
py::array real_array(const std::vector<double>& v) {
  return to_numpy(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()))));
}

// The typed results of campaign/results.hpp as read-only classes (SI unless the name ends in a
// unit). Nested results are views that keep the run alive.
void bind_result_classes(py::module_& m) {
  {
    py::class_<RecordProvenance> c(m, "RecordProvenance", "Where an analysis' data came from.");
    c.def_readonly("file", &RecordProvenance::file, "as given in the campaign")
        .def_readonly("key", &RecordProvenance::key, "campaign key, e.g. \"units[0].frf\"")
        .def_readonly("channels", &RecordProvenance::channels, "(role, channel name in the file) pairs")
        .def_readonly("samples", &RecordProvenance::samples)
        .def_readonly("sample_rate_Hz", &RecordProvenance::sample_rate_Hz, "Hz")
        .def_readonly("input", &RecordProvenance::input, "FRF: the input role")
        .def_readonly("outputs", &RecordProvenance::outputs, "FRF: the output roles");
    typed(c);
  }
  {
    py::class_<Curve> c(m, "Curve", "A curve of the report (thinned or log-spaced samples): x, y as arrays.");
    c.def_property_readonly("x", [](const Curve& k) { return real_array(k.x); })
        .def_property_readonly("y", [](const Curve& k) { return real_array(k.y); });
    typed(c);
  }
  {
    py::class_<VectorFitSummary> c(m, "VectorFitSummary", "A vector fit's summary.");
    c.def_readonly("order", &VectorFitSummary::order)
        .def_readonly("relative_rms_error", &VectorFitSummary::relative_rms_error)
        .def_readonly("converged", &VectorFitSummary::converged);
    typed(c);
  }
  {
    py::class_<NmpEvidence::Zero> z(m, "NmpZero", "The vector fit's zero of u -> Vs nearest the dip, with the phase verdict.");
    z.def_property_readonly("phase_verdict", [](const NmpEvidence::Zero& x) { return ident::to_string(x.phase_verdict); },
                            "\"minimum-phase\", \"non-minimum-phase\" or \"undetermined\" (measured phase)")
        .def_readonly("phase_change_deg", &NmpEvidence::Zero::phase_change_deg, "deg, across the dip")
        .def_readonly("fitted_zero", &NmpEvidence::Zero::fitted_zero, "rad/s")
        .def_readonly("fitted_zero_nonminimum_phase", &NmpEvidence::Zero::fitted_zero_nonminimum_phase);
    typed(z);
    py::class_<NmpEvidence> c(m, "NmpEvidence", "Evidence of a non-minimum-phase zero pair in u -> Vs (report section 2.3).");
    c.def_readonly("zero", &NmpEvidence::zero, "campaign.NmpZero or None")
        .def_readonly("iff_plant_fit_xz", &NmpEvidence::iff_plant_fit_xz, "xz of the IFF plant fit (< 0: non-minimum phase)")
        .def_readonly("iff_plant_fit_xz_standard_error", &NmpEvidence::iff_plant_fit_xz_standard_error,
                      "standard error of xz; the verdict's 95 % interval is xz +- 1.96 of it")
        .def_readonly("verdict_from", &NmpEvidence::verdict_from, "\"phase\", \"iff-plant-fit\", \"fitted-zero\" or \"none\"")
        .def_readonly("verdict_reason", &NmpEvidence::verdict_reason, "why: which evidence decided and what it said, e.g. an ambiguous phase change and the plant fit's xz");
    typed(c);
  }
  {
    py::class_<HighPassCorner> c(m, "HighPassCorner", "The resistor high-pass of the force sensor's read-out (Hz).");
    c.def_readonly("first_order_fit_Hz", &HighPassCorner::first_order_fit_Hz, "Hz, first-order fit below hpf_fmax_Hz")
        .def_readonly("first_order_fit_points", &HighPassCorner::first_order_fit_points)
        .def_readonly("r_c_Hz", &HighPassCorner::r_c_Hz, "Hz, 1 / (2 pi R C_sensor) when C_sensor is measured")
        .def_readonly("iff_plant_fit_Hz", &HighPassCorner::iff_plant_fit_Hz, "Hz, eq. 2.3 fitted down to the lowest frequency")
        .def_readonly("iff_plant_fit_error", &HighPassCorner::iff_plant_fit_error, "the cross-check's failure")
        .def_readonly("method", &HighPassCorner::method)
        .def_readonly("corner_Hz", &HighPassCorner::corner_Hz, "Hz, the unit's corner");
    typed(c);
  }
  {
    py::class_<FrfAnalysis> c(m, "FrfAnalysis", "The FRFs u -> [d_e, Vs] of a unit and what is read from them (SI, frequencies in Hz).");
    c.def_readonly("provenance", &FrfAnalysis::provenance)
        .def_property_readonly("welch", [](const FrfAnalysis& a) { return provenance_dict(a.welch); }, "the Welch estimate's settings")
        .def_readonly("fit_de", &FrfAnalysis::fit_de, "campaign.VectorFitSummary of u -> d_e or None")
        .def_readonly("fit_vs", &FrfAnalysis::fit_vs, "campaign.VectorFitSummary of u -> Vs or None")
        .def_readonly("static_gain_vector_fit", &FrfAnalysis::static_gain_vector_fit, "m/V, vector fit of u -> d_e")
        .def_readonly("static_gain", &FrfAnalysis::static_gain, "m/V, the unit's")
        .def_readonly("static_gain_source", &FrfAnalysis::static_gain_source)
        .def_readonly("static_gain_vs", &FrfAnalysis::static_gain_vs, "V/V, vector fit of u -> Vs")
        .def_readonly("de_plant", &FrfAnalysis::de_plant, "ident.DelayedSecondOrderFit of u -> d_e or None")
        .def_readonly("iff_plant", &FrfAnalysis::iff_plant, "ident.IffPlantFit of u -> Vs (eq. 2.3) or None")
        .def_readonly("iff_plant_fmin_Hz", &FrfAnalysis::iff_plant_fmin_Hz, "Hz, band of the IFF plant fit")
        .def_readonly("iff_plant_fmax_Hz", &FrfAnalysis::iff_plant_fmax_Hz, "Hz")
        .def_readonly("iff_plant_w_hpf_measured", &FrfAnalysis::iff_plant_w_hpf_measured, "w_hpf from R C_sensor (else fitted)")
        .def_readonly("nmp", &FrfAnalysis::nmp, "campaign.NmpEvidence")
        .def_readonly("hpf", &FrfAnalysis::hpf, "campaign.HighPassCorner")
        .def_readonly("resonance_vector_fit_Hz", &FrfAnalysis::resonance_vector_fit_Hz, "Hz")
        .def_readonly("resonance_vector_fit_damping", &FrfAnalysis::resonance_vector_fit_damping)
        .def_readonly("antiresonance_vector_fit_Hz", &FrfAnalysis::antiresonance_vector_fit_Hz, "Hz")
        .def_readonly("antiresonance_vector_fit_damping", &FrfAnalysis::antiresonance_vector_fit_damping)
        .def_readonly("resonance_Hz", &FrfAnalysis::resonance_Hz, "Hz")
        .def_readonly("resonance_damping", &FrfAnalysis::resonance_damping)
        .def_readonly("antiresonance_Hz", &FrfAnalysis::antiresonance_Hz, "Hz")
        .def_readonly("antiresonance_damping", &FrfAnalysis::antiresonance_damping, "< 0: non-minimum phase")
        .def_readonly("zero_is_nonminimum_phase", &FrfAnalysis::zero_is_nonminimum_phase)
        .def_readonly("shell_stiffness", &FrfAnalysis::shell_stiffness, "N/m, m_sus w_z^2");
    typed(c);
  }
  {
    py::class_<Model2DofFit> c(m, "Model2DofFit", "The tuned 2-DoF model (report section 3) with the fitted measurement chain.");
    c.def_property_readonly("tuning", [](const Model2DofFit& f) { return tuning_result(f.tuning); },
                            "as apa.tune_two_dof_measured returns it (params SI, quality)")
        .def_property_readonly("bench", [](const Model2DofFit& f) { return two_dof_bench_dict(f.bench); },
                               "the chain the model was tuned with (apa.two_dof_bench keywords)")
        .def_readonly("fmin_Hz", &Model2DofFit::fmin_Hz, "Hz, band of the tuning")
        .def_readonly("fmax_Hz", &Model2DofFit::fmax_Hz, "Hz");
    typed(c);
  }
  {
    py::class_<ident::DominantPole> c(m, "DominantPole", "The dominant pole pair of a vector fit (ident/dominant_pole.hpp).");
    c.def_readonly("pole", &ident::DominantPole::pole, "rad/s, Im > 0")
        .def_readonly("natural_frequency", &ident::DominantPole::natural_frequency, "rad/s")
        .def_property_readonly("frequency_Hz", &ident::DominantPole::frequency_Hz, "Hz")
        .def_readonly("damping", &ident::DominantPole::damping)
        .def_readonly("peak", &ident::DominantPole::peak, "its peak contribution, data units")
        .def_property_readonly("relative_rms_error", [](const ident::DominantPole& p) { return p.fit.relative_rms_error; },
                               "of the vector fit it comes from")
        .def_property_readonly("quality", [](const ident::DominantPole& p) { return p.fit.quality; }, "the vector fit's ident.FitQuality");
    typed(c);
  }
  {
    py::class_<DampedPlant> c(m, "DampedPlant", "One damped plant u' -> d_e of the IFF experiment (report section 2.6).");
    c.def_readonly("gain", &DampedPlant::gain, "controller gain g")
        .def_readonly("file", &DampedPlant::file)
        .def_readonly("provenance", &DampedPlant::provenance)
        .def_readonly("frf", &DampedPlant::frf, "dsp.Frf u' -> d_e")
        .def_readonly("identified", &DampedPlant::identified, "campaign.DominantPole (d_e's delay removed) or None")
        .def_readonly("identified_order", &DampedPlant::identified_order)
        .def_readonly("fmin_Hz", &DampedPlant::fmin_Hz, "Hz, the damped-plant band")
        .def_readonly("fmax_Hz", &DampedPlant::fmax_Hz, "Hz")
        .def_readonly("second_order", &DampedPlant::second_order, "ident.DelayedSecondOrderFit or None")
        .def_readonly("delay_removed", &DampedPlant::delay_removed, "s");
    typed(c);
  }
  {
    py::class_<bench::TrackingFigures> c(m, "TrackingFigures", "One waveform of the tracking experiment (bench/tracking.hpp).");
    c.def_readonly("width_open", &bench::TrackingFigures::width_open, "hysteresis width / stroke, without the feedforward")
        .def_readonly("width_ff", &bench::TrackingFigures::width_ff, "the same with it")
        .def_readonly("rms_open", &bench::TrackingFigures::rms_open, "m, rms tracking error without")
        .def_readonly("rms_ff", &bench::TrackingFigures::rms_ff, "m, with")
        .def_readonly("stroke_open", &bench::TrackingFigures::stroke_open, "m")
        .def_property_readonly("rms_reduction", &bench::TrackingFigures::rms_reduction, "rms_open / rms_ff");
    typed(c);
  }
  {
    py::class_<TrackingAnalysis> c(m, "TrackingAnalysis", "The tracking record: d_e against the command without and with the inverse "
                                                          "hysteresis feedforward (docs/hysteresis.md).");
    c.def_readonly("sine", &TrackingAnalysis::sine, "campaign.TrackingFigures of the 1 Hz sine")
        .def_readonly("triangle", &TrackingAnalysis::triangle, "campaign.TrackingFigures of the triangle")
        .def_readonly("amplitude", &TrackingAnalysis::amplitude, "V")
        .def_readonly("feedforward", &TrackingAnalysis::feedforward, "\"identified\" (from the open run) or \"given\"")
        .def_readonly("clamped_samples", &TrackingAnalysis::clamped_samples)
        .def_readonly("provenance", &TrackingAnalysis::provenance)
        .def_readonly("sine_open", &TrackingAnalysis::sine_open, "campaign.Curve: x command [V], y d_e [m]")
        .def_readonly("sine_ff", &TrackingAnalysis::sine_ff)
        .def_readonly("triangle_open", &TrackingAnalysis::triangle_open)
        .def_readonly("triangle_ff", &TrackingAnalysis::triangle_ff);
    typed(c);
  }
  {
    py::class_<UnitAnalysis> c(m, "UnitAnalysis", R"(One unit's results (campaign/results.hpp): the numbers the batch and the
acceptance use (SI: m, F, N/m, m/V; frequencies in Hz; None = not available), the FRF analysis, the
tuned 2-DoF model, the damped plants, and the acceptance (accepted, reasons). json() is the unit's
entry of results.json (every analysis, in the units its keys name).)");
    c.def_readonly("id", &UnitAnalysis::id)
        .def_readonly("name", &UnitAnalysis::name)
        .def_readonly("flatness", &UnitAnalysis::flatness, "m, by the spec's method")
        .def_readonly("capacitance_sensor", &UnitAnalysis::capacitance_sensor, "F")
        .def_readonly("capacitance_actuator", &UnitAnalysis::capacitance_actuator, "F")
        .def_readonly("stroke", &UnitAnalysis::stroke, "m")
        .def_readonly("k1", &UnitAnalysis::k1, "N/m, static stiffness k1 (= k_sc)")
        .def_readonly("k2", &UnitAnalysis::k2, "N/m")
        .def_readonly("k_resonance", &UnitAnalysis::k_resonance, "N/m, from the resonance")
        .def_readonly("k_oc", &UnitAnalysis::k_oc, "N/m, every stack open")
        .def_readonly("resonance_Hz", &UnitAnalysis::resonance_Hz, "Hz")
        .def_readonly("antiresonance_Hz", &UnitAnalysis::antiresonance_Hz, "Hz")
        .def_readonly("static_gain", &UnitAnalysis::static_gain, "m/V")
        .def_readonly("frf", &UnitAnalysis::frf, "dsp.Frf u -> [de, Vs] or None")
        .def_readonly("iff_plant", &UnitAnalysis::iff_plant, "ident.IffPlantFit of u -> Vs or None")
        .def_readonly("de_plant", &UnitAnalysis::de_plant, "ident.DelayedSecondOrderFit of u -> d_e or None")
        .def_readonly("frf_analysis", &UnitAnalysis::frf_analysis, "campaign.FrfAnalysis or None")
        .def_readonly("model_2dof", &UnitAnalysis::model_2dof, "campaign.Model2DofFit or None")
        .def_readonly("damped", &UnitAnalysis::damped, "list of campaign.DampedPlant, by gain")
        .def_readonly("tracking", &UnitAnalysis::tracking, "campaign.TrackingAnalysis or None")
        .def_readonly("not_measured", &UnitAnalysis::not_measured, "experiments the campaign does not list")
        .def_readonly("failed", &UnitAnalysis::failed, "one line per analysis that failed")
        .def_readonly("warnings", &UnitAnalysis::warnings, "cross-checks that disagree (high-pass corner, resonance, ...)")
        .def_property_readonly(
            "not_analysed",
            [](const UnitAnalysis& u) -> py::object {
              if (!u.not_analysed) return py::none();
              return py::dict(py::arg("file") = u.not_analysed->file, py::arg("key") = u.not_analysed->key,
                              py::arg("reason") = u.not_analysed->reason);
            },
            "None, or {file, key, reason} of a unit whose data could not be analysed (nothing else of it is filled in)")
        .def_readonly("accepted", &UnitAnalysis::accepted, "the acceptance")
        .def_readonly("reasons", &UnitAnalysis::reasons, "why it is rejected")
        .def("json", [](const UnitAnalysis& u) { return from_json(unit_json(u), "UnitResults", true); },
             "The unit's entry of results.json as Results (values in the units their keys name).");
    typed(c);
  }
  {
    py::class_<QuantitySpread> c(m, "QuantitySpread", "Spread of one quantity over the batch (values in the unit its name says).");
    c.def_readonly("quantity", &QuantitySpread::quantity, "results key, e.g. \"capacitance_sensor_uF\"")
        .def_readonly("units", &QuantitySpread::units, "number of units with a value")
        .def_readonly("min", &QuantitySpread::min)
        .def_readonly("max", &QuantitySpread::max)
        .def_readonly("median", &QuantitySpread::median)
        .def_readonly("relative_spread", &QuantitySpread::relative_spread, "(max - min) / median")
        .def_readonly("mad", &QuantitySpread::mad, "median absolute deviation");
    typed(c);
    py::class_<BatchOutlier> o(m, "BatchOutlier", "A unit whose quantity is an outlier of the batch (robust z-score).");
    o.def_readonly("unit", &BatchOutlier::unit)
        .def_readonly("quantity", &BatchOutlier::quantity)
        .def_readonly("value", &BatchOutlier::value)
        .def_readonly("median", &BatchOutlier::median)
        .def_readonly("robust_z", &BatchOutlier::robust_z);
    typed(o);
    py::class_<FrfSimilarity::Unit> su(m, "FrfSimilarityUnit", "rms distance in dB of one unit's FRFs from the batch median.");
    su.def_readonly("unit", &FrfSimilarity::Unit::unit)
        .def_readonly("de_rms_dB", &FrfSimilarity::Unit::de_rms_dB, "dB (NaN when no point compares)")
        .def_readonly("vs_rms_dB", &FrfSimilarity::Unit::vs_rms_dB, "dB");
    typed(su);
    py::class_<FrfSimilarity> sim(m, "FrfSimilarity", "Unit-to-unit similarity of the FRFs.");
    sim.def_readonly("fmin_Hz", &FrfSimilarity::fmin_Hz, "Hz")
        .def_readonly("fmax_Hz", &FrfSimilarity::fmax_Hz, "Hz")
        .def_readonly("units", &FrfSimilarity::units)
        .def_readonly("max_rms_dB", &FrfSimilarity::max_rms_dB, "dB");
    typed(sim);
    py::class_<BatchAnalysis> b(m, "BatchAnalysis", "The batch summary: outliers, spread of the key figures, FRF similarity.");
    b.def_readonly("outliers", &BatchAnalysis::outliers, "list of campaign.BatchOutlier")
        .def_readonly("spread", &BatchAnalysis::spread, "list of campaign.QuantitySpread")
        .def_readonly("similarity", &BatchAnalysis::similarity, "campaign.FrfSimilarity or None")
        .def_readonly("rejects", &BatchAnalysis::rejects, "outliers in capacitance or stroke reject a unit")
        .def("spread_of", [](const BatchAnalysis& a, const std::string& q) -> py::object {
          for (const auto& s : a.spread)
            if (s.quantity == q) return py::cast(s);
          return py::none();
        }, py::arg("quantity"), "The QuantitySpread of `quantity` (None when not in the batch).");
    typed(b);
  }
  {
    py::class_<IffStudy::Branch> br(m, "RootLocusBranch", "A branch of the IFF root locus (rad/s).");
    br.def_readonly("re_im", &IffStudy::Branch::re_im, "campaign.Curve: x Re, y Im (rad/s)")
        .def_property_readonly("gains", [](const IffStudy::Branch& b) { return real_array(b.gains); }, "at each point")
        .def_readonly("resonance_branch", &IffStudy::Branch::resonance_branch);
    typed(br);
    py::class_<IffStudy> c(m, "IffStudy", R"(The IFF study: root locus of the fitted plant with the report's controller against
the poles of the measured damped plants, and the optimal gain (rad/s, SI).)");
    c.def_property_readonly("controller", [](const IffStudy& s) {
          py::dict d;
          d["gain"] = s.controller.gain;
          d["w_hpf"] = s.controller.w_hpf;
          d["w_lpf"] = s.controller.w_lpf;
          d["w_robust"] = s.controller.w_robust;
          return d;
        }, "the controller (control.iff_controller keywords, rad/s)")
        .def_readonly("unit", &IffStudy::unit, "the unit whose plant is used")
        .def_readonly("plant", &IffStudy::plant, "ident.IffPlantFit or None")
        .def_property_readonly("gains", [](const IffStudy& s) { return real_array(s.gains); }, "of the damped plants with an identified pole")
        .def_property_readonly("damped_poles", [](const IffStudy& s) { return complex_array(s.damped_poles); }, "rad/s, measured")
        .def_property_readonly("model_poles", [](const IffStudy& s) { return complex_array(s.model_poles); }, "rad/s, of the root locus at those gains")
        .def_property_readonly("relative_pole_distance", [](const IffStudy& s) { return real_array(s.relative_pole_distance); })
        .def_readonly("max_relative_pole_distance", &IffStudy::max_relative_pole_distance)
        .def_readonly("pole_distance_tolerance", &IffStudy::pole_distance_tolerance, "above it: warning")
        .def_readonly("warning", &IffStudy::warning)
        .def_readonly("optimal_gain", &IffStudy::optimal_gain, "the gain of maximum damping")
        .def_readonly("max_damping", &IffStudy::max_damping, "damping ratio at optimal_gain")
        .def_readonly("optimal_pole", &IffStudy::optimal_pole, "rad/s")
        .def_readonly("note", &IffStudy::note, "why there is no study")
        .def_readonly("failed", &IffStudy::failed, "a NumericalError of the study")
        .def_readonly("branches", &IffStudy::branches, "list of campaign.RootLocusBranch (Figure 2.10b)")
        .def_readonly("open_loop_poles", &IffStudy::open_loop_poles, "campaign.Curve x Re, y Im (rad/s)")
        .def_readonly("open_loop_zeros", &IffStudy::open_loop_zeros, "campaign.Curve x Re, y Im (rad/s)");
    typed(c);
  }
  {
    py::class_<CampaignRun> c(m, "CampaignResult", R"(The results of campaign.run (campaign/results.hpp): units (campaign.UnitAnalysis),
batch (campaign.BatchAnalysis), iff (campaign.IffStudy), accepted and rejected (counts), written (the
files, when out_dir was given). results is the results.json document as Results (every analysis,
the report's units: _um, _uF, _Hz, ...); to_dict() is that document as plain dicts.)");
    c.def_property_readonly("units", [](const CampaignRun& r) -> const std::vector<UnitAnalysis>& { return r.result.units; },
                            py::return_value_policy::reference_internal, "list of campaign.UnitAnalysis")
        .def_property_readonly("batch", [](const CampaignRun& r) -> const BatchAnalysis& { return r.result.batch; },
                               py::return_value_policy::reference_internal, "campaign.BatchAnalysis")
        .def_property_readonly("iff", [](const CampaignRun& r) -> const IffStudy& { return r.result.iff; },
                               py::return_value_policy::reference_internal, "campaign.IffStudy")
        .def_property_readonly("accepted", [](const CampaignRun& r) { return r.result.accepted; }, "units accepted")
        .def_property_readonly("rejected", [](const CampaignRun& r) { return r.result.rejected; }, "units rejected")
        .def_property_readonly("not_analysed", [](const CampaignRun& r) { return r.result.not_analysed; },
                               "units whose data could not be analysed (neither accepted nor rejected)")
        .def_readonly("written", &CampaignRun::written, "files written (empty without out_dir)")
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
}

}  // namespace

void bind_campaign(py::module_& m) {
  using py::arg;
  bind_result_classes(m);

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
      arg("iff_unit") = DemoOptions{}.iff_unit, arg("tracking_unit") = DemoOptions{}.tracking_unit, arg("threads") = DemoOptions{}.threads,
      "Simulates the report's campaign on the virtual bench into DIR (data files, campaign.toml,\n"
      "data/truth.json): Result(campaign, truth, data). fast = shorter records for tests; tracking_unit: the unit\n"
      "with a tracking record (0: none).");
}

}  // namespace piezobench::python
