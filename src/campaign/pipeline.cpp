#include "piezobench/campaign/pipeline.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "piezobench/apa/piezo.hpp"
#include "piezobench/campaign/report_document.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "piezobench/campaign/superelement_fit.hpp"
#include "piezobench/control/iff.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/fields.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/parallel.hpp"
#include "piezobench/core/statistics.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/mat_struct.hpp"
#include "piezobench/io/output_dir.hpp"
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/lti/rlocus.hpp"
#include "piezobench/metrology/capacitance.hpp"
#include "piezobench/metrology/conformity.hpp"
#include "piezobench/metrology/uncertainty_budget.hpp"
#include "piezobench/report/html_report.hpp"
#include "shown_units.hpp"

namespace piezobench::campaign {

namespace fs = std::filesystem;
using Eigen::Index;
using Eigen::VectorXd;
using nlohmann::json;
using namespace shown_units;

namespace {

// ------------------------------------------------------------------------------------ batch

using Number = std::optional<double> (*)(const UnitAnalysis&);

struct Quantity {
  std::string name;   // results key, e.g. "capacitance_sensor_uF"
  std::string label;  // for people (the report, a rejection's reason)
  std::string unit;   // of the reported values
  double scale;       // SI -> reported unit
  Number value;       // the unit's number (a derived field of UnitAnalysis's declaration), SI
  bool rejects = false;  // a batch outlier rejects the unit (with reject_outliers)
};

// A derived number of UnitAnalysis's declaration: its name, unit and factor are the declaration's.
Quantity quantity(std::string label, Number value, bool rejects = false) {
  const core::Declared d = core::declared<UnitAnalysis>(value);
  return {core::results_key(d.name, d.shown), std::move(label), std::string(d.shown.unit), d.shown.per_si, value, rejects};
}

// In the order of the report: metrology, stiffness, dynamics.
const std::vector<Quantity>& quantities() {
  static const std::vector<Quantity> q = {
      quantity("flatness", &flatness_of),
      quantity("capacitance of the sensor stack", &capacitance_sensor_of, true),
      quantity("capacitance of the actuator stacks", &capacitance_actuator_of, true),
      quantity("stroke", &stroke_of, true),
      quantity("stiffness k1", &k1_of),
      quantity("stiffness k2", &k2_of),
      quantity("stiffness from the resonance", &k_resonance_of),
      quantity("resonance", &resonance_Hz_of),
      quantity("anti-resonance", &antiresonance_Hz_of),
      quantity("static gain u -> d_e", &static_gain_of)};
  return q;
}

using core::median;

struct BatchOutput {
  BatchAnalysis batch;
  std::map<int, std::vector<std::string>> outlier_reasons;  // unit id -> reasons
};

// Interpolates |H| of one output onto the log grid `f` (NaN outside the data).
VectorXd magnitude_on(const dsp::Frf& frf, Index output, const VectorXd& f) {
  VectorXd out(f.size());
  const VectorXd& g = frf.freq_Hz;
  for (Index k = 0; k < f.size(); ++k) {
    const auto it = std::lower_bound(g.data(), g.data() + g.size(), f(k));
    const Index j = it - g.data();
    if (j <= 0 || j >= g.size()) {
      out(k) = std::nan("");
      continue;
    }
    const double w = (f(k) - g(j - 1)) / (g(j) - g(j - 1));
    out(k) = std::abs((1.0 - w) * frf.H[static_cast<std::size_t>(output)](j - 1) + w * frf.H[static_cast<std::size_t>(output)](j));
  }
  return out;
}

BatchOutput batch_analysis(const Campaign& c, const std::vector<UnitAnalysis>& units) {
  BatchOutput out;
  for (const Quantity& q : quantities()) {
    std::vector<double> values;
    std::vector<const UnitAnalysis*> who;
    for (const auto& u : units) {
      if (const std::optional<double> v = q.value(u)) {
        values.push_back(*v * q.scale);
        who.push_back(&u);
      }
    }
    if (values.empty()) continue;
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    const double med = median(values);
    const metrology::OutlierAnalysis a = metrology::robust_outliers(values, c.specs.outliers, c.file.string(), q.name);
    out.batch.spread.push_back({q.name, q.label, q.unit, static_cast<long>(values.size()), *lo, *hi, med,
                                med != 0.0 ? (*hi - *lo) / std::abs(med) : 0.0, a.mad});
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (!a.outlier[i]) continue;
      out.batch.outliers.push_back({who[i]->id, q.name, values[i], a.median, a.robust_z[i]});
      if (c.specs.reject_outliers && q.rejects) {
        out.outlier_reasons[who[i]->id].push_back(
            fmt::format("{} {:.4g} {} is a batch outlier (median of the batch {:.4g} {}, robust z-score {:.1f}, limit {:.1f})", q.label,
                        values[i], q.unit, a.median, q.unit, a.robust_z[i], c.specs.outliers.threshold));
      }
    }
  }
  // Unit-to-unit similarity of the FRFs: rms distance in dB from the batch median magnitude.
  std::vector<const UnitAnalysis*> with_frf;
  for (const auto& u : units) {
    if (frf_of(u)) with_frf.push_back(&u);
  }
  if (with_frf.size() >= 2) {
    const VectorXd f = Eigen::VectorXd::LinSpaced(120, std::log10(c.analysis.fmin_Hz), std::log10(c.analysis.fmax_Hz)).unaryExpr([](double x) { return std::pow(10.0, x); });
    FrfSimilarity sim;
    sim.fmin_Hz = c.analysis.fmin_Hz;
    sim.fmax_Hz = c.analysis.fmax_Hz;
    sim.units.resize(with_frf.size());
    double worst = 0.0;
    for (Index o = 0; o < 2; ++o) {
      std::vector<VectorXd> mags;
      for (const auto* u : with_frf) mags.push_back(magnitude_on(*frf_of(*u), o, f));
      VectorXd med(f.size());
      for (Index k = 0; k < f.size(); ++k) {
        std::vector<double> v;
        for (const auto& m : mags) {
          if (std::isfinite(m(k)) && m(k) > 0.0) v.push_back(m(k));
        }
        med(k) = v.empty() ? std::nan("") : median(v);
      }
      for (std::size_t i = 0; i < with_frf.size(); ++i) {
        double s = 0.0;
        int n = 0;
        for (Index k = 0; k < f.size(); ++k) {
          if (std::isfinite(mags[i](k)) && std::isfinite(med(k)) && mags[i](k) > 0.0) {
            s += std::pow(20.0 * std::log10(mags[i](k) / med(k)), 2);
            ++n;
          }
        }
        const double rms = n > 0 ? std::sqrt(s / n) : std::nan("");
        sim.units[i].unit = with_frf[i]->id;
        (o == 0 ? sim.units[i].de_rms_dB : sim.units[i].vs_rms_dB) = rms;
        if (std::isfinite(rms)) worst = std::max(worst, rms);
      }
    }
    sim.max_rms_dB = worst;
    out.batch.similarity = std::move(sim);
  }
  out.batch.rule = c.specs.outliers;
  out.batch.rejects = c.specs.reject_outliers;
  return out;
}

// ------------------------------------------------------------------------------------ acceptance

// Values no actuator on a bench has (an APA's stroke is tens to hundreds of um, its stiffness 0.1
// to 100 N/um, its stacks' capacitance nF to tens of uF): a value outside these wide limits is a
// unit error in a record, never a measurement (issue 12: `d_e [um]` read as metres was accepted).
std::vector<std::string> implausible(const Campaign& c, const UnitAnalysis& u) {
  const UnitSpec* spec = nullptr;
  for (const UnitSpec& s : c.units) {
    if (s.id == u.id) spec = &s;
  }
  // "column 'probe' of 'stroke3.csv'" for a role of a file entry.
  const auto column = [&](const std::optional<FileSpec> UnitSpec::*entry, const char* role) {
    if (spec == nullptr || !(spec->*entry)) return fmt::format("column {}", role);
    const FileSpec& f = *(spec->*entry);
    const auto it = f.channels.find(role);
    return fmt::format("column '{}' of '{}'", it != f.channels.end() ? it->second : role, f.given);
  };
  std::vector<std::string> out;
  // A unit's figure (a derived field of UnitAnalysis) outside [lo, hi] (SI), told in its declared unit.
  const auto check = [&](std::optional<double> (*figure)(const UnitAnalysis&), double lo, double hi, const std::string& what,
                         const std::string& where) {
    const std::optional<double> v = figure(u);
    if (!v || (*v >= lo && *v <= hi)) return;
    const core::Shown shown = core::declared<UnitAnalysis>(figure).shown;
    out.push_back(fmt::format("implausible: {} {:.4g} {} cannot be a measurement (plausible {:g} to {:g} {}): check the units of {}", what,
                              *v * shown.per_si, shown.unit, lo * shown.per_si, hi * shown.per_si, shown.unit, where));
  };
  check(&stroke_of, 1e-9, 5e-3, "stroke", column(&UnitSpec::stroke, "de"));
  check(&k1_of, 1e3, 1e10, "stiffness k1", column(&UnitSpec::stiffness, "de"));
  check(&k2_of, 1e3, 1e10, "stiffness k2", column(&UnitSpec::stiffness, "de"));
  check(&k_resonance_of, 1e3, 1e10, "stiffness from the resonance", column(&UnitSpec::frf, "de"));
  check(&capacitance_sensor_of, 1e-12, 1e-2, "sensor capacitance", column(&UnitSpec::capacitance, "C_sensor"));
  check(&capacitance_actuator_of, 1e-12, 1e-2, "actuator capacitance", column(&UnitSpec::capacitance, "C_actuator"));
  return out;
}

// One acceptance check: the value (SI) +- U of its budget against [min, max] (SI), decided and shown in
// `unit` (`per_si` of it per SI unit; metrology/conformity.hpp). `fail_text` is the reason of a failed check.
AcceptanceCheck judged(std::string quantity, const char* unit, double per_si, double value, metrology::UncertaintyBudget budget,
                       std::optional<double> min, std::optional<double> max, std::string fail_text) {
  AcceptanceCheck a;
  const auto shown = [&](std::optional<double> v) { return v ? std::optional<double>(*v * per_si) : std::nullopt; };
  a.decision = metrology::decide(value * per_si, budget.expanded * per_si, shown(min), shown(max), budget.coverage_factor);
  if (a.decision.verdict == metrology::Conformity::kFail) {
    a.reason = std::move(fail_text);
  } else if (a.decision.verdict == metrology::Conformity::kMarginal) {
    a.reason = fmt::format("marginal: {} {} +- {} {} (k = 2) has a limit of the specification inside its interval (ISO 14253-1; "
                           "probability of conformity {} %)",
                           quantity, format_number(a.decision.value, 4), format_number(a.decision.expanded_uncertainty, 2), unit,
                           format_number_fixed(100.0 * a.decision.probability_of_conformity, 1));
  }
  a.quantity = std::move(quantity);
  a.unit = unit;
  a.budget = std::move(budget);
  return a;
}

// The added-mass test's k1 (before -> loaded) and k2 (loaded -> after) with their budgets: the
// deflection between the two readings' windows, the creep fit's residual as the readings' noise.
std::vector<std::pair<std::string, metrology::UncertaintyBudget>> static_stiffness_budgets(const Campaign& c, const StiffnessAnalysis& s) {
  const metrology::StaticStiffnessResult& r = s.result;
  const metrology::StaticStiffnessOptions& o = s.options;
  const double fs = s.provenance.sample_rate_Hz;
  const auto samples = [&](const std::array<double, 2>& a, const std::array<double, 2>& b) {
    return std::max(1.0, std::floor(std::min(a[1] - a[0], b[1] - b[0]) * fs));
  };
  std::vector<std::pair<std::string, metrology::UncertaintyBudget>> out;
  const double d1 = std::abs(r.d_before - r.d_loaded), d2 = std::abs(r.d_after - r.d_loaded);
  if (d1 > 0.0) out.emplace_back("k1", metrology::stiffness_budget(o.added_mass, o.gravity, d1, r.rms_residual, samples(o.before_s, o.loaded_s), c.bench.uncertainty));
  if (d2 > 0.0) out.emplace_back("k2", metrology::stiffness_budget(o.added_mass, o.gravity, d2, r.rms_residual, samples(o.after_s, o.loaded_s), c.bench.uncertainty));
  return out;
}

// Every acceptance check of the unit with its budget (docs/uncertainty.md, section 7).
std::vector<AcceptanceCheck> acceptance_checks(const Campaign& c, const UnitAnalysis& u) {
  const Specs& s = c.specs;
  const metrology::StaticTestUncertainties& in = c.bench.uncertainty;
  std::vector<AcceptanceCheck> checks;
  if (s.flatness_max && u.flatness_analysis) {
    const double flatness = u.flatness_analysis->flatness;
    checks.push_back(judged("flatness", "um", kUm, flatness, metrology::flatness_budget(u.flatness_analysis->probe_accuracy), std::nullopt,
                            *s.flatness_max,
                            fmt::format("flatness {} um above the limit {} um ({})", format_number_fixed(flatness * kUm, 2),
                                        format_number_fixed(*s.flatness_max * kUm, 2), metrology::to_string(s.flatness_method))));
  }
  if (u.capacitance_analysis) {
    const CapacitanceAnalysis& ca = *u.capacitance_analysis;
    const auto capacitance = [&](const char* what, double value, double scatter, const std::optional<metrology::Range>& range) {
      if (!range) return;
      checks.push_back(judged(fmt::format("capacitance of the {}", what), "uF", kUf, value,
                              metrology::capacitance_budget(value, scatter, static_cast<double>(ca.readings), in), range->min,
                              std::isfinite(range->max) ? std::optional<double>(range->max) : std::nullopt,
                              fmt::format("capacitance of the {} {} uF outside the specification [{}, {}] uF", what,
                                          format_number(value * kUf, 3), format_number(range->min * kUf, 3), format_number(range->max * kUf, 3))));
    };
    capacitance("sensor stack", ca.sensor, ca.sensor_scatter, s.capacitance_sensor);
    capacitance("actuator stacks", ca.actuator, ca.actuator_scatter, s.capacitance_actuator);
  }
  if (s.stroke_min && u.stroke_analysis) {
    const metrology::StrokeResult& r = u.stroke_analysis->result;
    checks.push_back(judged("stroke", "um", kUm, r.stroke,
                            metrology::stroke_budget(r.stroke, r.noise, static_cast<double>(r.smoothing_samples), in), *s.stroke_min, std::nullopt,
                            fmt::format("stroke {} um below the minimum {} um", format_number_fixed(r.stroke * kUm, 1),
                                        format_number_fixed(*s.stroke_min * kUm, 1))));
  }
  if (s.stiffness) {
    const auto stiffness = [&](const std::string& name, double v, metrology::UncertaintyBudget b) {
      checks.push_back(judged("stiffness " + name, "N/um", kNPerUm, v, std::move(b), s.stiffness->min, s.stiffness->max,
                              fmt::format("stiffness {} {} N/um outside [{}, {}] N/um", name, format_number_fixed(v * kNPerUm, 3),
                                          format_number_fixed(s.stiffness->min * kNPerUm, 3), format_number_fixed(s.stiffness->max * kNPerUm, 3))));
    };
    if (u.stiffness_analysis) {
      for (auto& [name, b] : static_stiffness_budgets(c, *u.stiffness_analysis)) {
        const std::optional<double> v = name == "k1" ? k1_of(u) : k2_of(u);
        if (v) stiffness(name, *v, std::move(b));
      }
    }
    if (const std::optional<double> k = k_resonance_of(u)) {
      const double w = std::sqrt(*k / c.bench.suspended_mass);
      const ident::DelayedSecondOrderFit* de = de_plant_of(u);
      const double se = de ? de->uncertainty.standard_error_of("natural_frequency") : 0.0;
      stiffness("from the resonance", *k,
                metrology::resonance_stiffness_budget(c.bench.suspended_mass, w, std::isfinite(se) ? se : 0.0, in));
    }
  }
  return checks;
}

// The unit's verdict: rejected for a failed analysis, check, outlier or implausible value; marginal
// when none of these but a check is marginal; accepted otherwise. Reasons: the failures, then the
// marginal checks.
void accept_or_reject(const Campaign& c, UnitAnalysis& u, const std::vector<std::string>& outlier_reasons) {
  u.checks = acceptance_checks(c, u);
  std::vector<std::string> fails, marginal;
  for (const auto& f : u.failed) fails.push_back("analysis failed: " + f);
  for (const AcceptanceCheck& a : u.checks) {
    if (a.decision.verdict == metrology::Conformity::kFail) fails.push_back(a.reason);
    if (a.decision.verdict == metrology::Conformity::kMarginal) marginal.push_back(a.reason);
  }
  for (const auto& r : outlier_reasons) fails.push_back(r);
  for (const auto& r : implausible(c, u)) fails.push_back(r);
  u.marginal = fails.empty() && !marginal.empty();
  u.accepted = fails.empty() && marginal.empty();
  u.reasons = std::move(fails);
  u.reasons.insert(u.reasons.end(), marginal.begin(), marginal.end());
}

// ------------------------------------------------------------------------------------ IFF

// Relative distance between an identified damped pole and the model's at the same gain above which
// the report warns that the model does not describe the closed loop.
constexpr double kPoleDistanceTolerance = 0.05;

// The resonance branch of the IFF root locus on a log grid of gains, and its best damping.
struct ResonanceLocus {
  std::vector<double> gains;
  std::vector<lti::CVector> poles;  // branch-matched
  Index branch = 0;
  double optimal_gain = 0.0;
  double max_damping = 0.0;
  std::complex<double> optimal_pole;

