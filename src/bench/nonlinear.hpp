#pragma once
// The stacks' nonlinearities on the virtual bench: Prandtl-Ishlinskii or Bouc-Wen hysteresis, and creep.
// Fixed-size state, no allocation, no virtual call: they run inside VirtualBench::step().
#include <Eigen/Core>
#include <array>
#include <vector>
#include <cmath>

namespace piezobench::bench::detail {

// Prandtl-Ishlinskii model (M. Brokate and J. Sprekels, "Hysteresis and Phase Transitions",
// Springer 1996; K. Kuhnen, "Modeling, identification and compensation of complex hysteretic
// nonlinearities", Eur. J. Control 9(4), 2003): the effective stack voltage is
//     Va_eff = Va + sum_i w_i P_{r_i}[Va],
// where P_r is the play (backlash) operator of threshold r, P_r[v](t) = min(max(P(t-), v - r), v + r),
// starting at 0 with the bench at rest. A play operator whose threshold exceeds the excursion of
// the voltage is stuck and contributes nothing, so small signals see the linear model (gain 1) and
// large ones a larger gain with a loop: for a sine of amplitude A about any offset, the loop's half
// range is A + sum_{r_i < A} w_i (A - r_i) and its width at the offset sum_{r_i < A} 2 w_i min(r_i, A - r_i)
// (exact once every operator has turned at least once). Width relative to stroke thus grows with
// the amplitude (Figure 2.3).
class PlayHysteresis {
 public:
  static constexpr int kOperators = 8;
  using Array = Eigen::Array<double, kOperators, 1>;
  // The bench's default: thresholds 10, 20, ..., 80 V, each weight 0.163 * scale (large-signal
  // stroke over -20..150 V 1.6 times the small-signal gain; width/stroke 7.5 % at 20 V, 18 % at
  // 80 V; below 10 V, the FRFs' excitation levels, linear).
  static PlayHysteresis bench_default(double scale);

  PlayHysteresis() = default;
  // Up to kOperators operators (the rest: weight 0); the sizes are checked by UnitTruth::validate.
  static PlayHysteresis from(const std::vector<double>& thresholds, const std::vector<double>& weights);
  PlayHysteresis(const std::array<double, kOperators>& thresholds, const std::array<double, kOperators>& weights);

  // Advances every operator to the voltage v and returns sum_i w_i P_{r_i}[v] (V), the amount to
  // add to v to get the effective voltage. (Eigen arrays: the operators run two by two in SIMD
  // registers and the sum is a tree, which the bench's inner loop needs to stay fast.)
  double update(double v) noexcept {
    state_ = state_.max(v - thresholds_).min(v + thresholds_);
    return (weights_ * state_).sum();
  }
  void reset() noexcept { state_.setZero(); }
  [[nodiscard]] double threshold(int i) const { return thresholds_(i); }
  [[nodiscard]] double weight(int i) const { return weights_(i); }

 private:
  Array thresholds_ = Array::Zero();
  Array weights_ = Array::Zero();
  Array state_ = Array::Zero();
};

// Bouc-Wen hysteresis (R. Bouc 1967, Y.-K. Wen 1976; in the form used for piezoelectric stacks by
// T. S. Low and W. Guo, J. Microelectromech. Syst. 4(4), 1995), the bench's second law: a family
// the Prandtl-Ishlinskii identification does not contain, so that the compensation's tests are not
// circular. The effective stack voltage is
//     Va_eff = (1 + a) Va - h,   dh = a dVa - beta |dVa| h - beta dVa |h|   (n = 1, gamma = beta),
// rate-independent. After a reversal h moves with slope a until it changes sign (the branch's
// slope is 1: the small-signal gain), then saturates exponentially towards +-a / (2 beta) (slope
// 1 + a: the large-signal gain). Each sample integrates the equation exactly for a linear change
// of Va (a linear piece, then an exponential one), so the result does not depend on the rate.
// Loops are point-symmetric about their centre, widening then narrowing relative to their stroke
// as the amplitude grows (docs/virtual-bench.md: 18 % of the stroke at 80 V, the PI law's figure).
class BoucWenHysteresis {
 public:
  // The bench's default: a = 1.0 scale, beta = 0.02 /V.
  static BoucWenHysteresis bench_default(double scale);

  BoucWenHysteresis() = default;
  BoucWenHysteresis(double a, double beta);

