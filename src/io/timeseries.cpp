#include "piezobench/io/timeseries.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <unordered_map>

#include "csv_table.hpp"
#include "mat_file.hpp"
#include "uff58.hpp"
#include "mapped_file.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/memory.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/io/units.hpp"

namespace piezobench::io {
namespace fs = std::filesystem;
using text::quote;

namespace {

constexpr const char* kTime = "t";
constexpr const char* kFs = "fs";
constexpr const char* kUnits = "units";
constexpr const char* kSettings = "settings";
constexpr const char* kChannelOrder = "channels";  // comma-separated names, in order (v7.3 lists alphabetically)
// Samples read from a .mat file at once (256 KiB): large enough for full-speed reads, small enough
// for the checks that follow each piece to find it in the L2 cache.
constexpr Eigen::Index kReadChunk = Eigen::Index{1} << 15;
// Stamps within this many sample periods of the line through their end points are exact (the
// reader's fast pass, time_samples_ok); others go through fit_time.
constexpr double kExactTime = 1e-6;

// True when every sample is finite: x * 0 is 0 for a finite x and NaN for NaN and +-Inf, and
// Eigen's sum runs on vectors (the caller finds the bad sample with check_finite only when there
// is one).
bool all_finite(const double* x, Eigen::Index n) {
  return (Eigen::Map<const Eigen::ArrayXd>(x, n) * 0.0).sum() == 0.0;
}

// NaN/Inf check with the channel and the first bad sample in the message.
void check_finite(const std::string& source, const std::string& channel, const Eigen::Ref<const Eigen::VectorXd>& v) {
  if (all_finite(v.data(), v.size())) return;
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (!std::isfinite(v(k))) {
      throw InputError(source, channel, "finite samples",
                       (std::isnan(v(k)) ? std::string("NaN") : std::string(v(k) > 0 ? "Inf" : "-Inf")) +
                           " at sample " + std::to_string(k));
    }
  }
}

// Records reach 10^7 samples per channel: their buffers are allocated once, filled straight from
// the file and faulted in 2 MiB at a time where the kernel allows it (core::advise_huge_pages),
// which halves the cost of reading a large file (first-touch page faults were half of it).
void advise_huge_pages(double* data, Eigen::Index count) {
  core::advise_huge_pages(data, static_cast<std::size_t>(count) * sizeof(double));
}

// The checks of sample_rate_from_time (finite, strictly increasing, uniform) over
// t[first, first + count) in one pass on 2-wide vectors (GCC/Clang vector extensions), given t(0)
// and dt. A true result means sample_rate_from_time accepts these samples: x * 0 is NaN exactly
// for a non-finite x; for finite samples t[k] - t[k-1] > 0 exactly when t[k] > t[k-1]; the
// deviation is computed as there, and max_k (|d_k| / dt) = (max_k |d_k|) / dt because rounded
// division by dt > 0 is monotonic.
bool time_samples_ok(const double* t, Eigen::Index n, Eigen::Index first, Eigen::Index count, double dt, double tol) {
  typedef double Pair __attribute__((vector_size(16), aligned(8), may_alias));
  if (!(std::isfinite(dt) && dt > 0.0)) return false;
  const double t0 = t[0];
  const Eigen::Index a = std::max<Eigen::Index>(first, 1);
  const Eigen::Index end = first + count;
  const Eigen::Index uniform_end = std::min(end, n - 1);  // the last sample is exact by construction
  double nonfinite = first == 0 ? t[0] * 0.0 : 0.0;
  double step = std::numeric_limits<double>::infinity();  // smallest t[k] - t[k-1]
  double worst = 0.0;                                      // largest |t[k] - (t0 + k dt)|
  Eigen::Index k = a;
  if (uniform_end - a >= 2) {
    Pair zero = {0.0, 0.0}, min_step = {step, step}, max_dev = {0.0, 0.0};
    Pair kk = {static_cast<double>(k), static_cast<double>(k + 1)};
    const Pair two = {2.0, 2.0};
    for (; k + 2 <= uniform_end; k += 2, kk += two) {
      const Pair x = *reinterpret_cast<const Pair*>(t + k);
      const Pair d = x - *reinterpret_cast<const Pair*>(t + k - 1);
      const Pair e = x - (t0 + kk * dt);
      const Pair dev = e > -e ? e : -e;
      zero += x * 0.0;
      min_step = d < min_step ? d : min_step;
      max_dev = dev > max_dev ? dev : max_dev;
    }
    nonfinite += zero[0] + zero[1];
    step = std::min(min_step[0], min_step[1]);
    worst = std::max(max_dev[0], max_dev[1]);
  }
  for (; k < end; ++k) {
    nonfinite += t[k] * 0.0;
    step = std::min(step, t[k] - t[k - 1]);
    if (k < uniform_end) worst = std::max(worst, std::abs(t[k] - (t0 + static_cast<double>(k) * dt)));
  }
  return nonfinite == 0.0 && step > 0.0 && worst / dt <= tol;
}

// What a time vector says about the sampling: the rate of a least-squares line through the
// stamps (t[k] = a + k dt), the precision the stamps are stored with and how far the worst stamp
// lies from the line beyond that precision.
struct TimeFit {
  double rate = 0.0;       // Hz, 1 / dt of the fitted line
  double precision = 0.0;  // s: half the quantum the file stores the stamps with, plus double round-off
  double deviation = 0.0;  // s: largest |t[k] - (a + k dt)|
  double jitter = 0.0;     // that deviation beyond `precision`, in sample periods
  Eigen::Index worst = 0;  // the stamp of that deviation
};

// Half the quantum of stored stamps (s): the largest of their printed decimals (10^-d, from the
// smallest d that every stamp examined is a multiple of), float32 storage (half an ulp of the
// largest stamp) and double round-off. `scale`: seconds per stored unit (ms files: 1e-3), so that
// the decimals and float32 are judged on the numbers as the file holds them.
double stored_precision(const Eigen::Ref<const Eigen::VectorXd>& t, double scale, double dt) {
  const Eigen::Index n = t.size();
  const Eigen::Index step = std::max<Eigen::Index>(1, n / 4096);  // a sample of the stamps suffices
  double largest = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) largest = std::max(largest, std::abs(t(k)));
  const double eps = std::numeric_limits<double>::epsilon();
  double half_quantum = 0.0;
  bool float32 = true;
  for (Eigen::Index k = 0; k < n && float32; k += step) {
    const double raw = t(k) / scale;
    float32 = std::abs(raw - static_cast<double>(static_cast<float>(raw))) <= 4.0 * eps * std::abs(raw);
  }
  if (float32) {
    int exponent = 0;
    (void)std::frexp(largest / scale, &exponent);
    half_quantum = 0.5 * std::ldexp(1.0, exponent - 24) * scale;
  }
  for (int d = 0; d <= 15; ++d) {
    const double quantum = std::pow(10.0, -d);
    bool multiple = true;
    for (Eigen::Index k = 0; k < n && multiple; k += step) {
      const double units = t(k) / scale / quantum;
      multiple = std::abs(units - std::round(units)) <= 16.0 * eps * std::abs(units) + 1e-9;
    }
    if (multiple) {
      // A grid whose step is a whole number of quanta (10 kHz stamps with 4 decimals) is stored
      // exactly: no rounding to allow for.
      const double steps = dt / (quantum * scale);
      if (!(steps >= 0.5 && std::abs(steps - std::round(steps)) <= 1e-6 * steps)) half_quantum = std::max(half_quantum, 0.5 * quantum * scale);
      break;
    }
  }
  return half_quantum + 8.0 * eps * largest;
}

bool is_time_name(const std::string& name);
bool is_rate_name(const std::string& name);

// Strictly increasing stamps (InputError otherwise), fitted by a line (see TimeFit).
TimeFit fit_time(const std::string& source, const Eigen::Ref<const Eigen::VectorXd>& t, double scale) {
  check_finite(source, kTime, t);
  const Eigen::Index n = t.size();
  for (Eigen::Index k = 1; k < n; ++k) {
    if (!(t(k) > t(k - 1))) {
      throw InputError(source, kTime, "a strictly increasing time vector",
                       "t[" + std::to_string(k) + "] = " + format_number(t(k), 10) + " after t[" + std::to_string(k - 1) +
                           "] = " + format_number(t(k - 1), 10));
    }
  }
  // Offsets from t[0] (exact for epoch stamps: t[0] <= t[k] <= 2 t[0]), against centred indices.
  const double t0 = t(0), kbar = 0.5 * static_cast<double>(n - 1);
  double xbar = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) xbar += t(k) - t0;
  xbar /= static_cast<double>(n);
  double sxy = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) sxy += (static_cast<double>(k) - kbar) * (t(k) - t0 - xbar);
  const double nn = static_cast<double>(n);
  const double dt = sxy / (nn * (nn * nn - 1.0) / 12.0);
  TimeFit fit;
  fit.rate = 1.0 / dt;
  // Stamps coarser than a quarter period cannot show a dropped sample (a step of half a period
  // from the line at least): their precision counts as a quarter period at most.
  fit.precision = std::min(stored_precision(t, scale, dt), 0.25 * dt);
  double worst = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double r = std::abs(t(k) - t0 - (xbar + (static_cast<double>(k) - kbar) * dt));
    if (r > worst) {
      worst = r;
      fit.worst = k;
    }
  }
  fit.deviation = worst;
  fit.jitter = std::max(0.0, worst - fit.precision) / dt;
  return fit;
}