  // The branch's pole at gain g: the closed-loop pole nearest to the branch's pole at the nearest
  // grid gain.
  [[nodiscard]] std::complex<double> pole_at(const lti::StateSpace& loop, double g) const {
    std::size_t near = 0;
    for (std::size_t i = 1; i < gains.size(); ++i) {
      if (std::abs(std::log((gains[i] + 1e-300) / (g + 1e-300))) < std::abs(std::log((gains[near] + 1e-300) / (g + 1e-300)))) near = i;
    }
    const std::complex<double> ref = poles[near](branch);
    const lti::CVector p = lti::closed_loop_poles(loop, g);
    Index best = 0;
    for (Index i = 1; i < p.size(); ++i) {
      if (std::abs(p(i) - ref) < std::abs(p(best) - ref)) best = i;
    }
    return p(best);
  }
};

ResonanceLocus resonance_locus(const lti::StateSpace& loop, std::complex<double> resonance_pole) {
  ResonanceLocus r;
  // Gains around the one that makes the loop gain 1 at the resonance.
  lti::Vector w(1);
  w(0) = std::abs(resonance_pole);
  const double l = std::abs(lti::freqresp(loop, w).H[0](0, 0));
  const double g_ref = l > 0.0 && std::isfinite(l) ? 1.0 / l : 1.0;
  r.gains.push_back(0.0);
  for (int i = 0; i <= 400; ++i) r.gains.push_back(g_ref * std::pow(10.0, -3.0 + 6.0 * i / 400.0));
  const lti::RootLocus rl = lti::rlocus(loop, r.gains);
  r.poles = rl.poles;
  for (Index i = 1; i < r.poles[0].size(); ++i) {
    if (std::abs(r.poles[0](i) - resonance_pole) < std::abs(r.poles[0](r.branch) - resonance_pole)) r.branch = i;
  }
  // The optimum is the root locus's (lti::max_damping_on_branch, as control::iff_root_locus and
  // `iff rlocus`): adaptive grid from g = 0, refined by golden section.
  const lti::BranchOptimum best = lti::max_damping_on_branch(loop, resonance_pole);
  r.optimal_gain = best.gain;
  r.optimal_pole = best.pole;
  r.max_damping = best.damping;
  return r;
}

IffStudy iff_study(const Campaign& c, const std::vector<UnitAnalysis>& units) {
  const UnitAnalysis* chosen = nullptr;
  if (c.analysis.iff_unit != 0) {
    for (const auto& u : units) {
      if (u.id == c.analysis.iff_unit) chosen = &u;
    }
  }
  if (!chosen) {
    for (const auto& u : units) {
      const bool identified = std::any_of(u.damped.begin(), u.damped.end(), [](const DampedPlant& d) { return d.identified.has_value(); });
      if (!chosen && identified && iff_plant_of(u)) chosen = &u;
    }
  }
  if (!chosen) {
    for (const auto& u : units) {
      if (!chosen && iff_plant_of(u)) chosen = &u;
    }
  }
  IffStudy out;
  out.controller = c.analysis.controller;
  if (!chosen || !iff_plant_of(*chosen)) {
    out.note = "no unit with a fitted IFF plant (no FRF u -> Vs)";
    return out;
  }
  out.unit = chosen->id;
  const ident::IffPlantFit& p = *iff_plant_of(*chosen);
  out.plant = p;
  const lti::StateSpace plant = lti::to_state_space(p.transfer_function());
  const lti::StateSpace controller = lti::to_state_space(control::iff_controller(out.controller));
  control::IffLoopOptions lo;
  lo.resonance = p.wp;
  const lti::StateSpace loop = control::iff_open_loop(plant, controller, lo);
  const std::complex<double> resonance_pole(-p.xp * p.wp, p.wp * std::sqrt(std::max(0.0, 1.0 - p.xp * p.xp)));
  const ResonanceLocus locus = resonance_locus(loop, resonance_pole);
  out.optimal_gain = locus.optimal_gain;
  out.max_damping = locus.max_damping;
  out.optimal_pole = locus.optimal_pole;
  // The root locus for the plot (report Figure 2.10b): every branch, with its gains for the hover
  // labels, the open-loop poles and zeros, inside a window of 3 wp around the origin (the
  // controller's 2 kHz pole and the Pade approximant's poles lie far outside).
  const double limit = 3.0 * p.wp;
  const auto inside = [&](std::complex<double> z) { return std::abs(z) <= limit && z.imag() >= 0.0; };
  const Index nb = locus.poles.empty() ? 0 : locus.poles.front().size();
  for (Index b = 0; b < nb; ++b) {
    IffStudy::Branch branch;
    for (std::size_t i = 0; i < locus.poles.size(); ++i) {
      const auto z = locus.poles[i](b);
      if (!inside(z)) continue;
      branch.re_im.x.push_back(z.real());
      branch.re_im.y.push_back(z.imag());
      branch.gains.push_back(locus.gains[i]);
    }
    branch.resonance_branch = b == locus.branch;
    if (branch.re_im.x.size() > 1) out.branches.push_back(std::move(branch));
  }
  const auto points = [&](const lti::CVector& v) {
    Curve curve;
    for (const auto z : v) {
      if (!inside(z)) continue;
      curve.x.push_back(z.real());
      curve.y.push_back(z.imag());
    }
    return curve;
  };
  out.open_loop_poles = points(lti::poles(loop));
  out.open_loop_zeros = points(lti::zeros(loop));
  out.pole_distance_tolerance = kPoleDistanceTolerance;
  for (const auto& d : chosen->damped) {
    if (!d.identified) continue;
    const auto pole = d.identified->pole;
    out.gains.push_back(d.gain);
    out.damped_poles.push_back(pole);
    const std::complex<double> z = locus.pole_at(loop, d.gain);
    out.model_poles.push_back(z);
    out.relative_pole_distance.push_back(std::abs(pole - z) / std::abs(z));
    out.max_relative_pole_distance = std::max(out.max_relative_pole_distance, out.relative_pole_distance.back());
  }
  if (out.max_relative_pole_distance > kPoleDistanceTolerance) {
    out.warning = fmt::format(
        "the identified damped poles are up to {} % off the model's root locus (more than {} %): "
        "the IFF plant model (eq. 2.3) does not describe the closed loop at those gains",
        format_number_fixed(100.0 * out.max_relative_pole_distance, 0),
        format_number_fixed(100.0 * kPoleDistanceTolerance, 0));
  }
  return out;
}

// ------------------------------------------------------------------------------------ super element

// Report section 4: the super element on the bench, ga and gs tuned against each unit's measured
// FRFs (superelement_fit.hpp) and compared with eq. 4.1 (Table 4.1's constants); Figure 4.2's
// model for the first unit with an FRF.
SuperElementComparison superelement_comparison(const Campaign& c, const std::vector<UnitAnalysis>& units) {
  const CampaignSuperElement& s = *c.superelement;
  const fem::SuperElement se = s.setup.load();
  SuperElementFitOptions fo;
  fo.moving_mass = c.bench.suspended_mass;
  fo.amplifier_gain = c.bench.amplifier_gain;
  fo.modal_damping = s.modal_damping;
  fo.band_min_Hz = std::max(fo.band_min_Hz, c.analysis.fmin_Hz);
  const fem::Modes modes = fem::modes(superelement_bench_model(se, s.setup, fo));
  // Eq. 4.1 with the stacks' effective modulus (campaign_file.hpp's stack_modulus_Pa): c^E replaced,
  // s^D scaled so that gs scales with the modulus as ga does.
  apa::PiezoConstants pc;
  pc.s_d *= pc.c_e / s.stack_modulus;
  pc.c_e = s.stack_modulus;
  const apa::PiezoSensitivities eq41 = apa::piezo_sensitivities(pc);
  SuperElementComparison out;
  out.source = s.given;
  out.dofs = static_cast<long>(se.size());
  for (Index i = 0; i < std::min<Index>(10, modes.frequencies_Hz.size()); ++i) out.modes_Hz.push_back(modes.frequencies_Hz(i));
  out.moving_mass = fo.moving_mass;
  out.eq41_ga = eq41.ga;
  out.eq41_gs = eq41.gs;
  out.stack_modulus = s.stack_modulus;
  out.warnings = se.warnings;
  std::vector<double> ga, gs, measured_res;
  for (const auto& u : units) {
    if (!frf_of(u)) continue;
    const SuperElementFit fit = fit_superelement(se, s.setup, *frf_of(u), fo);
    SuperElementUnitFit row;
    row.unit = u.id;
    row.name = u.name;
    row.ga = fit.ga;
    row.gs = fit.gs;
    row.ga_relative_to_eq41 = std::abs(fit.ga) / eq41.ga - 1.0;
    row.gs_relative_to_eq41 = std::abs(fit.gs) / eq41.gs - 1.0;
    row.band_Hz = {fit.band_lo_Hz, fit.band_hi_Hz};
    row.resonance_Hz = fit.resonance_Hz;
    if (fit.antiresonance_Hz > 0.0) row.antiresonance_Hz = fit.antiresonance_Hz;
    row.measured_resonance_Hz = resonance_Hz_of(u);
    row.measured_antiresonance_Hz = antiresonance_Hz_of(u);
    row.de_error_dB = fit.de_error_dB;
    row.vs_error_dB = fit.vs_error_dB;
    out.units.push_back(row);
    ga.push_back(std::abs(fit.ga));
    gs.push_back(std::abs(fit.gs));
    if (row.measured_resonance_Hz) measured_res.push_back(*row.measured_resonance_Hz);
    if (!out.figure) out.figure = SuperElementComparison::Response{u.id, u.name, fit.model};
  }
  if (!out.units.empty()) {
    out.ga = median(ga);
    out.gs = median(gs);
    out.resonance_Hz = out.units.front().resonance_Hz;
  }
  if (!measured_res.empty()) out.measured_resonance_Hz = median(measured_res);
  return out;
}

}  // namespace