  // Advances to the voltage v and returns Va_eff - v = a v - h (V).
  double update(double v) noexcept {
    double dv = v - last_;
    last_ = v;
    if (dv != 0.0 && a_ > 0.0) {
      const double dir = dv > 0.0 ? 1.0 : -1.0;
      double adv = dir * dv;  // |dv|
      double g = dir * h_;    // h in the direction of motion
      if (g < 0.0) {          // linear piece until h changes sign
        const double need = -g / a_;
        if (adv <= need) {
          g += a_ * adv;
          adv = 0.0;
        } else {
          g = 0.0;
          adv -= need;
        }
      }
      if (adv > 0.0) g = h_max_ + (g - h_max_) * std::exp(-2.0 * beta_ * adv);
      h_ = dir * g;
    }
    return a_ * v - h_;
  }
  void reset() noexcept { h_ = last_ = 0.0; }
  [[nodiscard]] double a() const { return a_; }
  [[nodiscard]] double beta() const { return beta_; }

 private:
  double a_ = 0.0, beta_ = 0.0, h_max_ = 0.0;
  double h_ = 0.0, last_ = 0.0;
};

// The bench's hysteresis, one law or the other (BenchOptions::hysteresis_law).
class Hysteresis {
 public:
  Hysteresis() = default;
  Hysteresis(PlayHysteresis play) : play_(play), bouc_wen_(false) {}            // NOLINT(google-explicit-constructor)
  Hysteresis(BoucWenHysteresis bw) : bw_(bw), bouc_wen_(true) {}                // NOLINT(google-explicit-constructor)
  // Bouc-Wen plus quadratic v^2 (1/V) on the effective voltage: loops asymmetric about their centre.
  Hysteresis(BoucWenHysteresis bw, double quadratic) : bw_(bw), quadratic_(quadratic), bouc_wen_(true) {}
  // Va_eff - v (V) after advancing to the voltage v.
  double update(double v) noexcept { return (bouc_wen_ ? bw_.update(v) : play_.update(v)) + quadratic_ * v * v; }
  void reset() noexcept {
    play_.reset();
    bw_.reset();
  }

 private:
  PlayHysteresis play_;
  BoucWenHysteresis bw_;
  double quadratic_ = 0.0;
  bool bouc_wen_ = false;
};

// Creep of the actuator stacks as a generalized Kelvin chain (a Prony series, the usual linear
// viscoelastic form of logarithmic creep): an extra actuator force F_c = sum_i c_i with
//     tau_i c_i' = load_i (s_load - F_c - f_free) + voltage_i f_free,
// where f_free = ga Va_eff is the force of the stack voltage (its free stroke times the stacks'
// stiffness) and s_load - f_free - F_c = ka (xn - delta_creep) - f_free is the stacks' elastic
// strain times their stiffness (s_load = ka xn). After a voltage step the stroke grows by
// voltage_i per time constant; under a constant load the stacks keep compressing. With the
// time constants one decade apart and equal coefficients, the creep grows by about the
// coefficient per decade of time between the first and the last time constant.
// Each state is advanced exactly for a target held over its update period
// (c += (1 - exp(-T/tau)) (target - c), T = kDecimation Ts).
class Creep {
 public:
  static constexpr int kStates = 3;
  static constexpr std::array<double, kStates> kTimeConstants = {5.0, 50.0, 500.0};  // s
  // The states advance once every kDecimation samples, driven by the mean of the drive over them
  // (the fastest time constant is 50,000 samples at 10 kHz; the mean keeps fast content from
  // aliasing into the creep). The force is held in between.
  static constexpr int kDecimation = 8;

  Creep() = default;
  // Per decade coefficients (relative), sample time (s).
  Creep(double voltage_per_decade, double load_per_decade, double sample_time);

  [[nodiscard]] double force() const noexcept { return force_; }
  void update(double f_free, double s_load) noexcept {
    sum_free_ += f_free;
    sum_load_ += s_load;
    if (++count_ < kDecimation) return;
    constexpr double kInv = 1.0 / kDecimation;
    const double free = sum_free_ * kInv;
    const double elastic = sum_load_ * kInv - force_ - free;
    c_ += alpha_ * (load_ * elastic + voltage_ * free - c_);
    force_ = c_.sum();
    sum_free_ = sum_load_ = 0.0;
    count_ = 0;
  }
  void reset() noexcept {
    c_.setZero();
    force_ = sum_free_ = sum_load_ = 0.0;
    count_ = 0;
  }

 private:
  // Padded to 4 (two SIMD registers); the fourth state has alpha = 0 and stays 0.
  using Array = Eigen::Array<double, 4, 1>;
  Array alpha_ = Array::Zero();
  Array voltage_ = Array::Zero();
  Array load_ = Array::Zero();
  Array c_ = Array::Zero();
  double force_ = 0.0;
  double sum_free_ = 0.0, sum_load_ = 0.0;
  int count_ = 0;
};

}  // namespace piezobench::bench::detail