std::string percent(double fraction) { return format_number(100.0 * fraction, 3) + " %"; }

// The sample rate of a time vector: exact stamps (prechecked by the reader's own pass, or within
// kExactTime periods of the line through the end points) give the end-to-end rate; others the
// fitted one, when their jitter beyond the stored precision is at most `tol` sample periods.
// `forced`: an explicit --fs replaces the stamps' rate, so jitter beyond `tol` is a warning.
struct TimeRate {
  double rate = 0.0;  // Hz
  double relative_uncertainty = 0.0;
};
TimeRate sample_rate_from_time(const std::string& source, const Eigen::Ref<const Eigen::VectorXd>& t, double tol, bool prechecked,
                               double scale, bool forced, std::vector<std::string>& warnings) {
  const Eigen::Index n = t.size();
  const double end_to_end = 1.0 / ((t(n - 1) - t(0)) / static_cast<double>(n - 1));
  if (prechecked) return {end_to_end, 0.0};
  const TimeFit fit = fit_time(source, t, scale);
  const double dt = 1.0 / fit.rate;
  if (fit.jitter > tol) {
    const std::string found = "t[" + std::to_string(fit.worst) + "] = " + format_number(t(fit.worst), 12) + " s is " +
                              percent(fit.jitter) + " of a sample period off the stamps' fitted rate " +
                              format_number(fit.rate, 10) + " Hz (beyond the stored precision " +
                              format_number(fit.precision, 3) + " s)";
    if (!forced) {
      throw InputError(source, kTime,
                       "uniform sampling: jitter at most " + percent(tol) + " of a sample period beyond the stored precision "
                       "(docs/formats.md, \"Time stamps\"; --fs overrides the time vector)",
                       found);
    }
    warnings.push_back(source + ": t: non-uniform time stamps (" + found + "), ignored for the sample rate given");
  }
  // Uniform to round-off: the end-to-end rate (what exact stamps give, as the reader's own pass).
  if (fit.deviation <= kExactTime * dt) return {end_to_end, 0.0};
  // The fitted rate is good to about the worst deviation over the record's length.
  return {fit.rate, 2.0 * fit.deviation / (t(n - 1) - t(0))};
}

bool agree(double a, double b, double tol) { return std::abs(a - b) <= tol * std::abs(b); }

// Sample rate from, in order of precedence for the value returned: an explicit fs, the file's own
// `fs`, the time vector. The file's fs must agree with the time vector; an explicit fs that
// disagrees with either is used, with a warning naming both. `t_scale`: seconds per unit of the
// stamps as the file stores them (time_unit_factor).
double resolve_sample_rate(const std::string& source, const Eigen::Ref<const Eigen::VectorXd>& t, double fs_option,
                           std::optional<double> fs_file, double tol, std::vector<std::string>& warnings,
                           bool t_prechecked = false, double t_scale = 1.0) {
  std::optional<double> fs_time;
  double time_uncertainty = 0.0;
  if (t.size() >= 2) {
    const TimeRate r = sample_rate_from_time(source, t, tol, t_prechecked, t_scale, fs_option > 0.0, warnings);
    fs_time = r.rate;
    time_uncertainty = r.relative_uncertainty;
  }
  if (t.size() == 1) check_finite(source, kTime, t);
  if (fs_file && !(std::isfinite(*fs_file) && *fs_file > 0.0)) {
    throw InputError(source, kFs, "a positive finite sample rate in Hz", format_number(*fs_file, 10));
  }
  const double rate_tol = kExactTime + time_uncertainty;
  const auto disagreement = [](double a, double b) { return format_number(100.0 * (a - b) / b, 3) + " %"; };
  if (fs_option > 0.0 && fs_time && !agree(fs_option, *fs_time, rate_tol)) {
    warnings.push_back(source + ": --fs " + format_number(fs_option, 10) + " Hz overrides the time vector's " +
                       format_number(*fs_time, 10) + " Hz (" + disagreement(fs_option, *fs_time) + ")");
  }
  if (fs_option > 0.0 && fs_file && !agree(fs_option, *fs_file, kExactTime)) {
    warnings.push_back(source + ": --fs " + format_number(fs_option, 10) + " Hz overrides the file's fs = " +
                       format_number(*fs_file, 10) + " Hz (" + disagreement(fs_option, *fs_file) + ")");
  }
  if (fs_option <= 0.0 && fs_file && fs_time && !agree(*fs_file, *fs_time, rate_tol)) {
    throw InputError(source, kFs, "a sample rate consistent with t (" + format_number(*fs_time, 10) + " Hz from t)",
                     "fs = " + format_number(*fs_file, 10) + " Hz in the file (give --fs to choose)");
  }
  if (fs_option > 0.0) return fs_option;
  if (fs_file) return *fs_file;
  if (fs_time) return *fs_time;
  throw InputError(source, "fs", "a time vector t (2 samples or more) or a sample rate (--fs)", "neither");
}

bool is_time_name(const std::string& name) {
  const std::string l = text::to_lower(name);
  return l == "t" || l == "time";
}

// Whether a variable or field is called `units` (or `unit`, any case).
bool is_units_name(const std::string& name) {
  const std::string l = text::to_lower(name);
  return l == "units" || l == "unit";
}

bool is_rate_name(const std::string& name) {
  const std::string l = text::to_lower(name);
  return l == "fs" || l == "sample_rate" || l == "sample_rate_hz" || l == "samplerate" || l == "sampling_rate";
}

// A sample rate written as text: "fs: 10000", "Fs = 10 kHz", "sample_rate_Hz: 10000",
// "sample rate [Hz]: 1000" (keys in any case; Hz unless a frequency unit follows). nullopt when the
// text is not about the sample rate; InputError (source, field) when its value is not a rate.
std::optional<double> rate_from_text(const std::string& text, const std::string& source, const std::string& field) {
  const size_t sep = text.find_first_of(":=");
  if (sep == std::string::npos) return std::nullopt;
  std::string key(text::trim(std::string_view(text).substr(0, sep)));
  std::string unit;
  if (const size_t open = key.find_first_of("[("); open != std::string::npos) {
    const size_t close = key.find_first_of("])", open);
    unit = std::string(text::trim(std::string_view(key).substr(open + 1, close == std::string::npos ? std::string::npos : close - open - 1)));
    key = std::string(text::trim(std::string_view(key).substr(0, open)));
  }
  std::string lower = text::to_lower(key);
  std::replace(lower.begin(), lower.end(), ' ', '_');
  if (lower.size() > 3 && lower.compare(lower.size() - 3, 3, "_hz") == 0) {
    lower.resize(lower.size() - 3);
    if (unit.empty()) unit = "Hz";
  }
  if (lower != "fs" && lower != "sample_rate" && lower != "samplerate" && lower != "sampling_rate" &&
      lower != "sampling_frequency") {
    return std::nullopt;
  }
  std::string_view value = text::trim(std::string_view(text).substr(sep + 1));
  if (const size_t blank = value.find_first_of(" \t"); blank != std::string_view::npos) {
    if (!unit.empty()) throw InputError(source, field, "one unit for the sample rate", quote(text));
    unit = std::string(text::trim(value.substr(blank)));
    value = value.substr(0, blank);
  }
  const std::optional<double> v = text::parse_double(value);
  if (!v || !(std::isfinite(*v) && *v > 0.0)) throw InputError(source, field, "a positive sample rate", quote(value));
  if (unit.empty()) return *v;
  const Unit u = unit_from_string(unit, source, field);
  if (u.quantity != Quantity::kFrequency) throw InputError(source, field, "a sample rate in Hz or kHz", "unit " + quote(unit));
  return *v * u.to_si;
}

// Factor from a time column's unit to seconds ("" = seconds).
double time_unit_factor(const std::string& unit, const std::string& source, const std::string& field) {
  if (unit.empty()) return 1.0;
  const Unit u = unit_from_string(unit, source, field);
  if (u.quantity != Quantity::kTime) {
    throw InputError(source, field, "a time unit (us, ms, s, min) for the time vector", "unit " + quote(unit));
  }
  return u.to_si;
}

