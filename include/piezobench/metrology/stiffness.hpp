#pragma once
// Axial stiffness of an actuator (report section 2.2).
//
// Static stiffness from an added mass, k = m_a g / delta_d_e (eq. 2.1): a mass m_a is put on the
// suspended mass at t_on (~3 s) and taken off at t_off (~13 s) while the encoder records d_e
// (Figure 2.4). The piezoelectric stacks creep, so d_e keeps moving while the mass is on and "the"
// deflection depends on when it is read: the report's two readings k1 (mass on) and k2 (mass off)
// differ by ~12 % (Table 2.1). Both are returned, read at defined times, and the creep is measured:
//
//  Readings (the report's k1, k2; the same windows as the virtual bench's truth): the means of d_e
//    before  = [t_on  + before_s[0],  t_on  + before_s[1])    default [t_on - 1.0, t_on - 0.1)
//    loaded  = [t_off + loaded_s[0],  t_off + loaded_s[1])    default [t_off - 1.0, t_off - 0.1)
//    after   = [t_off + after_s[0],   t_off + after_s[1])     default [t_off + 1.0, t_off + 2.0)
//    k1 = m_a g / |d_before - d_loaded|,   k2 = m_a g / |d_after - d_loaded|.
//  Creep: the whole record is fitted with a linear viscoelastic (superposed) step response with
//  logarithmic creep
//    d_e(t) = d0 + sum_k H(t - t_k) [ D_k + c_k log10(1 + (t - t_k) / tau) ],   k = on, off
//  by linear least squares in (d0, D_on, c_on, D_off, c_off) for each tau of a logarithmic grid
//  (min_time_constant .. max_time_constant, 41 values searched coarse to fine: every 4th, then those
//  around the best, or all 41 when the coarse misfits have more than one minimum; then a parabola
//  through the best three in log tau), leaving out `settle_s` after each event (the load being applied and the oscillation of
//  the suspended mass). D_k is the deflection at the event without the creep that follows it (the
//  fitted curve extrapolated back to t_k): k_elastic_on = m_a g / |D_on|, k_elastic_off likewise;
//  c_k is the creep per decade of time. The creep between the two readings of k1 is what makes
//  k1 < k2; k_elastic is what the stiffness would read without creep.
// Event times: options.t_on/t_off when set, else from the operator's mass log (t_on: first sample
// above 1 % of its maximum; t_off: first later sample below 99 %), i.e. where the load starts to
// change; else from d_e: the windows of `settle_s` with the largest fall and the largest rise of
// d_e, each event being the first sample of its window where d_e has left the level before it by
// 2 % of the change.
//
// Stiffness from the resonance, k = m w^2 (eq. 2.2).
// Units: SI (s, m, kg, N/m).
#include "piezobench/core/fields.hpp"
#include <Eigen/Dense>
#include <array>
#include <string>

