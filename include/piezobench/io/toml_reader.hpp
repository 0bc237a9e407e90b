#pragma once
// The one typed reader of piezobench's TOML files (campaign, station, answers, bench, twin, LTI,
// hysteresis model, super element, 2-DoF parameters), over the tables io/toml_table.hpp parses.
//
// A TomlReader is a view of one table that knows the file and the table's key path. Every error is
// an InputError(source, field, expected, found) with
//   - source: "FILE: line L" (the line of the offending value; the file alone when it has none),
//   - field:  the full key path ("units[2].frf.file", "bench.sample_rate_Hz", "phases[3].steps[1]"),
//   - found:  what the file holds, numbers as written (core/format.hpp's format_number_exact:
//             "1e-12", never std::to_string's "0.000000").
//   "campaign.toml: line 7: analysis.fmax_Hz: expected a number > 0 Hz, found -5"
//
// Units: a key whose name ends in a unit symbol of io/units.hpp ("_Hz", "_um", "_V", "_s",
// "_N_per_um" as "N/um") names that unit in its errors ("a number > 0 Hz"); the value is returned
// as written (the caller converts, as the key says). Units: the caller's (bounds are in the key's unit).
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <toml++/toml.h>

namespace piezobench::io {

// What a number must be besides finite: an interval with open or closed ends.
struct NumberBounds {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;
  bool max_open = false;

  static NumberBounds any() { return {}; }
  static NumberBounds positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }        // > 0
  static NumberBounds non_negative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }  // >= 0
  static NumberBounds open(double lo, double hi) { return {lo, hi, true, true}; }                              // (lo, hi)
  static NumberBounds closed(double lo, double hi) { return {lo, hi, false, false}; }                          // [lo, hi]
  static NumberBounds half_open(double lo, double hi) { return {lo, hi, false, true}; }                        // [lo, hi)

  [[nodiscard]] bool contains(double v) const;
  // "a number", "a number > 0", "a number in [0, 1)", each followed by " UNIT" when unit is given.
  [[nodiscard]] std::string describe(const std::string& unit = "") const;
};

// The unit a key's name ends in, as io/units.hpp writes it ("fmin_Hz" -> "Hz", "stiffness_N_per_um"
// -> "N/um", "gravity_m_per_s2" -> "m/s2"); "" when it ends in none ("gain", "hpf_resistance_ohm").
std::string key_unit(std::string_view key);

class TomlReader {
 public:
  // `file` names the input in errors (a path, "--plant"); `path` is the table's key path ("" at the
  // root). The table must outlive the reader.
  TomlReader(const toml::table& table, std::string file, std::string path = "");

  [[nodiscard]] const toml::table& table() const { return *table_; }
  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  // The full path of key k of this table ("units[2]" + "frf" -> "units[2].frf").
  [[nodiscard]] std::string key(std::string_view k) const;
  // "FILE: line L" of `node` (this table's line when node is null or has no position).
  [[nodiscard]] std::string where(const toml::node* node = nullptr) const;
  // Throws InputError(where(at or key k's node), key(k), expected, found).
  [[noreturn]] void fail(std::string_view k, const std::string& expected, const std::string& found,
                         const toml::node* at = nullptr) const;

  [[nodiscard]] bool has(std::string_view k) const { return table_->contains(k); }
  [[nodiscard]] const toml::node* get(std::string_view k) const { return table_->get(k); }
  // Unknown keys are errors: "expected one of a, b, c, found an unknown key".
  void only(const std::vector<std::string>& known) const;

  // A finite number (a TOML integer or float) within `bounds`; nullopt when the key is absent.
  [[nodiscard]] std::optional<double> number(std::string_view k, const NumberBounds& bounds = {}) const;
  // The same, required: absent is "expected WHAT (or the bounds' words), found nothing (the key is required)".
  [[nodiscard]] double required_number(std::string_view k, const NumberBounds& bounds = {}, const std::string& what = "") const;
  // A TOML integer in [lo, hi] (a float is refused, never converted; core/checked_number.hpp).
  [[nodiscard]] std::optional<std::int64_t> integer(std::string_view k, std::int64_t lo = std::numeric_limits<std::int64_t>::min(),
                                                    std::int64_t hi = std::numeric_limits<std::int64_t>::max()) const;
  [[nodiscard]] std::optional<bool> boolean(std::string_view k) const;
  [[nodiscard]] std::optional<std::string> string(std::string_view k) const;
  [[nodiscard]] std::string required_string(std::string_view k, const std::string& what = "a string") const;
  // A string among `allowed`: "expected \"a\", \"b\" or \"c\", found 'x'".
  [[nodiscard]] std::optional<std::string> choice(std::string_view k, const std::vector<std::string>& allowed) const;

  // An array of finite numbers within `bounds` (absent: nullopt); errors name the element ("k[2]").
  [[nodiscard]] std::optional<std::vector<double>> numbers(std::string_view k, const NumberBounds& bounds = {}) const;
  [[nodiscard]] std::vector<double> required_numbers(std::string_view k, const NumberBounds& bounds = {}) const;
  // An array of TOML integers each in [lo, hi] (absent: nullopt); errors name the element.
  [[nodiscard]] std::optional<std::vector<std::int64_t>> integers(std::string_view k, std::int64_t lo, std::int64_t hi) const;
  // An array of strings; absent: empty.
  [[nodiscard]] std::vector<std::string> strings(std::string_view k) const;
  // [min, max]: two finite numbers (not ordered here; the caller says which order it needs).
  [[nodiscard]] std::optional<std::pair<double, double>> pair(std::string_view k, const std::string& what = "[min, max]") const;
  // An array (any elements), checked to be one; absent: nullptr.
  [[nodiscard]] const toml::array* array(std::string_view k, const std::string& what = "an array") const;
  // Element i of array k (for the line of an error about it); nullptr when there is none.
  [[nodiscard]] const toml::node* element(std::string_view k, std::size_t i) const;

  // A sub-table ([k] or k = {...}); absent: nullopt.
  [[nodiscard]] std::optional<TomlReader> table(std::string_view k) const;
  [[nodiscard]] TomlReader required_table(std::string_view k, const std::string& what = "") const;
  // The sub-table k, or when absent a reader of an empty table at that path (every key absent).
  [[nodiscard]] TomlReader table_or_empty(std::string_view k) const;
  // The tables of an array of tables ([[k]]), each with its path "k[i]"; absent: empty.
  [[nodiscard]] std::vector<TomlReader> tables(std::string_view k) const;

  // The number a node read by hand holds (an array's element): `k` is its key in this table
  // ("den[2]", "A[1][0]"), named in the error with this table's path.
  [[nodiscard]] double number_at(const toml::node& node, std::string_view k, const NumberBounds& bounds = {}) const;

 private:
  const toml::table* table_;
  std::string file_, path_;
};

}  // namespace piezobench::io