// SI units: each channel's unit (ReadOptions::unit_overrides, else the file's, else
// ReadOptions::units) is looked up in the unit table and replaced by its SI symbol; a unit the
// table does not know is an InputError naming the channel and the units known. A channel no unit
// is given for stays "" (SI assumed) with a warning; all "": `units` is cleared. Returns the
// factor from each channel's unit to SI.
std::vector<double> to_si_units(const std::string& source, const std::vector<std::string>& names,
                                std::vector<std::string>& units, const ReadOptions& options, std::vector<std::string>& warnings) {
  if (units.empty()) units.assign(names.size(), "");
  std::vector<double> factors(names.size(), 1.0);
  for (size_t j = 0; j < names.size(); ++j) {
    std::string& unit = units[j];
    const auto given = options.units.find(names[j]);
    if (given != options.units.end()) {
      if (!unit.empty() && unit != given->second) {
        throw InputError(source, "channel " + names[j], "the unit given for it (" + given->second + ")",
                         "unit " + quote(unit) + " in the file");
      }
      unit = given->second;
    }
    const auto forced = options.unit_overrides.find(names[j]);
    if (forced != options.unit_overrides.end()) {
      if (!unit.empty() && unit != forced->second) {
        warnings.push_back(source + ": channel " + names[j] + ": unit " + quote(forced->second) + " from --units replaces " +
                           quote(unit) + " in the file");
      }
      unit = forced->second;
    }
    if (unit.empty()) {
      warnings.push_back(source + ": channel " + names[j] + " has no unit: taken as SI (give it with --units " + names[j] + "=UNIT)");
      continue;
    }
    const Unit u = unit_from_string(unit, source, "channel " + names[j]);
    factors[j] = u.to_si;
    unit = u.si_symbol;
  }
  if (std::all_of(units.begin(), units.end(), [](const std::string& u) { return u.empty(); })) units.clear();
  return factors;
}

// Samples in SI units (see to_si_units).
void convert_to_si(TimeSeries& ts, const ReadOptions& options) {
  const std::vector<double> factors = to_si_units(ts.source, ts.names, ts.units, options, ts.warnings);
  for (size_t j = 0; j < factors.size(); ++j) {
    if (factors[j] != 1.0) ts.data.col(static_cast<Eigen::Index>(j)) *= factors[j];
  }
}

// A unit entry (ReadOptions::unit_overrides, or the file's own `units`) must name a channel of the
// file (any of them, read or not), its time vector or another variable `known` lists: a typo is an
// InputError, never dropped.
void check_unit_names(const std::string& source, const std::string& field_prefix, const std::vector<std::string>& keys,
                      const std::vector<std::string>& available, const std::vector<std::string>& known = {}) {
  for (const std::string& key : keys) {
    if (is_time_name(key) || is_rate_name(key)) continue;
    if (std::find(available.begin(), available.end(), key) != available.end()) continue;
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::vector<std::string> sorted = available;
    std::sort(sorted.begin(), sorted.end());
    throw InputError(source, field_prefix + key, "the unit of a channel of the file (" + text::join(sorted) + ")",
                     quote(key) + ", which names no channel");
  }
}

std::vector<std::string> override_keys(const ReadOptions& options) {
  std::vector<std::string> keys;
  for (const auto& [k, v] : options.unit_overrides) keys.push_back(k);
  return keys;
}

std::vector<std::string> available_names(const std::vector<std::string>& names) {
  std::vector<std::string> sorted = names;
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

[[noreturn]] void throw_unknown_channel(const std::string& source, const std::string& name,
                                        const std::vector<std::string>& available) {
  throw InputError(source, "channel " + name,
                   "one of the channels in the file (" + text::join(available_names(available)) + ")",
                   quote(name));
}

// Channels to read: the requested ones (validated against what exists), or all.
std::vector<std::string> select_channels(const std::string& source, const ReadOptions& options,
                                         const std::vector<std::string>& available) {
  if (options.channels.empty()) {
    if (available.empty()) throw InputError(source, "channels", "at least one numeric channel", "none");
    return available;
  }
  std::set<std::string> seen;
  for (const std::string& name : options.channels) {
    if (std::find(available.begin(), available.end(), name) == available.end()) {
      throw_unknown_channel(source, name, available);
    }
    if (!seen.insert(name).second) throw InputError(source, "channels", "distinct channel names", quote(name) + " twice");
  }
  return options.channels;
}

void check_lengths(const std::string& source, const std::vector<std::string>& names,
                   const std::vector<Eigen::Index>& lengths, Eigen::Index t_length) {
  for (size_t j = 1; j < names.size(); ++j) {
    if (lengths[j] != lengths[0]) {
      throw InputError(source, names[j], "the length of " + names[0] + " (" + std::to_string(lengths[0]) + " samples)",
                       std::to_string(lengths[j]) + " samples");
    }
  }
  if (t_length >= 0 && !names.empty() && t_length != lengths[0]) {
    throw InputError(source, kTime, "the length of " + names[0] + " (" + std::to_string(lengths[0]) + " samples)",
                     std::to_string(t_length) + " samples");
  }
  if (!names.empty() && lengths[0] == 0) throw InputError(source, names[0], "at least one sample", "an empty record");
}

}  // namespace

// ---- TimeSeries -----------------------------------------------------------------------------

Eigen::Index TimeSeries::index(const std::string& name) const {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw_unknown_channel(source, name, names);
  return static_cast<Eigen::Index>(it - names.begin());
}

Eigen::Ref<const Eigen::VectorXd> TimeSeries::channel(const std::string& name) const { return data.col(index(name)); }

std::string TimeSeries::unit(const std::string& name) const {
  const Eigen::Index j = index(name);
  return units.empty() ? std::string() : units[static_cast<size_t>(j)];
}

namespace {

// TimeSeries::validate; `samples` = false leaves out the passes over the samples (finite values,
// increasing t) for a reader that has made them already.
void validate_series(const TimeSeries& ts, bool samples) {
  const auto& names = ts.names;
  const auto& data = ts.data;
  const auto& t = ts.t;
  const auto& units = ts.units;
  const double sample_rate = ts.sample_rate;
  const std::string& source = ts.source;
  if (names.empty() || data.cols() == 0) throw InputError(source, "channels", "at least one channel", "none");
  if (static_cast<Eigen::Index>(names.size()) != data.cols()) {
    throw InputError(source, "names", std::to_string(data.cols()) + " names (one per data column)",
                     std::to_string(names.size()));
  }
  if (data.rows() == 0) throw InputError(source, names.front(), "at least one sample", "an empty record");
  std::set<std::string> seen;
  for (const std::string& name : names) {
    if (name.empty()) throw InputError(source, "names", "non-empty channel names", "an empty name");
    if (name == kTime) throw InputError(source, "names", "the time vector in t, not among the channels", quote(name));
    if (!seen.insert(name).second) throw InputError(source, "names", "distinct channel names", quote(name) + " twice");
  }
  if (!units.empty() && units.size() != names.size()) {
    throw InputError(source, "units", std::to_string(names.size()) + " units (one per channel) or none",
                     std::to_string(units.size()));
  }
  if (!(std::isfinite(sample_rate) && sample_rate > 0.0)) {
    throw InputError(source, "sample_rate", "a positive finite rate in Hz", format_number(sample_rate, 10));
  }
  if (samples) {
    for (Eigen::Index j = 0; j < data.cols(); ++j) check_finite(source, names[static_cast<size_t>(j)], data.col(j));
  }
  if (t.size() > 0) {
    if (t.size() != data.rows()) {
      throw InputError(source, kTime, std::to_string(data.rows()) + " samples", std::to_string(t.size()));
    }
    if (!samples) return;
    check_finite(source, kTime, t);
    for (Eigen::Index k = 1; k < t.size(); ++k) {
      if (!(t(k) > t(k - 1))) {
        throw InputError(source, kTime, "a strictly increasing time vector",
                         "t[" + std::to_string(k) + "] <= t[" + std::to_string(k - 1) + "]");
      }
    }
  }
}

}  // namespace

void TimeSeries::validate() const { validate_series(*this, /*samples=*/true); }

void ReadOptions::validate() const {
  if (!(std::isfinite(fs) && fs >= 0.0)) throw InputError("ReadOptions", "fs", "0 (from t) or a positive rate in Hz", format_number(fs, 10));
  if (!(std::isfinite(time_tolerance) && time_tolerance > 0.0 && time_tolerance < 0.5)) {
    throw InputError("ReadOptions", "time_tolerance", "a fraction of a sample period in (0, 0.5)", format_number(time_tolerance, 10));
  }
  std::set<std::string> seen;
  for (const std::string& c : channels) {
    if (c.empty()) throw InputError("ReadOptions", "channels", "non-empty names", "an empty name");
    if (!seen.insert(c).second) throw InputError("ReadOptions", "channels", "distinct names", quote(c) + " twice");
  }
  detail::CsvDialect{delimiter, decimal}.validate();
  for (const auto& [channel, unit] : units) (void)unit_from_string(unit, "ReadOptions", "units." + channel);
  for (const auto& [channel, unit] : unit_overrides) (void)unit_from_string(unit, "--units", channel);
}