namespace piezobench::metrology {

struct StaticStiffnessOptions {
  double added_mass = 6.4;        // kg, m_a
  double gravity = 9.8;           // m/s^2
  double settle_s = 1.0;          // s, left out of the creep fit after each event
  std::array<double, 2> before_s{-1.0, -0.1};  // s, reading windows relative to the events (see above)
  std::array<double, 2> loaded_s{-1.0, -0.1};
  std::array<double, 2> after_s{1.0, 2.0};
  double t_on = 0.0;              // s, 0 = detect
  double t_off = 0.0;             // s, 0 = detect
  double min_time_constant = 1e-3;  // s, creep time-constant grid
  double max_time_constant = 10.0;  // s
  void validate() const;          // InputError (source "static stiffness options") naming the field
};

struct StaticStiffnessResult {
  double t_on = 0.0;             // s, events used
  double t_off = 0.0;            // s
  double d_before = 0.0;         // m, the three readings
  double d_loaded = 0.0;         // m
  double d_after = 0.0;          // m
  double k1 = 0.0;               // N/m, m_a g / |d_before - d_loaded|
  double k2 = 0.0;               // N/m, m_a g / |d_after - d_loaded|
  double deflection_on = 0.0;    // m, D_on (negative: the mass compresses the APA)
  double deflection_off = 0.0;   // m, D_off
  double k_elastic_on = 0.0;     // N/m, m_a g / |D_on|
  double k_elastic_off = 0.0;    // N/m, m_a g / |D_off|
  double creep_on = 0.0;         // m per decade, c_on
  double creep_off = 0.0;        // m per decade, c_off
  double creep_time_constant = 0.0;  // s, tau
  double rms_residual = 0.0;     // m, of the fit over the samples used
  Eigen::VectorXd fit;           // m, the fitted curve at every sample (for plots)
};

// t: s, strictly increasing; de: m; mass_log: kg or empty (no log). All the same length, finite.
// InputError (source, field "t", "de", "added_mass", "t_on", "t_off") when a reading window or the
// settling time does not fit in the record or the events cannot be found; NumericalError when the
// fit is singular.
StaticStiffnessResult static_stiffness(const Eigen::Ref<const Eigen::VectorXd>& t,
                                       const Eigen::Ref<const Eigen::VectorXd>& de,
                                       const Eigen::Ref<const Eigen::VectorXd>& mass_log,
                                       const StaticStiffnessOptions& options = {}, const std::string& source = "");

// k = m w^2, N/m (mass kg > 0, resonance rad/s > 0; InputError naming "mass" / "resonance").
double stiffness_from_resonance(double mass, double resonance_rad_s, const std::string& source = "");

constexpr auto describe(core::Type<StaticStiffnessResult>) {
  using S = StaticStiffnessResult;
  using namespace core::shown;
  return core::fields<S>("StaticStiffnessResult", "the static stiffness test: a mass put on and taken off",
      core::field("t_on", &S::t_on, kSecond, "the mass put on"),
      core::field("t_off", &S::t_off, kSecond, "the mass taken off"),
      core::field("d_before", &S::d_before, kMetreAsUm, "reading before the mass").key("readings_um.before"),
      core::field("d_loaded", &S::d_loaded, kMetreAsUm, "reading with the mass").key("readings_um.loaded"),
      core::field("d_after", &S::d_after, kMetreAsUm, "reading after the mass").key("readings_um.after"),
      core::field("k1", &S::k1, kNewtonPerMetreAsNPerUm, "m_a g / |d_before - d_loaded|"),
      core::field("k2", &S::k2, kNewtonPerMetreAsNPerUm, "m_a g / |d_after - d_loaded|"),
      core::field("deflection_on", &S::deflection_on, kMetreAsUm, "elastic deflection D_on (negative: compressed)").part_only(),
      core::field("deflection_off", &S::deflection_off, kMetreAsUm, "elastic deflection D_off").part_only(),
      core::field("k_elastic_on", &S::k_elastic_on, kNewtonPerMetreAsNPerUm, "m_a g / |D_on|").key("elastic_N_per_um.on"),
      core::field("k_elastic_off", &S::k_elastic_off, kNewtonPerMetreAsNPerUm, "m_a g / |D_off|").key("elastic_N_per_um.off"),
      core::field("creep_on", &S::creep_on, kMetreAsUm, "creep per decade of time after the mass is put on").key("creep_um_per_decade.on"),
      core::field("creep_off", &S::creep_off, kMetreAsUm, "creep per decade after it is taken off").key("creep_um_per_decade.off"),
      core::field("creep_time_constant", &S::creep_time_constant, kSecond, "tau of the creep model"),
      core::field("rms_residual", &S::rms_residual, kMetreAsUm, "rms residual of the creep model's fit").key("fit_rms_um"),
      core::field("fit", &S::fit, kNone, "the fitted curve at every sample (m)").part_only());
}

constexpr auto describe(core::Type<StaticStiffnessOptions>) {
  using S = StaticStiffnessOptions;
  using namespace core::shown;
  return core::fields<S>("StaticStiffnessOptions", "how the static stiffness record is read",
      core::field("added_mass", &S::added_mass, kKilogram, "m_a, the mass put on"),
      core::field("gravity", &S::gravity, kMetrePerSecond2, "g"),
      core::field("settle_s", &S::settle_s, kNone, "s, left out of the creep fit after each event").part_only(),
      core::field("before_s", &S::before_s, kNone, "s, reading window before the mass, relative to t_on").key("reading_windows_s.before"),
      core::field("loaded_s", &S::loaded_s, kNone, "s, reading window with the mass, relative to t_off").key("reading_windows_s.loaded"),
      core::field("after_s", &S::after_s, kNone, "s, reading window after the mass, relative to t_off").key("reading_windows_s.after"),
      core::field("t_on", &S::t_on, kSecond, "given event time (0: detected)").part_only(),
      core::field("t_off", &S::t_off, kSecond, "given event time (0: detected)").part_only(),
      core::field("min_time_constant", &S::min_time_constant, kSecond, "creep time-constant grid, lowest").part_only(),
      core::field("max_time_constant", &S::max_time_constant, kSecond, "creep time-constant grid, highest").part_only());
}

}  // namespace piezobench::metrology