// ------------------------------------------------------------------------------------ run

namespace {

// The progress log of the options, serialized.
struct LockedLog {
  std::mutex mutex;
  const PipelineOptions& options;
  void operator()(const std::string& line) {
    if (!options.log) return;
    const std::lock_guard<std::mutex> lock(mutex);
    options.log(line);
  }
};

}  // namespace

std::vector<UnitAnalysis> analyze_units(const Campaign& c, const std::vector<std::size_t>& indices, const PipelineOptions& options) {
  LockedLog locked{{}, options};
  const Log log = [&](const std::string& line) { locked(line); };
  const std::size_t n = indices.size();
  for (const std::size_t i : indices) {
    if (i >= c.units.size()) throw std::out_of_range("analyze_units: unit index out of range");
  }
  int threads = options.threads > 0 ? options.threads : c.analysis.threads;
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::max(1, std::min<int>(threads, static_cast<int>(n)));
  std::vector<UnitAnalysis> units(n);
  log(fmt::format("analysing {} units on {} threads", n, threads));
  core::parallel_for(n, threads, [&](std::size_t i) {
    const UnitSpec& spec = c.units[indices[i]];
    units[i] = analyze_unit(c, spec, log);
    if (!units[i].not_analysed) {
      log(fmt::format("{}: done ({} of the experiments not measured, {} analyses failed)", spec.name,
                      units[i].not_measured.size(), units[i].failed.size()));
    }
  });
  return units;
}