std::string to_string(MatVersion v) {
  switch (v) {
    case MatVersion::kV5: return "v5";
    case MatVersion::kV73: return "v7.3";
  }
  return "v5";
}

MatVersion mat_version_from_string(const std::string& s) {
  const std::string l = text::to_lower(s);
  if (l == "v5" || l == "5" || l == "-v5" || l == "v7" || l == "7" || l == "-v7" || l == "v6" || l == "-v6") return MatVersion::kV5;
  if (l == "v7.3" || l == "7.3" || l == "-v7.3" || l == "v73") return MatVersion::kV73;
  throw InputError("", "mat version", "v5, v7 or v7.3", quote(s));
}

// ---- readers --------------------------------------------------------------------------------

TimeSeries read_timeseries(const fs::path& file, const ReadOptions& options) {
  const std::string ext = text::to_lower(file.extension().string());
  if (ext == ".mat") return read_timeseries_mat(file, options);
  if (ext == ".csv") return read_timeseries_csv(file, options);
  if (ext == ".uff" || ext == ".unv" || ext == ".uf") return read_timeseries_uff58(file, options);
  throw InputError(file.string(), "file", "a .mat, .csv or .uff file", "extension " + quote(ext));
}

namespace {

// Where the channels of a MAT file live: the top level or the fields of one struct.
struct MatLayout {
  std::vector<std::string> channels;  // numeric vectors (excluding t and fs)
  std::string group;                  // "" = top level
  std::optional<detail::MatValue> group_var;  // the struct, read with data, when group is set
};

bool is_numeric_vector(const detail::MatVarInfo& v) {
  if (!detail::is_numeric_class(v.class_type) || v.is_complex) return false;
  int non_singleton = 0;
  size_t count = 1;
  for (size_t d : v.dims) {
    if (d != 1) ++non_singleton;
    count *= d;
  }
  return non_singleton <= 1 && count > 1;
}

std::vector<std::string> struct_channels(const detail::MatValue& var) {
  std::vector<std::string> out;
  for (const std::string& name : var.field_names) {
    if (is_time_name(name)) continue;
    const detail::MatValue* field = var.field(name);
    if (field == nullptr) continue;
    if (is_numeric_vector({name, field->class_type, field->is_complex, field->dims, ""})) out.push_back(name);
  }
  return out;
}

detail::MatValue read_group(detail::MatInput* mat, const fs::path& file, const std::string& group) {
  detail::MatValue var = detail::read_mat_variable(mat, file, group);
  if (var.class_type != MAT_C_STRUCT || var.count() != 1) {
    throw InputError(file.string(), group, "a 1x1 struct holding the channels", detail::describe(var));
  }
  return var;
}

MatLayout mat_layout(detail::MatInput* mat, const fs::path& file, const ReadOptions& options,
                     const std::vector<detail::MatVarInfo>& vars) {
  MatLayout layout;
  if (!options.group.empty()) {
    const bool exists = std::any_of(vars.begin(), vars.end(), [&](const auto& v) { return v.name == options.group; });
    if (!exists) {
      std::vector<std::string> names;
      for (const auto& v : vars) names.push_back(v.name);
      throw InputError(file.string(), "group " + options.group, "a struct variable of the file (" + text::join(names) + ")",
                       quote(options.group));
    }
    layout.group = options.group;
    layout.group_var = read_group(mat, file, options.group);
    layout.channels = struct_channels(*layout.group_var);
    return layout;
  }
  std::vector<std::string> structs;
  for (const auto& v : vars) {
    if (is_time_name(v.name) || is_rate_name(v.name)) continue;
    if (is_numeric_vector(v)) layout.channels.push_back(v.name);
    if (v.class_type == MAT_C_STRUCT && !is_units_name(v.name) && v.name != kSettings) structs.push_back(v.name);
  }
  // Files written by piezobench list their channels in order (HDF5 lists variables by name).
  const auto order_var = std::find_if(vars.begin(), vars.end(), [](const auto& v) { return v.name == kChannelOrder; });
  if (order_var != vars.end() && order_var->class_type == MAT_C_CHAR) {
    const std::string list = detail::to_text(detail::read_mat_variable(mat, file, kChannelOrder), file.string(), kChannelOrder);
    std::vector<std::string> ordered;
    for (std::string_view part : text::split(list, ',')) ordered.emplace_back(text::trim(part));
    std::vector<std::string> sorted_listed = ordered, sorted_found = layout.channels;
    std::sort(sorted_listed.begin(), sorted_listed.end());
    std::sort(sorted_found.begin(), sorted_found.end());
    if (sorted_listed == sorted_found) layout.channels = ordered;
  }
  // Channels saved as fields of one struct (`data.u`, `data.de`): used when the top level holds
  // no vector at all, or when the requested channels are fields of that struct.
  if (structs.size() == 1) {
    const bool top_level_has_requested =
        !options.channels.empty() &&
        std::all_of(options.channels.begin(), options.channels.end(), [&](const std::string& c) {
          return std::find(layout.channels.begin(), layout.channels.end(), c) != layout.channels.end();
        });
    if (layout.channels.empty() || (!options.channels.empty() && !top_level_has_requested)) {
      detail::MatValue candidate = read_group(mat, file, structs.front());
      std::vector<std::string> fields = struct_channels(candidate);
      const bool fits = options.channels.empty()
                            ? !fields.empty()
                            : std::all_of(options.channels.begin(), options.channels.end(), [&](const std::string& c) {
                                return std::find(fields.begin(), fields.end(), c) != fields.end();
                              });
      if (fits) {
        layout.group = structs.front();
        layout.group_var = std::move(candidate);
        layout.channels = std::move(fields);
      }
    }
  }
  return layout;
}

// Text fields of a struct (units) or text/scalar fields (settings); other fields are ignored.
std::map<std::string, Setting> read_struct_settings(const detail::MatValue& var, const std::string& source, const std::string& field) {
  std::map<std::string, Setting> out;
  if (var.class_type != MAT_C_STRUCT || var.count() != 1) {
    throw InputError(source, field, "a 1x1 struct", detail::describe(var));
  }
  for (const std::string& name : var.field_names) {
    const detail::MatValue* f = var.field(name);
    if (f == nullptr) continue;
    if (f->class_type == MAT_C_CHAR) {
      out[name] = detail::to_text(*f, source, field + "." + name);
    } else if (detail::is_numeric_class(f->class_type) && !f->is_complex && f->count() == 1) {
      out[name] = detail::to_real_vector(*f, source, field + "." + name)(0);
    }
  }
  return out;
}

// The texts of a cell array's elements (char rows), column-major; InputError naming `field` for
// any other element.
std::vector<std::string> cell_texts(const detail::MatValue& cell, const std::string& source, const std::string& field) {
  std::vector<std::string> out;
  for (size_t i = 0; i < cell.items.size(); ++i) {
    out.push_back(std::string(text::trim(detail::to_text(cell.items[i], source, field + "{" + std::to_string(i + 1) + "}"))));
  }
  return out;
}

// "u=V, de=um" or "u: V; de: um" as (name, unit) pairs; nullopt when the text is not such a list.
std::optional<std::vector<std::pair<std::string, std::string>>> unit_pairs(const std::string& list) {
  std::vector<std::pair<std::string, std::string>> out;
  std::string normalized = list;
  std::replace(normalized.begin(), normalized.end(), ';', ',');
  for (std::string_view part : text::split(normalized, ',')) {
    part = text::trim(part);
    if (part.empty()) continue;
    const size_t sep = part.find_first_of("=:");
    if (sep == std::string_view::npos) return std::nullopt;
    out.emplace_back(std::string(text::trim(part.substr(0, sep))), std::string(text::trim(part.substr(sep + 1))));
  }
  if (out.empty()) return std::nullopt;
  return out;
}

// The units a MAT file gives its variables, from every place writers put them (docs/formats.md,
// "Units in .mat files"): a `units` struct (top level or inside the record struct: one char field
// per channel), a `units` cell array (name/unit pairs as an N x 2 or 2 x N cell, or one unit per
// name of a `channels` / `names` / `labels` list of the same length), v7.3 `units` attributes of
// datasets (top level or in a group) and a group's or the file's (root group's) attributes (`units` = "u=V, de=um", `de_units`,
// `units_de`, or an attribute named as the channel). Two places that disagree, a units cell that
// cannot be matched to names, or an entry that names no variable of the file are InputErrors.
class MatUnits {
 public:
  MatUnits(detail::MatInput* mat, const fs::path& file, const std::vector<detail::MatVarInfo>& vars, const MatLayout& layout)
      : mat_(mat), file_(file), source_(file.string()), vars_(vars), layout_(layout) {
    for (const auto& v : vars) known_.push_back(v.name);
    if (layout.group_var) known_.insert(known_.end(), layout.group_var->field_names.begin(), layout.group_var->field_names.end());
  }

  std::map<std::string, std::string> collect() {
    // v7.3 attributes of the datasets themselves, and of the file.
    for (const auto& v : vars_) add(v.name, v.unit, v.name + " (attribute units)", false);
    std::vector<std::string> top_level;
    for (const auto& v : vars_) top_level.push_back(v.name);
    from_attributes(detail::mat_file_attributes(mat_), "file", top_level);
    if (layout_.group_var) {
      const detail::MatValue& g = *layout_.group_var;
      for (size_t f = 0; f < g.field_names.size(); ++f) {
        const detail::MatValue* field = g.field(g.field_names[f]);
        if (field != nullptr) add(g.field_names[f], field->unit, layout_.group + "." + g.field_names[f] + " (attribute units)", false);
      }
      from_attributes(g.attributes, layout_.group, g.field_names);
      for (const std::string& f : g.field_names) {
        if (is_units_name(f)) from_value(*g.field(f), layout_.group + "." + f, &g);
      }
    }
    for (const auto& v : vars_) {
      if (is_units_name(v.name)) from_value(detail::read_mat_variable(mat_, file_, v.name), v.name, nullptr);
    }
    return units_;
  }

 private:
  // One name's unit from `place`: a second place must agree.
  void add(const std::string& name, const std::string& unit, const std::string& place, bool check_name) {
    const std::string u(text::trim(unit));
    if (u.empty()) return;
    if (check_name) check_unit_names(source_, place + ": ", {name}, known_);
    const auto [it, inserted] = units_.emplace(name, u);
    if (inserted) {
      place_of_[name] = place;
    } else if (it->second != u) {
      throw InputError(source_, place, "the unit " + place_of_[name] + " gives " + name + " (" + it->second + ")", "unit " + quote(u));
    }
  }

  // Names a units cell of one row or column pairs with: `channels`, `names`, `labels` (a cell of
  // char rows, or a char row of comma-separated names) beside it.
  std::optional<std::vector<std::string>> names_beside(const detail::MatValue* group) const {
    for (const char* candidate : {"channels", "names", "channel_names", "labels"}) {
      std::optional<detail::MatValue> value;
      if (group != nullptr) {
        if (const detail::MatValue* f = group->field(candidate)) value = *f;
      } else if (std::any_of(vars_.begin(), vars_.end(), [&](const auto& v) { return v.name == candidate; })) {
        value = detail::read_mat_variable(mat_, file_, candidate);
      }
      if (!value) continue;
      if (value->class_type == MAT_C_CELL) return cell_texts(*value, source_, candidate);
      std::vector<std::string> out;
      for (std::string_view part : text::split(detail::to_text(*value, source_, candidate), ',')) out.emplace_back(text::trim(part));
      return out;
    }
    return std::nullopt;
  }

  // A `units` variable or field: a struct, a char row of NAME=UNIT pairs, or a cell.
  void from_value(const detail::MatValue& uv, const std::string& place, const detail::MatValue* group) {
    if (uv.class_type == MAT_C_STRUCT) {
      for (const auto& [name, value] : read_struct_settings(uv, source_, place)) {
        if (std::holds_alternative<std::string>(value)) add(name, std::get<std::string>(value), place + "." + name, true);
      }
      return;
    }
    if (uv.class_type == MAT_C_CHAR) {
      const std::string t = detail::to_text(uv, source_, place);
      const auto pairs = unit_pairs(t);
      if (!pairs) throw InputError(source_, place, "units as NAME=UNIT pairs (\"u=V, de=um\"), a struct or a cell", quote(t));
      for (const auto& [name, unit] : *pairs) add(name, unit, place + " (" + name + ")", true);
      return;
    }
    if (uv.class_type != MAT_C_CELL) throw InputError(source_, place, "a struct, a cell or a char row of units", detail::describe(uv));
    if (!uv.has_data) {
      throw InputError(source_, place, "units as a cell of texts (a cell of structs or cells is not read)", detail::describe(uv));
    }
    from_cell(uv, place, group);
  }

  // A units cell: NAME/UNIT pairs (N x 2 or 2 x N), or one unit per name of a list beside it.
  void from_cell(const detail::MatValue& uv, const std::string& place, const detail::MatValue* group) {
    const std::vector<std::string> texts = cell_texts(uv, source_, place);
    const size_t rows = uv.dims.empty() ? 0 : uv.dims[0], cols = texts.size() / std::max<size_t>(rows, 1);
    const auto all_known = [&](size_t first, size_t stride, size_t count) {
      for (size_t i = 0; i < count; ++i) {
        const std::string& n = texts[first + i * stride];
        if (std::find(known_.begin(), known_.end(), n) == known_.end() && !is_time_name(n)) return false;
      }
      return true;
    };
    const bool vector = rows == 1 || cols == 1;
    if (!vector && cols == 2 && all_known(0, 1, rows)) {  // N x 2: {'u', 'V'; 'de', 'um'}
      for (size_t i = 0; i < rows; ++i) add(texts[i], texts[rows + i], place + "{" + std::to_string(i + 1) + ",2}", true);
      return;
    }
    if (!vector && rows == 2 && all_known(0, 2, cols)) {  // 2 x N: {'u', 'de'; 'V', 'um'}
      for (size_t i = 0; i < cols; ++i) add(texts[2 * i], texts[2 * i + 1], place + "{2," + std::to_string(i + 1) + "}", true);
      return;
    }
    const std::optional<std::vector<std::string>> names = vector ? names_beside(group) : std::nullopt;
    if (!names || names->size() != texts.size()) {
      throw InputError(source_, place,
                       "units a channel can be matched to: NAME/UNIT pairs (an N x 2 cell) or one unit per name of a "
                       "`channels`, `names` or `labels` list of the same length",
                       detail::describe(uv) + (names ? " beside " + std::to_string(names->size()) + " names" : " without names"));
    }
    for (size_t i = 0; i < texts.size(); ++i) add((*names)[i], texts[i], place + "{" + std::to_string(i + 1) + "}", true);
  }

  // A group's attributes (the record group's, or the file's own root group's): `units` =
  // "u=V, de=um", `de_units`, `de_unit`, `units_de`, or an attribute named as a member.
  void from_attributes(const std::vector<std::pair<std::string, std::string>>& attributes, const std::string& group,
                       const std::vector<std::string>& members) {
    for (const auto& [key, value] : attributes) {
      const std::string place = group + " (attribute " + key + ")";
      const std::string l = text::to_lower(key);
      if (is_units_name(key)) {
        const auto pairs = unit_pairs(value);
        if (!pairs) throw InputError(source_, place, "units as NAME=UNIT pairs (\"u=V, de=um\")", quote(value));
        for (const auto& [name, unit] : *pairs) add(name, unit, place, true);
      } else if (l.size() > 6 && l.compare(l.size() - 6, 6, "_units") == 0) {
        add(key.substr(0, key.size() - 6), value, place, true);
      } else if (l.size() > 5 && l.compare(l.size() - 5, 5, "_unit") == 0) {
        add(key.substr(0, key.size() - 5), value, place, true);
      } else if (l.rfind("units_", 0) == 0 && l.size() > 6) {
        add(key.substr(6), value, place, true);
      } else if (std::find(members.begin(), members.end(), key) != members.end()) {
        add(key, value, place, false);
      }
    }
  }

  detail::MatInput* mat_;
  const fs::path& file_;
  const std::string source_;
  const std::vector<detail::MatVarInfo>& vars_;
  const MatLayout& layout_;
  std::map<std::string, std::string> units_, place_of_;
  std::vector<std::string> known_;  // every variable and field a unit may name
};

std::map<std::string, std::string> mat_units(detail::MatInput* mat, const fs::path& file, const std::vector<detail::MatVarInfo>& vars,
                                             const MatLayout& layout) {
  return MatUnits(mat, file, vars, layout).collect();
}

// A MAT file open for read_mat: its variables and where the channels are.
struct MatSource {
  const fs::path& file;
  std::string source;
  detail::MatFilePtr mat;
  std::vector<detail::MatVarInfo> vars;
  MatLayout layout;