CampaignResult finish_campaign(const Campaign& c, std::vector<UnitAnalysis> units, const PipelineOptions& options) {
  LockedLog log{{}, options};
  log("batch: outliers, spread, similarity, acceptance, IFF");
  CampaignResult r;
  r.campaign = c;
  BatchOutput batch = batch_analysis(c, units);
  for (auto& u : units) {
    if (u.not_analysed) {
      // Neither accepted nor rejected: nothing of it was measured into the batch.
      u.accepted = false;
      u.reasons = {"not analysed: " + u.not_analysed->reason};
      r.not_analysed += 1;
      continue;
    }
    const auto it = batch.outlier_reasons.find(u.id);
    accept_or_reject(c, u, it == batch.outlier_reasons.end() ? std::vector<std::string>{} : it->second);
    (u.accepted ? r.accepted : u.marginal ? r.marginal : r.rejected) += 1;
  }
  const auto t_iff = std::chrono::steady_clock::now();
  try {
    r.iff = iff_study(c, units);
    log(fmt::format("IFF: root locus and damped plants ({:.2f} s)", std::chrono::duration<double>(std::chrono::steady_clock::now() - t_iff).count()));
  } catch (const NumericalError& e) {
    r.iff = IffStudy{};
    r.iff.controller = c.analysis.controller;
    r.iff.failed = e.what();
  }
  if (c.superelement) {
    log("super element: " + c.superelement->given + " (ga and gs tuned against every unit's FRF)");
    try {
      r.superelement = superelement_comparison(c, units);
    } catch (const NumericalError& e) {
      r.superelement = SuperElementComparison{};
      r.superelement->failed = e.what();
    }
  }
  r.batch = std::move(batch.batch);
  r.units = std::move(units);
  return r;
}

CampaignResult run_campaign(const Campaign& c, const PipelineOptions& options) {
  std::vector<std::size_t> all(c.units.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return finish_campaign(c, analyze_units(c, all, options), options);
}

void remove_outputs(const fs::path& out_dir) {
  std::error_code ec;
  for (const char* name : {"results.json", "results.mat", "report.html"}) fs::remove(out_dir / name, ec);
}

std::vector<fs::path> write_outputs(const CampaignResult& result, const fs::path& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir)) {
    throw InputError(out_dir.string(), "--out", "a folder that can be created", ec ? ec.message() : "not a folder");
  }
  // All three are written into a staging folder first: a failure (disk full) leaves out_dir as it
  // was. results.json goes before the renames and comes back last, so it marks a complete set.
  const json results = results_json(result);
  io::StagedOutputs staged(out_dir);
  io::write_json_as_mat(results, staged.stage("results.mat"));
  report::write_html(report_document(result), staged.stage("report.html"));
  io::write_text_atomically(staged.stage("results.json"), results.dump(2) + "\n");
  fs::remove(out_dir / "results.json", ec);
  return staged.commit();
}

}  // namespace piezobench::campaign