  // The record struct's field `name` (nullptr at the top level).
  [[nodiscard]] const detail::MatValue* field(const std::string& name) const {
    return layout.group_var ? layout.group_var->field(name) : nullptr;
  }
};

// The time vector as read: in ts.t, or in the file's mapping (view only).
struct MatTime {
  std::string name;                             // "" when the file has none
  Eigen::Index length = -1;
  bool prechecked = false;                      // its samples checked as they were read
  std::optional<detail::MappedDoubles> mapped;  // the time vector in the mapping (view only)
};

size_t stored_elements(const detail::MatVarInfo& v) {
  size_t count = 1;
  for (size_t d : v.dims) count *= d;
  return count;
}

// A requested channel that exists but is not a numeric vector gets its own message.
void check_requested_channels(const MatSource& m, const ReadOptions& options) {
  for (const std::string& c : options.channels) {
    if (std::find(m.layout.channels.begin(), m.layout.channels.end(), c) != m.layout.channels.end()) continue;
    const detail::MatValue* found = nullptr;
    std::optional<detail::MatValue> top;
    if (m.layout.group_var) {
      found = m.layout.group_var->field(c);
    } else if (std::any_of(m.vars.begin(), m.vars.end(), [&](const auto& v) { return v.name == c; })) {
      top = detail::read_mat_variable(m.mat.get(), m.file, c);
      found = &*top;
    }
    if (found != nullptr) {
      const std::string field = m.layout.group.empty() ? c : m.layout.group + "." + c;
      throw InputError(m.source, field, "a real numeric vector (2 samples or more)", detail::describe(*found));
    }
  }
}

// Lengths come from the variables' headers, so the matrix is allocated once and every channel
// is copied straight into its column (records reach 10^7 samples: no second copy).
std::vector<Eigen::Index> channel_lengths(const MatSource& m, const std::vector<std::string>& names) {
  std::vector<Eigen::Index> lengths;
  for (const std::string& name : names) {
    if (m.layout.group_var) {
      lengths.push_back(static_cast<Eigen::Index>(m.field(name)->count()));
    } else {
      const auto info = std::find_if(m.vars.begin(), m.vars.end(), [&](const auto& v) { return v.name == name; });
      lengths.push_back(static_cast<Eigen::Index>(stored_elements(*info)));
    }
  }
  return lengths;
}

// A top-level time vector. A plain double vector as long as the channels is read straight into
// place (and checked chunk by chunk, see time_samples_ok); anything else through a copy and the
// full checks.
void read_top_level_time(const MatSource& m, const detail::MatVarInfo& info, Eigen::Index channel_length, bool viewing,
                         TimeSeries& ts, MatTime& time) {
  const auto n = static_cast<Eigen::Index>(stored_elements(info));
  if (viewing && n >= 2 && n == channel_length) time.mapped = detail::map_double_vector(m.mat.get(), time.name, stored_elements(info));
  const std::optional<double> t_last = time.mapped ? std::nullopt :
      n >= 2 && n == channel_length && is_numeric_vector(info) && info.class_type == MAT_C_DOUBLE
          ? detail::read_double_element(m.mat.get(), time.name, n, n - 1)
          : std::nullopt;
  bool read = false;
  if (time.mapped) {
    const double* t = time.mapped->data;
    const double dt = (t[n - 1] - t[0]) / static_cast<double>(n - 1);  // as sample_rate_from_time
    bool ok = true;
    for (Eigen::Index first = 0; first < n && ok; first += kReadChunk) {
      ok = time_samples_ok(t, n, first, std::min(kReadChunk, n - first), dt, kExactTime);
    }
    time.prechecked = ok;
    read = true;
  } else if (t_last) {
    ts.t.resize(n);
    advise_huge_pages(ts.t.data(), n);
    bool ok = true;
    double dt = 0.0;
    const auto check = [&](Eigen::Index first, Eigen::Index piece) {
      if (first == 0) dt = (*t_last - ts.t(0)) / static_cast<double>(n - 1);  // as sample_rate_from_time
      ok = ok && time_samples_ok(ts.t.data(), n, first, piece, dt, kExactTime);
    };
    read = detail::read_double_vector_into(m.mat.get(), time.name, ts.t, kReadChunk, check);
    time.prechecked = read && ok && ts.t(n - 1) == *t_last;
  }
  if (!read) {
    ts.t = detail::to_real_vector(detail::read_mat_variable(m.mat.get(), m.file, time.name), m.source, time.name);
  }
  time.length = time.mapped ? n : ts.t.size();
}

// The time vector, `t` or `time` in any case (MATLAB scripts write `time`, `Time`): inside the
// group if it has one, else at the top level.
MatTime read_mat_time(const MatSource& m, Eigen::Index channel_length, bool viewing, TimeSeries& ts) {
  MatTime time;
  const detail::MatValue* t_in_group = nullptr;
  if (m.layout.group_var) {
    for (const std::string& f : m.layout.group_var->field_names) {
      if (is_time_name(f)) {
        time.name = f;
        t_in_group = m.field(f);
        break;
      }
    }
  }
  const auto t_info = t_in_group != nullptr ? m.vars.end()
                                            : std::find_if(m.vars.begin(), m.vars.end(), [](const auto& v) { return is_time_name(v.name); });
  if (t_info != m.vars.end()) time.name = t_info->name;
  if (t_in_group != nullptr) {
    ts.t = detail::to_real_vector(*t_in_group, m.source, m.layout.group + "." + time.name);
    time.length = ts.t.size();
  } else if (t_info != m.vars.end()) {
    read_top_level_time(m, *t_info, channel_length, viewing, ts, time);
  }
  return time;
}

// The sample rate as a scalar `fs`, `Fs`, `sample_rate` or `sample_rate_Hz` (any case).
std::optional<double> mat_sample_rate(const MatSource& m) {
  const auto fs_info = std::find_if(m.vars.begin(), m.vars.end(), [](const auto& v) { return is_rate_name(v.name); });
  if (fs_info == m.vars.end()) return std::nullopt;
  const detail::MatValue fv = detail::read_mat_variable(m.mat.get(), m.file, fs_info->name);
  const Eigen::VectorXd f = detail::to_real_vector(fv, m.source, fs_info->name);
  if (f.size() != 1) throw InputError(m.source, fs_info->name, "a scalar sample rate in Hz", detail::describe(fv));
  return f(0);
}

// The time stamps in seconds (a mapped vector in another unit is copied to be scaled); returns
// the seconds per unit of the stored stamps.
double time_to_seconds(const MatSource& m, const std::string& unit, MatTime& time, TimeSeries& ts) {
  if (ts.t.size() == 0 && !time.mapped) return 1.0;
  const double factor = time_unit_factor(unit, m.source, std::string(kUnits) + "." + time.name);
  if (time.mapped && factor != 1.0) {
    ts.t = Eigen::Map<const Eigen::VectorXd>(time.mapped->data, time.length) * factor;
    time.mapped.reset();
  } else if (factor != 1.0) {
    ts.t *= factor;
  }
  return factor;
}

// What the channels need besides their samples: the time vector where it is (in the mapping or
// in ts.t), its scale and checks, the file's sample rate and units.
struct MatChannelContext {
  Eigen::Map<const Eigen::VectorXd> t_samples;
  double t_scale;
  bool t_prechecked;
  std::optional<double> fs_file;
  const std::map<std::string, std::string>& units;

  [[nodiscard]] std::string unit_of(const std::string& name) const {
    const auto it = units.find(name);
    return it != units.end() ? it->second : std::string();
  }
};

// In place: every channel a plain double vector at the top level, in SI units already; false
// (and `view` untouched but for warnings) when one is not.
bool map_mat_channels(const MatSource& m, const std::vector<std::string>& names, Eigen::Index n, const ReadOptions& options,
                      const MatChannelContext& c, FiniteCheck finite_check, TimeSeriesView& view) {
  std::vector<std::string> units;
  for (const std::string& name : names) units.push_back(c.unit_of(name));
  const std::vector<double> factors = to_si_units(m.source, names, units, options, view.warnings);
  std::vector<detail::MappedDoubles> mapped;
  if (std::all_of(factors.begin(), factors.end(), [](double f) { return f == 1.0; })) {
    for (const std::string& name : names) {
      std::optional<detail::MappedDoubles> md = detail::map_double_vector(m.mat.get(), name, static_cast<size_t>(n));
      if (!md) break;
      mapped.push_back(std::move(*md));
    }
  }
  if (mapped.size() != names.size()) return false;
  for (size_t j = 0; j < names.size(); ++j) {
    bool finite = true;
    for (Eigen::Index first = 0; first < n && finite && finite_check == FiniteCheck::kReader; first += kReadChunk) {
      finite = all_finite(mapped[j].data + first, std::min(kReadChunk, n - first));
    }
    if (!finite) check_finite(m.source, names[j], Eigen::Map<const Eigen::VectorXd>(mapped[j].data, n));
    view.columns.push_back(mapped[j].data);
  }
  view.sample_rate =
      resolve_sample_rate(m.source, c.t_samples, options.fs, c.fs_file, options.time_tolerance, view.warnings, c.t_prechecked, c.t_scale);
  view.names = names;
  view.units = std::move(units);
  view.samples = n;
  view.source = m.source;
  view.storage = mapped.front().file;
  view.mapped = true;
  return true;
}

// Every channel copied into its column of ts.data, checked for NaN/Inf piece by piece as it
// arrives (the exact message comes from check_finite, which runs only when there is something to
// report).
void read_mat_channels(const MatSource& m, const std::vector<std::string>& names, Eigen::Index n, TimeSeries& ts) {
  ts.names = names;
  ts.data.resize(n, static_cast<Eigen::Index>(names.size()));
  advise_huge_pages(ts.data.data(), ts.data.size());
  for (size_t j = 0; j < names.size(); ++j) {
    const std::string field = m.layout.group.empty() ? names[j] : m.layout.group + "." + names[j];
    const auto col = static_cast<Eigen::Index>(j);
    bool finite = true;
    if (m.layout.group_var) {
      detail::copy_real_vector(*m.field(names[j]), m.source, field, ts.data.col(col));
      finite = all_finite(ts.data.col(col).data(), ts.data.rows());
    } else if (!detail::read_double_vector_into(m.mat.get(), names[j], ts.data.col(col), kReadChunk,
                                                [&](Eigen::Index first, Eigen::Index count) {
                                                  finite = finite && all_finite(ts.data.col(col).data() + first, count);
                                                })) {
      detail::copy_real_vector(detail::read_mat_variable(m.mat.get(), m.file, names[j]), m.source, field, ts.data.col(col));
      finite = all_finite(ts.data.col(col).data(), ts.data.rows());
    }
    if (!finite) check_finite(m.source, field, ts.data.col(col));
  }
}

// read_timeseries_mat, and read_timeseries_view's use of a MAT file: with `view`, a time vector and
// channels stored as plain doubles (detail::map_double_vector) are checked in place in the file's
// mapping; when every channel is (top level, SI units), `view` gets them (view->mapped) and the
// TimeSeries returned is empty.
TimeSeries read_mat(const fs::path& file, const ReadOptions& options, TimeSeriesView* view,
                    FiniteCheck finite_check = FiniteCheck::kReader) {
  options.validate();
  MatSource m{file, file.string(), detail::open_mat_for_reading(file), {}, {}};
  m.vars = detail::list_mat_variables(m.mat.get(), file);
  if (m.vars.empty()) throw InputError(m.source, "variables", "at least one variable", "an empty MAT file");
  m.layout = mat_layout(m.mat.get(), file, options, m.vars);
  if (!options.channels.empty()) check_requested_channels(m, options);
  std::vector<std::string> available = m.layout.channels;
  const std::vector<std::string> names = select_channels(m.source, options, available);
  const std::vector<Eigen::Index> lengths = channel_lengths(m, names);

  TimeSeries ts;
  ts.source = m.source;
  MatTime time = read_mat_time(m, lengths.front(), view != nullptr, ts);
  check_lengths(m.source, names, lengths, time.length);
  const std::optional<double> fs_file = mat_sample_rate(m);
  // Units from every place a writer puts them (mat_units).
  const std::map<std::string, std::string> file_units = mat_units(m.mat.get(), file, m.vars, m.layout);
  {
    std::vector<std::string> all = m.layout.channels;
    if (!time.name.empty()) all.push_back(time.name);
    check_unit_names(m.source, "--units ", override_keys(options), all);
  }
  const auto time_unit = file_units.find(time.name);
  const double t_scale = time_to_seconds(m, time_unit != file_units.end() ? time_unit->second : std::string(), time, ts);
  const MatChannelContext c{
      Eigen::Map<const Eigen::VectorXd>(time.mapped ? time.mapped->data : ts.t.data(), time.mapped ? time.length : ts.t.size()),
      t_scale, time.prechecked, fs_file, file_units};
  if (view != nullptr && !m.layout.group_var && map_mat_channels(m, names, lengths.front(), options, c, finite_check, *view)) return ts;

  read_mat_channels(m, names, lengths.front(), ts);
  ts.sample_rate = resolve_sample_rate(m.source, c.t_samples, options.fs, fs_file, options.time_tolerance, ts.warnings, c.t_prechecked,
                                       t_scale);
  ts.units.assign(names.size(), "");
  for (size_t j = 0; j < names.size(); ++j) ts.units[j] = c.unit_of(names[j]);
  convert_to_si(ts, options);
  if (std::any_of(m.vars.begin(), m.vars.end(), [](const auto& v) { return v.name == kSettings; })) {
    const detail::MatValue sv = detail::read_mat_variable(m.mat.get(), file, kSettings);
    if (sv.class_type == MAT_C_STRUCT) ts.settings = read_struct_settings(sv, m.source, kSettings);
  }
  // The samples were checked above (finite channels, and t by resolve_sample_rate).
  validate_series(ts, /*samples=*/false);
  return ts;
}

}  // namespace

TimeSeries read_timeseries_mat(const fs::path& file, const ReadOptions& options) { return read_mat(file, options, nullptr); }

std::optional<TimeSeries> read_mat_readings(const fs::path& file, const std::vector<std::string>& channels) {
  if (channels.empty() || text::to_lower(file.extension().string()) != ".mat") return std::nullopt;
  const detail::MatFilePtr mat = detail::open_mat_for_reading(file);
  const std::vector<detail::MatVarInfo> vars = detail::list_mat_variables(mat.get(), file);
  std::vector<Eigen::VectorXd> values;
  for (const auto& name : channels) {
    if (std::none_of(vars.begin(), vars.end(), [&](const detail::MatVarInfo& v) { return v.name == name; })) return std::nullopt;
    const detail::MatValue v = detail::read_mat_variable(mat.get(), file, name);
    const bool vector = v.class_type == MAT_C_DOUBLE && !v.is_complex && v.has_data && v.dims.size() == 2 &&
                        (v.dims[0] == 1 || v.dims[1] == 1) && v.count() >= 1;
    if (!vector) return std::nullopt;
    values.push_back(detail::to_real_vector(v, file.string(), name));
  }
  const Eigen::Index n = values.front().size();
  if (std::any_of(values.begin(), values.end(), [&](const Eigen::VectorXd& v) { return v.size() != n; })) return std::nullopt;
  TimeSeries ts;
  ts.names = channels;
  ts.data.resize(n, static_cast<Eigen::Index>(channels.size()));
  for (std::size_t j = 0; j < values.size(); ++j) ts.data.col(static_cast<Eigen::Index>(j)) = values[j];
  ts.sample_rate = 1.0;
  ts.source = file.string();
  ts.validate();
  return ts;
}

TimeSeriesView read_timeseries_view(const fs::path& file, const ReadOptions& options, FiniteCheck finite) {
  TimeSeriesView view;
  TimeSeries ts = text::to_lower(file.extension().string()) == ".mat" ? read_mat(file, options, &view, finite)
                                                                      : read_timeseries(file, options);
  if (view.mapped) return view;
  auto owned = std::make_shared<TimeSeries>(std::move(ts));
  view.names = owned->names;
  for (Eigen::Index j = 0; j < owned->channels(); ++j) view.columns.push_back(owned->data.col(j).data());
  view.samples = owned->samples();
  view.sample_rate = owned->sample_rate;
  view.units = owned->units;
  view.source = owned->source;
  view.warnings = owned->warnings;
  view.storage = std::move(owned);
  return view;
}

Eigen::Index TimeSeriesView::index(const std::string& name) const {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw_unknown_channel(source, name, names);
  return static_cast<Eigen::Index>(it - names.begin());
}

Eigen::Map<const Eigen::VectorXd> TimeSeriesView::channel(const std::string& name) const {
  return {columns[static_cast<size_t>(index(name))], samples};
}

std::string TimeSeriesView::unit(const std::string& name) const {
  const Eigen::Index j = index(name);
  return units.empty() ? std::string() : units[static_cast<size_t>(j)];
}

TimeSeries read_timeseries_csv(const fs::path& file, const ReadOptions& options) {
  options.validate();
  const detail::CsvTable table(file, {options.delimiter, options.decimal});
  const std::string& source = table.source();

  std::optional<double> fs_comment;
  for (const auto& [line_no, comment] : table.comments()) {
    if (const std::optional<double> f = rate_from_text(comment, source, "comment (line " + std::to_string(line_no) + ")")) {
      fs_comment = f;
    }
  }

  const auto& columns = table.columns();
  std::vector<std::string> available;
  int time_column = -1;
  for (size_t c = 0; c < columns.size(); ++c) {
    if (time_column < 0 && is_time_name(columns[c].name)) {
      time_column = static_cast<int>(c);
    } else {
      available.push_back(columns[c].name);
    }
  }
  check_unit_names(source, "--units ", override_keys(options), available);
  const std::vector<std::string> names = select_channels(source, options, available);
  // For each CSV column, the column of the table it fills (-1: not read); the time vector last.
  std::vector<int> target(columns.size(), -1);
  std::vector<std::string> units(names.size());
  for (size_t j = 0; j < names.size(); ++j) {
    for (size_t c = 0; c < columns.size(); ++c) {
      if (static_cast<int>(c) != time_column && columns[c].name == names[j]) {
        target[c] = static_cast<int>(j);
        units[j] = columns[c].unit;
      }
    }
  }
  const auto nread = static_cast<Eigen::Index>(names.size() + (time_column >= 0 ? 1 : 0));
  if (time_column >= 0) target[static_cast<size_t>(time_column)] = static_cast<int>(names.size());
  Eigen::MatrixXd data = table.read(target, nread);

  TimeSeries ts;
  ts.source = source;
  ts.names = names;
  double t_scale = 1.0;
  if (time_column >= 0) {
    const detail::CsvColumn& tc = columns[static_cast<size_t>(time_column)];
    ts.t = data.col(nread - 1);
    t_scale = time_unit_factor(tc.unit, source, "column " + tc.name);
    ts.t *= t_scale;
    ts.data = data.leftCols(nread - 1);
  } else {
    ts.data = std::move(data);
  }
  ts.units = std::move(units);
  convert_to_si(ts, options);
  ts.sample_rate = resolve_sample_rate(source, ts.t, options.fs, fs_comment, options.time_tolerance, ts.warnings, false, t_scale);
  ts.validate();
  return ts;
}

TimeSeries read_timeseries_uff58(const fs::path& file, const ReadOptions& options) {
  options.validate();
  const std::string source = file.string();
  detail::UffTimeHistories uff = detail::read_uff58_time_histories(file);
  check_unit_names(source, "--units ", override_keys(options), uff.names);
  const std::vector<std::string> names = select_channels(source, options, uff.names);
  TimeSeries ts;
  ts.source = source;
  ts.names = names;
  ts.data.resize(uff.data.rows(), static_cast<Eigen::Index>(names.size()));
  for (size_t j = 0; j < names.size(); ++j) {
    const auto k = static_cast<size_t>(std::find(uff.names.begin(), uff.names.end(), names[j]) - uff.names.begin());
    ts.data.col(static_cast<Eigen::Index>(j)) = uff.data.col(static_cast<Eigen::Index>(k));
    ts.units.push_back(uff.units[k]);
  }
  convert_to_si(ts, options);
  std::optional<double> fs_file;
  if (uff.increment_s > 0.0) {
    // Record 7 keeps the increment to 6 significant digits (E13.5): a whole rate in Hz that
    // rounds to it is the rate (1.52588E-05 s is 65536 Hz, not 65535.95 Hz).
    const double rate = 1.0 / uff.increment_s, whole = std::round(rate);
    const double printed = std::stod(format_number(1.0 / whole, 6));
    fs_file = whole > 0.0 && std::abs(printed - uff.increment_s) <= 1e-9 * uff.increment_s ? whole : rate;
  }
  ts.t = uff.t;
  ts.sample_rate = resolve_sample_rate(source, ts.t, options.fs, fs_file, options.time_tolerance, ts.warnings, false, uff.time_scale);
  ts.validate();
  return ts;
}

// ---- writers --------------------------------------------------------------------------------

void write_timeseries(const TimeSeries& ts, const fs::path& file, const MatWriteOptions& options) {
  const std::string ext = text::to_lower(file.extension().string());
  if (ext == ".mat") return write_timeseries_mat(ts, file, options);
  if (ext == ".csv") return write_timeseries_csv(ts, file);
  throw InputError(file.string(), "output file", "a .mat or .csv file", "extension " + quote(ext));
}

namespace {

// Validates for writing: the data, and the names the format needs. Errors name the target file.
void validate_for_writing(const TimeSeries& ts, const fs::path& file, bool mat) {
  try {
    ts.validate();
  } catch (const InputError& e) {
    throw e.with_source(file.string());
  }
  const std::string target = file.string();
  if (!mat) {
    for (const std::string& name : ts.names) {
      if (name.find_first_of(",\n\r[]\"") != std::string::npos || name.front() == '#' || name != text::trim(name)) {
        throw InputError(target, "channel " + name, "a name without ',', brackets, quotes, line breaks or edge spaces", quote(name));
      }
    }
    for (const std::string& unit : ts.units) {
      if (unit.find_first_of(",\n\r[]\"") != std::string::npos) {
        throw InputError(target, "units", "units without ',', brackets, quotes or line breaks", quote(unit));
      }
    }
    return;
  }
  for (const std::string& name : ts.names) {
    if (!detail::is_matlab_identifier(name)) {
      throw InputError(target, "channel " + name, "a MATLAB variable name (letter, then letters, digits, _; <= 63)", quote(name));
    }
    if (name == kFs || name == kUnits || name == kSettings || name == kChannelOrder) {
      throw InputError(target, "channel " + name, "a name other than the reserved t, fs, units, settings, channels", quote(name));
    }
  }
  for (const auto& [key, value] : ts.settings) {
    if (!detail::is_matlab_identifier(key)) {
      throw InputError(target, "settings", "MATLAB field names (letter, then letters, digits, _)", quote(key));
    }
  }
}

}  // namespace

void write_timeseries_mat(const TimeSeries& ts, const fs::path& file, const MatWriteOptions& options) {
  validate_for_writing(ts, file, /*mat=*/true);
  const bool v73 = options.version == MatVersion::kV73;
  detail::write_mat_atomically(file, v73, options.compress, [&](detail::MatWriter& w) {
    if (ts.t.size() > 0) w.write(detail::make_real_column(kTime, ts.t));
    for (Eigen::Index j = 0; j < ts.data.cols(); ++j) {
      w.write(detail::make_real_column(ts.names[static_cast<size_t>(j)], ts.data.col(j)));
    }
    w.write(detail::make_scalar(kFs, ts.sample_rate));
    w.write(detail::make_text(kChannelOrder, text::join(ts.names, ",")));
    std::vector<std::pair<std::string, detail::MatValue>> unit_fields;
    if (ts.t.size() > 0) unit_fields.emplace_back(kTime, detail::make_text(kTime, "s"));
    for (size_t j = 0; j < ts.units.size(); ++j) {
      if (!ts.units[j].empty()) unit_fields.emplace_back(ts.names[j], detail::make_text(ts.names[j], ts.units[j]));
    }
    if (!ts.units.empty()) unit_fields.emplace_back(kFs, detail::make_text(kFs, "Hz"));
    if (!unit_fields.empty() && !ts.units.empty()) w.write(detail::make_struct(kUnits, std::move(unit_fields)));
    if (!ts.settings.empty()) {
      std::vector<std::pair<std::string, detail::MatValue>> fields;
      for (const auto& [key, value] : ts.settings) {
        if (std::holds_alternative<double>(value)) {
          fields.emplace_back(key, detail::make_scalar(key, std::get<double>(value)));
        } else {
          fields.emplace_back(key, detail::make_text(key, std::get<std::string>(value)));
        }
      }
      w.write(detail::make_struct(kSettings, std::move(fields)));
    }
  });
}

void write_timeseries_csv(const TimeSeries& ts, const fs::path& file) {
  validate_for_writing(ts, file, /*mat=*/false);
  write_atomically(file, [&](std::ostream& out) {
    const bool has_t = ts.t.size() > 0;
    std::string line;
    // CSV has no other place for the rate: without a time column it goes in a comment line
    // that read_timeseries_csv understands (and other tools skip as a comment).
    if (!has_t) out << "# sample_rate_Hz: " << format_number(ts.sample_rate, 17) << '\n';
    if (has_t) line += "t [s]";
    for (size_t j = 0; j < ts.names.size(); ++j) {
      if (has_t || j > 0) line += ',';
      line += ts.names[j];
      if (!ts.units.empty() && !ts.units[j].empty()) line += " [" + ts.units[j] + "]";
    }
    out << line << '\n';
    char buf[32];
    for (Eigen::Index k = 0; k < ts.data.rows(); ++k) {
      line.clear();
      if (has_t) line += format_number(ts.t(k), 17);
      for (Eigen::Index j = 0; j < ts.data.cols(); ++j) {
        if (has_t || j > 0) line += ',';
        const int n = std::snprintf(buf, sizeof buf, "%.17g", ts.data(k, j));
        line.append(buf, static_cast<size_t>(n));
      }
      line += '\n';
      out << line;
      if (!out) return;  // write_atomically reports the stream failure
    }
  });
}

}  // namespace piezobench::io
