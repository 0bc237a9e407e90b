#include "piezobench/io/frf_file.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <set>

#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "uff58.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "piezobench/io/units.hpp"

namespace piezobench::io {
namespace fs = std::filesystem;
using text::quote;
using Eigen::Index;

// ---- UFF 58 ---------------------------------------------------------------------------------
//
// Universal File Format dataset 58 "Function at nodal DOF" (SDRC I-DEAS; UC-SDRL's description,
// as used by pyuff): "    -1", "    58", five 80-column ID lines, records 6..11 (DOF
// identification, data form, abscissa / ordinate / denominator / z-axis characteristics), then
// record 12 (the values) and "    -1". Binary 58b: the identifier line is
// Format(I6,1A1,I6,I6,I12,I12,I6,I6,I12,I12) = 58, 'b', byte order (1 little, 2 big endian),
// floating point format (2 = IEEE 754), number of ASCII lines following (11), number of bytes
// following them, 4 unused; record 12 is then that many raw bytes in the same value order, with
// no line break before the closing "    -1".

namespace {

constexpr int kFuncFrf = 4;
constexpr int kFuncCoherence = 6;
constexpr int kOrdRealSingle = 2, kOrdRealDouble = 4, kOrdComplexSingle = 5, kOrdComplexDouble = 6;
constexpr int kSpecFrequency = 18;
constexpr int kSpecTime = 17;
constexpr int kSpecAcceleration = 12;
constexpr int kFuncTime = 1;  // time response (what Testlab and Simcenter export as time histories)
constexpr double kStandardGravity = 9.80665;  // m/s^2 per g
constexpr int kDirZ = 3;
constexpr const char* kResponseTag = "piezobench response: ";
constexpr const char* kReferenceTag = "piezobench reference: ";
constexpr const char* kProvenanceTag = "welch: ";  // ID line 5: how the FRF was estimated

std::string fmt_line(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string fmt_line(const char* format, ...) {
  char buf[256];
  va_list ap;
  va_start(ap, format);
  const int n = std::vsnprintf(buf, sizeof buf, format, ap);
  va_end(ap);
  return std::string(buf, static_cast<size_t>(std::clamp(n, 0, static_cast<int>(sizeof buf) - 1)));
}

std::string id_line(const std::string& text) {
  // General note 1 of the format: ID lines may not be blank; "NONE" when unused.
  return text.empty() ? std::string("NONE") : text.substr(0, 80);
}

std::string label20(const std::string& text) { return text.empty() ? std::string("NONE") : text.substr(0, 20); }

// Evenly spaced within a millionth of a step (the file keeps 6 digits of min and increment anyway).
bool is_uniform(const Eigen::VectorXd& f) {
  const Index n = f.size();
  if (n < 2) return false;
  const double step = (f(n - 1) - f(0)) / static_cast<double>(n - 1);
  for (Index k = 1; k + 1 < n; ++k) {
    if (std::abs(f(k) - (f(0) + static_cast<double>(k) * step)) > 1e-6 * step) return false;
  }
  return true;
}

std::string provenance_line(const dsp::FrfProvenance& p) {
  if (p.estimator.empty() && p.window.empty() && p.nfft == 0) return "NONE";
  std::vector<std::string> fields;
  if (!p.estimator.empty()) fields.push_back("est=" + p.estimator);
  if (!p.window.empty()) fields.push_back("win=" + p.window);
  if (p.nfft > 0) fields.push_back("nfft=" + std::to_string(p.nfft));
  fields.push_back("ovl=" + format_number(p.overlap, 10));
  if (!p.detrend.empty()) fields.push_back("dtr=" + p.detrend);
  if (p.averages > 0) fields.push_back("avg=" + std::to_string(p.averages));
  if (p.sample_rate > 0) fields.push_back("fs=" + format_number(p.sample_rate, 10));
  // Whole fields only: a field cut at column 80 would read back as a wrong number.
  std::string line = kProvenanceTag;
  for (const std::string& f : fields) {
    if (line.size() + f.size() + 1 > 80) break;
    if (line.back() != ' ') line += ' ';
    line += f;
  }
  return line;
}

void write_dataset(std::ostream& out, int func_type, int func_id, const std::string& response, int response_node,
                   const std::string& reference, int reference_node, const Eigen::VectorXd& freq,
                   const Eigen::VectorXcd* complex_values, const Eigen::VectorXd* real_values,
                   const FrfWriteOptions& options, const std::string& id5, const std::string& ord_unit = "",
                   const std::string& denom_unit = "") {
  const Index n = freq.size();
  const bool even = is_uniform(freq);
  const bool is_complex = complex_values != nullptr;
  out << "    -1\n    58\n";
  const std::string what = func_type == kFuncFrf ? "FRF " : "Coherence ";
  out << id_line(what + response + " / " + reference) << '\n';
  out << id_line(kResponseTag + response) << '\n';
  out << id_line(options.date) << '\n';
  out << id_line(kReferenceTag + reference) << '\n';
  out << id_line(id5) << '\n';
  // Record 6: Format(2(I5,I10),2(1X,10A1,I10,I4)).
  out << fmt_line("%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d", func_type, func_id, 0, 0, "NONE", response_node, kDirZ,
                  "NONE", reference_node, kDirZ)
      << '\n';
  // Record 7: Format(3I10,3E13.5).
  const double step = even ? (freq(n - 1) - freq(0)) / static_cast<double>(n - 1) : 0.0;
  out << fmt_line("%10d%10d%10d%13.5E%13.5E%13.5E", is_complex ? kOrdComplexDouble : kOrdRealDouble, static_cast<int>(n),
                  even ? 1 : 0, even ? freq(0) : 0.0, step, 0.0)
      << '\n';
  // Records 8..11: Format(I10,3I5,2(1X,20A1)).
  out << fmt_line("%10d%5d%5d%5d %-20s %-20s", kSpecFrequency, 0, 0, 0, "Frequency", "Hz") << '\n';
  out << fmt_line("%10d%5d%5d%5d %-20s %-20s", 0, 0, 0, 0, label20(response).c_str(), label20(ord_unit).c_str()) << '\n';
  out << fmt_line("%10d%5d%5d%5d %-20s %-20s", 0, 0, 0, 0, label20(func_type == kFuncFrf ? reference : response).c_str(),
                  label20(denom_unit).c_str())
      << '\n';
  out << fmt_line("%10d%5d%5d%5d %-20s %-20s", 0, 0, 0, 0, "NONE", "NONE") << '\n';
  // Record 12: cases 5..8 of the format's addendum B.
  std::string line;
  int on_line = 0;
  const auto flush_if = [&](int per_line) {
    if (++on_line == per_line) {
      out << line << '\n';
      line.clear();
      on_line = 0;
    }
  };
  for (Index k = 0; k < n; ++k) {
    if (is_complex) {
      const std::complex<double> h = (*complex_values)(k);
      if (even) {  // 4E20.12: two values per line
        line += fmt_line("%20.12E%20.12E", h.real(), h.imag());
        flush_if(2);
      } else {  // E13.5,2E20.12: one value per line
        line += fmt_line("%13.5E%20.12E%20.12E", freq(k), h.real(), h.imag());
        flush_if(1);
      }
    } else {
      const double v = (*real_values)(k);
      if (even) {  // 4E20.12
        line += fmt_line("%20.12E", v);
        flush_if(4);
      } else {  // 2(E13.5,E20.12)
        line += fmt_line("%13.5E%20.12E", freq(k), v);
        flush_if(2);
      }
    }
  }
  if (!line.empty()) out << line << '\n';
  out << "    -1\n";
}

}  // namespace

void write_frf_uff58(const dsp::Frf& frf, const fs::path& file, const FrfWriteOptions& options) {
  options.validate();
  frf.validate(file.string());
  const auto check_name = [&](const std::string& name, const std::string& what) {
    if (name.size() > 80 - std::strlen(kResponseTag) ||
        std::any_of(name.begin(), name.end(), [](char c) { return c < 32 || c > 126; })) {
      throw InputError(file.string(), what + " " + name, "printable ASCII of at most 58 characters", quote(name));
    }
  };
  for (const std::string& o : frf.outputs) check_name(o, "output");
  check_name(frf.input, "input");
  if (frf.freq_Hz.minCoeff() < 0.0) throw InputError(file.string(), "freq_Hz", "frequencies >= 0 Hz", format_number(frf.freq_Hz.minCoeff(), 10));
  const std::string input = frf.input.empty() ? std::string("input") : frf.input;
  const std::string id5 = provenance_line(frf.provenance);
  write_atomically(file, [&](std::ostream& out) {
    for (size_t i = 0; i < frf.outputs.size(); ++i) {
      const int node = static_cast<int>(i) + 1;
      const std::string ord_unit = i < options.output_units.size() ? options.output_units[i] : std::string();
      const std::string denom_unit = options.output_units.empty() ? std::string() : options.input_unit;
      write_dataset(out, kFuncFrf, node, frf.outputs[i], node, input, options.reference_node, frf.freq_Hz, &frf.H[i], nullptr,
                    options, id5, ord_unit.empty() && !denom_unit.empty() ? "1" : ord_unit, denom_unit);
      if (!frf.coherence.empty()) {
        write_dataset(out, kFuncCoherence, node, frf.outputs[i], node, input, options.reference_node, frf.freq_Hz, nullptr,
                      &frf.coherence[i], options, id5);
      }
    }
  });
}

namespace {

// One dataset 58 as read from the file.
struct Dataset58 {
  size_t line = 0;  // line of its "58" identifier
  int func_type = 0;
  std::string id[5];
  std::string rsp_entity, ref_entity;
  long long rsp_node = 0, rsp_dir = 0, ref_node = 0, ref_dir = 0;
  int ord_type = 0;
  long long n = 0;
  bool even = false;
  double abscissa_min = 0.0, abscissa_inc = 0.0;
  int abscissa_spec = 0;
  std::string ord_label, denom_label;
  std::string abscissa_unit, ord_unit, denom_unit;  // records 8-10 units labels ("" = NONE)
  int ord_spec = 0;                                  // record 9 specific data type (12 acceleration, ...)
  double abscissa_scale = 1.0;                       // SI per abscissa unit (ms: 1e-3)
  bool abscissa_time = false;                        // abscissa in s (else Hz), from its unit or type
  std::string frf_unit;                              // an FRF's SI unit from records 9 and 10 ("" = none given)
  Eigen::VectorXd x;
  Eigen::VectorXcd y;
};

class UffReader {
 public:
  UffReader(std::string content, std::string source) : data_(std::move(content)), source_(std::move(source)) {}

  std::vector<Dataset58> read_all() {
    std::vector<Dataset58> out;
    std::string_view line;
    while (next_line(line)) {
      if (text::trim(line) != "-1") {
        if (text::trim(line).empty()) continue;
        throw InputError(source_, "line " + std::to_string(line_no_), "a dataset start (    -1)", quote(line));
      }
      std::string_view id_line;
      if (!next_line(id_line)) break;  // a trailing "-1" with nothing after it
      const std::string_view id_text = id_line.substr(0, std::min<size_t>(6, id_line.size()));
      const std::optional<long long> id = text::parse_int(id_text);
      if (!id) throw InputError(source_, "line " + std::to_string(line_no_), "a dataset number", quote(id_line));
      const bool binary = id_line.size() > 6 && (id_line[6] == 'b' || id_line[6] == 'B');
      if (*id == 58) {
        out.push_back(read_58(id_line, binary));
      } else {
        skip_dataset(id_line, binary, *id);
      }
    }
    return out;
  }

 private:
  std::string field(const Dataset58& d, const std::string& what) const {
    return "dataset 58 at line " + std::to_string(d.line) + " " + what;
  }

  bool next_line(std::string_view& line) {
    if (pos_ >= data_.size()) return false;
    size_t end = data_.find('\n', pos_);
    if (end == std::string::npos) end = data_.size();
    line = std::string_view(data_).substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end + 1;
    ++line_no_;
    return true;
  }

  std::string_view require_line(const Dataset58& d, const std::string& what) {
    std::string_view line;
    if (!next_line(line)) throw InputError(source_, field(d, what), "a line", "the end of the file (truncated?)");
    return line;
  }

  static std::string_view column(std::string_view line, size_t start, size_t width) {
    if (start >= line.size()) return {};
    return line.substr(start, width);
  }

  long long int_field(const Dataset58& d, std::string_view line, size_t start, size_t width, const std::string& what) const {
    const std::string_view text = column(line, start, width);
    if (text::trim(text).empty()) return 0;  // Fortran reads blanks as zero
    const std::optional<long long> v = text::parse_int(text);
    if (!v) throw InputError(source_, field(d, what), "an integer", quote(text));
    return *v;
  }

  double real_field(const Dataset58& d, std::string_view line, size_t start, size_t width, const std::string& what) const {
    const std::string_view text = column(line, start, width);
    if (text::trim(text).empty()) return 0.0;
    const std::optional<double> v = text::parse_double(text, /*fortran=*/true);
    if (!v || !std::isfinite(*v)) throw InputError(source_, field(d, what), "a finite number", quote(text));
    return *v;
  }

  // Skips a dataset of another type (ASCII: up to its "-1"; binary: its declared lengths).
  void skip_dataset(std::string_view id_line, bool binary, long long id) {
    const size_t start_line = line_no_;
    if (binary) {
      const std::optional<long long> ascii_lines = text::parse_int(column(id_line, 19, 12));
      const std::optional<long long> bytes = text::parse_int(column(id_line, 31, 12));
      if (!ascii_lines || !bytes || *ascii_lines < 0 || *bytes < 0) {
        throw InputError(source_, "dataset " + std::to_string(id) + "b at line " + std::to_string(start_line),
                         "the binary header (I6,A1,I6,I6,I12,I12,...)", quote(id_line));
      }
      std::string_view line;
      for (long long i = 0; i < *ascii_lines; ++i) {
        if (!next_line(line)) throw InputError(source_, "dataset " + std::to_string(id) + "b", "its header lines", "the end of the file");
      }
      if (static_cast<unsigned long long>(*bytes) > data_.size() - std::min(pos_, data_.size())) {
        throw InputError(source_, "dataset " + std::to_string(id) + "b", std::to_string(*bytes) + " bytes of data", "a truncated file");
      }
      pos_ += static_cast<size_t>(*bytes);
    }
    std::string_view line;
    while (next_line(line)) {
      if (text::trim(line) == "-1") return;
    }
    throw InputError(source_, "dataset " + std::to_string(id) + " at line " + std::to_string(start_line), "a closing -1",
                     "the end of the file (truncated?)");
  }

  Dataset58 read_58(std::string_view id_line, bool binary) {
    Dataset58 d;
    d.line = line_no_;
    int byte_order = 1;
    long long n_bytes = 0;
    if (binary) {
      // Format(I6,1A1,I6,I6,I12,I12,I6,I6,I12,I12)
      byte_order = static_cast<int>(int_field(d, id_line, 7, 6, "(58b byte order)"));
      const long long fp = int_field(d, id_line, 13, 6, "(58b floating-point format)");
      const long long ascii_lines = int_field(d, id_line, 19, 12, "(58b number of ASCII lines)");
      n_bytes = int_field(d, id_line, 31, 12, "(58b number of bytes)");
      if (byte_order != 1 && byte_order != 2) {
        throw InputError(source_, field(d, "(58b byte order)"), "1 (little endian) or 2 (big endian)", std::to_string(byte_order));
      }
      if (fp != 2) throw InputError(source_, field(d, "(58b floating-point format)"), "2 (IEEE 754)", std::to_string(fp));
      if (ascii_lines != 11) throw InputError(source_, field(d, "(58b number of ASCII lines)"), "11", std::to_string(ascii_lines));
      if (n_bytes < 0) throw InputError(source_, field(d, "(58b number of bytes)"), "a byte count >= 0", std::to_string(n_bytes));
    }
    for (auto& id : d.id) id = text::utf8_from_legacy(text::trim(require_line(d, "ID lines")));
    const std::string_view r6 = require_line(d, "record 6");
    d.func_type = static_cast<int>(int_field(d, r6, 0, 5, "record 6 (function type)"));
    d.rsp_entity = text::utf8_from_legacy(text::trim(column(r6, 30, 11)));
    d.rsp_node = int_field(d, r6, 41, 10, "record 6 (response node)");
    d.rsp_dir = int_field(d, r6, 51, 4, "record 6 (response direction)");
    d.ref_entity = text::utf8_from_legacy(text::trim(column(r6, 55, 11)));
    d.ref_node = int_field(d, r6, 66, 10, "record 6 (reference node)");
    d.ref_dir = int_field(d, r6, 76, 4, "record 6 (reference direction)");
    const std::string_view r7 = require_line(d, "record 7");
    d.ord_type = static_cast<int>(int_field(d, r7, 0, 10, "record 7 (ordinate data type)"));
    d.n = int_field(d, r7, 10, 10, "record 7 (number of values)");
    const long long spacing = int_field(d, r7, 20, 10, "record 7 (abscissa spacing)");
    d.abscissa_min = real_field(d, r7, 30, 13, "record 7 (abscissa minimum)");
    d.abscissa_inc = real_field(d, r7, 43, 13, "record 7 (abscissa increment)");
    if (d.ord_type != kOrdRealSingle && d.ord_type != kOrdRealDouble && d.ord_type != kOrdComplexSingle &&
        d.ord_type != kOrdComplexDouble) {
      throw InputError(source_, field(d, "record 7 (ordinate data type)"), "2, 4, 5 or 6", std::to_string(d.ord_type));
    }
    if (spacing != 0 && spacing != 1) throw InputError(source_, field(d, "record 7 (abscissa spacing)"), "0 or 1", std::to_string(spacing));
    d.even = spacing == 1;
    // A bound on what a file can hold keeps a corrupt count from allocating gigabytes.
    const auto max_n = static_cast<long long>(data_.size());
    if (d.n < 1 || d.n > max_n) {
      throw InputError(source_, field(d, "record 7 (number of values)"), "between 1 and the file size", std::to_string(d.n));
    }
    if (d.even && !(d.abscissa_inc > 0.0)) {
      throw InputError(source_, field(d, "record 7 (abscissa increment)"), "> 0 for even spacing", format_number(d.abscissa_inc, 10));
    }
    const auto units_label = [](std::string_view record) {
      std::string u = text::utf8_from_legacy(text::trim(column(record, 47, 20)));
      return u == "NONE" ? std::string() : u;
    };
    const std::string_view r8 = require_line(d, "record 8");
    d.abscissa_spec = static_cast<int>(int_field(d, r8, 0, 10, "record 8 (abscissa data type)"));
    d.abscissa_unit = units_label(r8);
    const std::string_view r9 = require_line(d, "record 9");
    d.ord_spec = static_cast<int>(int_field(d, r9, 0, 10, "record 9 (ordinate data type)"));
    d.ord_label = text::utf8_from_legacy(text::trim(column(r9, 26, 20)));
    d.ord_unit = units_label(r9);
    const std::string_view r10 = require_line(d, "record 10");
    d.denom_label = text::utf8_from_legacy(text::trim(column(r10, 26, 20)));
    d.denom_unit = units_label(r10);
    (void)require_line(d, "record 11");

    if (binary) {
      read_binary_values(d, byte_order, n_bytes);
    } else {
      read_ascii_values(d);
    }
    if (d.even) {
      d.x.resize(static_cast<Index>(d.n));
      for (Index k = 0; k < d.x.size(); ++k) d.x(k) = d.abscissa_min + static_cast<double>(k) * d.abscissa_inc;
    }
    to_si(d);
    return d;
  }

  // Units labels of records 8-10, honoured or refused: the abscissa in Hz (kHz converted) or, for
  // a time history (function type 1, abscissa type 17), in s (ms converted); an FRF's ordinate as
  // numerator / denominator in SI (e.g. um / V scales by 1e-6; a numerator that is a quotient
  // holding the denominator already, such as `(1/N)*(m/s^2)` over `N`, is not divided twice). An
  // unlabelled ("NONE") axis is taken as SI. Coherence (function type 6) is dimensionless; a time
  // history's ordinate is converted by the time-series reader (its unit is kept in ord_unit).
  void to_si(Dataset58& d) const {
    d.abscissa_time = is_time_history(d);
    if (!d.abscissa_unit.empty()) {
      const std::string where = field(d, "record 8 (abscissa units)");
      const Unit u = unit_from_string(d.abscissa_unit, source_, where);
      if (u.quantity != Quantity::kTime && u.quantity != Quantity::kFrequency) {
        throw InputError(source_, where, "a frequency unit (Hz, kHz) or a time unit (s, ms)", "unit " + quote(d.abscissa_unit));
      }
      d.abscissa_time = u.quantity == Quantity::kTime;
      d.abscissa_scale = u.to_si;
      d.x *= u.to_si;
    }
    if (d.func_type == kFuncTime && (d.ord_unit == "g" || d.ord_unit == "G") && d.ord_spec == kSpecAcceleration) {
      d.y *= kStandardGravity;  // an accelerometer's g, not grams
      d.ord_unit = "m/s^2";
    }
    if (d.func_type != kFuncFrf) return;
    // The FRF's unit as text the unit table parses ("(m/s^2)/(N)"); H stays as stored.
    std::string numerator = d.ord_unit;
    if (d.ord_unit == "g" && d.ord_spec == kSpecAcceleration) {
      d.y *= kStandardGravity;
      numerator = "m/s^2";
    }
    if (numerator.empty() && d.denom_unit.empty()) return;
    d.frf_unit = numerator.empty() ? "1" : "(" + numerator + ")";
    const Unit num = numerator.empty() ? Unit{} : unit_from_string(numerator, source_, field(d, "record 9 (ordinate units)"));
    if (d.denom_unit.empty()) return;
    const Unit den = unit_from_string(d.denom_unit, source_, field(d, "record 10 (denominator units)"));
    const std::vector<std::string_view> parts = text::split(num.si_symbol, '/');
    const bool divided = parts.size() > 1 && std::find(parts.begin() + 1, parts.end(), std::string_view(den.si_symbol)) != parts.end();
    if (!divided) d.frf_unit += "/(" + d.denom_unit + ")";
  }

  static bool is_time_history(const Dataset58& d) { return d.func_type == kFuncTime || d.abscissa_spec == kSpecTime; }

  bool is_complex(const Dataset58& d) const { return d.ord_type == kOrdComplexSingle || d.ord_type == kOrdComplexDouble; }

  // Stores the flat value sequence (record 12 order) into x and y.
  void unpack(Dataset58& d, const std::vector<double>& v) {
    const auto n = static_cast<Index>(d.n);
    const int per_point = (is_complex(d) ? 2 : 1) + (d.even ? 0 : 1);
    d.y.resize(n);
    if (!d.even) d.x.resize(n);
    for (Index k = 0; k < n; ++k) {
      const size_t base = static_cast<size_t>(k) * static_cast<size_t>(per_point);
      size_t i = base;
      if (!d.even) d.x(k) = v[i++];
      const double re = v[i++];
      const double im = is_complex(d) ? v[i++] : 0.0;
      d.y(k) = {re, im};
    }
  }

  void read_ascii_values(Dataset58& d) {
    const int per_point = (is_complex(d) ? 2 : 1) + (d.even ? 0 : 1);
    const size_t expected = static_cast<size_t>(d.n) * static_cast<size_t>(per_point);
    std::vector<std::string_view> lines;
    std::string_view line;
    bool closed = false;
    while (next_line(line)) {
      if (text::trim(line) == "-1") {
        closed = true;
        break;
      }
      lines.push_back(line);
    }
    if (!closed) throw InputError(source_, field(d, "record 12"), "values followed by -1", "the end of the file (truncated?)");
    // Free format first (what most writers produce: fields separated by blanks) ...
    std::vector<double> values;
    values.reserve(expected);
    bool free_ok = true;
    for (std::string_view l : lines) {
      size_t i = 0;
      while (i < l.size() && free_ok) {
        while (i < l.size() && (l[i] == ' ' || l[i] == '\t')) ++i;
        if (i >= l.size()) break;
        size_t j = i;
        while (j < l.size() && l[j] != ' ' && l[j] != '\t') ++j;
        const std::optional<double> v = text::parse_double(l.substr(i, j - i), /*fortran=*/true);
        if (!v) free_ok = false;
        else values.push_back(*v);
        i = j;
      }
      if (!free_ok) break;
    }
    // ... then the fixed columns of the format, for fields that touch (e.g. -1.0E+00-2.0E+00).
    if (!free_ok || values.size() != expected) {
      values.clear();
      std::vector<size_t> widths;
      const bool single = d.ord_type == kOrdRealSingle || d.ord_type == kOrdComplexSingle;
      if (single) widths.assign(6, 13);
      else if (d.even) widths.assign(4, 20);
      else if (is_complex(d)) widths = {13, 20, 20};
      else widths = {13, 20, 13, 20};
      for (size_t li = 0; li < lines.size(); ++li) {
        size_t start = 0;
        for (size_t w : widths) {
          const std::string_view text = column(lines[li], start, w);
          start += w;
          if (text::trim(text).empty()) continue;
          const std::optional<double> v = text::parse_double(text, /*fortran=*/true);
          if (!v) {
            throw InputError(source_, field(d, "record 12 (line " + std::to_string(d.line + 11 + li + 1) + ")"), "a number",
                             quote(text));
          }
          values.push_back(*v);
        }
      }
    }
    if (values.size() != expected) {
      throw InputError(source_, field(d, "record 12"), std::to_string(expected) + " values (" + std::to_string(d.n) + " points)",
                       std::to_string(values.size()));
    }
    for (size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) {
        throw InputError(source_, field(d, "record 12"), "finite values", "a non-finite value at position " + std::to_string(i));
      }
    }
    unpack(d, values);
  }

  static double decode(const unsigned char* p, int size, bool swap) {
    unsigned char b[8];
    for (int i = 0; i < size; ++i) b[i] = swap ? p[size - 1 - i] : p[i];
    if (size == 4) {
      float f;
      std::memcpy(&f, b, 4);
      return static_cast<double>(f);
    }
    double v;
    std::memcpy(&v, b, 8);
    return v;
  }

  void read_binary_values(Dataset58& d, int byte_order, long long n_bytes) {
    const bool single = d.ord_type == kOrdRealSingle || d.ord_type == kOrdComplexSingle;
    const int size = single ? 4 : 8;
    const int ord_per_point = is_complex(d) ? 2 : 1;
    const auto n = static_cast<unsigned long long>(d.n);
    // The abscissa of uneven data is single precision in the format's text but double in
    // several writers (pyuff); the byte count tells which.
    int x_size = 0;
    const unsigned long long ordinate_bytes = n * static_cast<unsigned long long>(ord_per_point * size);
    if (d.even) {
      if (static_cast<unsigned long long>(n_bytes) != ordinate_bytes) {
        throw InputError(source_, field(d, "(58b number of bytes)"), std::to_string(ordinate_bytes) + " for " + std::to_string(n) + " values",
                         std::to_string(n_bytes));
      }
    } else if (static_cast<unsigned long long>(n_bytes) == ordinate_bytes + 4 * n) {
      x_size = 4;
    } else if (static_cast<unsigned long long>(n_bytes) == ordinate_bytes + 8 * n) {
      x_size = 8;
    } else {
      throw InputError(source_, field(d, "(58b number of bytes)"),
                       std::to_string(ordinate_bytes + 4 * n) + " or " + std::to_string(ordinate_bytes + 8 * n) + " for " +
                           std::to_string(n) + " uneven points",
                       std::to_string(n_bytes));
    }
    if (static_cast<unsigned long long>(n_bytes) > data_.size() - std::min(pos_, data_.size())) {
      throw InputError(source_, field(d, "record 12"), std::to_string(n_bytes) + " bytes of binary data",
                       std::to_string(data_.size() - std::min(pos_, data_.size())) + " bytes left (truncated file)");
    }
    const bool swap = (byte_order == 1) != (std::endian::native == std::endian::little);
    const auto* p = reinterpret_cast<const unsigned char*>(data_.data() + pos_);
    std::vector<double> values;
    values.reserve(static_cast<size_t>(n) * static_cast<size_t>(ord_per_point + (d.even ? 0 : 1)));
    for (unsigned long long k = 0; k < n; ++k) {
      if (!d.even) {
        values.push_back(decode(p, x_size, swap));
        p += x_size;
      }
      for (int j = 0; j < ord_per_point; ++j) {
        values.push_back(decode(p, size, swap));
        p += size;
      }
    }
    pos_ += static_cast<size_t>(n_bytes);
    for (size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) {
        throw InputError(source_, field(d, "record 12"), "finite values", "a non-finite value at position " + std::to_string(i));
      }
    }
    unpack(d, values);
    // No line break is due before the closing -1, but some writers add one: accept both.
    std::string_view line;
    while (next_line(line)) {
      if (text::trim(line).empty()) continue;
      if (text::trim(line) == "-1") return;
      throw InputError(source_, field(d, "end"), "-1 after the binary data", quote(line));
    }
    throw InputError(source_, field(d, "end"), "-1 after the binary data", "the end of the file (truncated?)");
  }

  std::string data_;
  std::string source_;
  size_t pos_ = 0;
  size_t line_no_ = 0;
};

std::string dof_name(long long node, long long dir) {
  static const char* kDirs[] = {"", "+X", "+Y", "+Z", "+RX", "+RY", "+RZ"};
  std::string out = std::to_string(node);
  if (dir >= 1 && dir <= 6) out += kDirs[dir];
  if (dir <= -1 && dir >= -6) out += std::string("-") + (kDirs[-dir] + 1);
  return out;
}

bool usable_label(const std::string& s) { return !s.empty() && s != "NONE"; }

std::string tagged(const std::string& id, const char* tag) {
  const size_t len = std::strlen(tag);
  return id.size() > len && id.compare(0, len, tag) == 0 ? std::string(text::trim(std::string_view(id).substr(len))) : std::string();
}

std::string response_name(const Dataset58& d) {
  if (std::string s = tagged(d.id[1], kResponseTag); !s.empty()) return s;
  if (usable_label(d.ord_label)) return d.ord_label;
  if (usable_label(d.rsp_entity)) return d.rsp_entity + ":" + dof_name(d.rsp_node, d.rsp_dir);
  return dof_name(d.rsp_node, d.rsp_dir);
}

std::string reference_name(const Dataset58& d) {
  if (std::string s = tagged(d.id[3], kReferenceTag); !s.empty()) return s;
  if (d.func_type == kFuncFrf && usable_label(d.denom_label)) return d.denom_label;
  if (usable_label(d.ref_entity)) return d.ref_entity + ":" + dof_name(d.ref_node, d.ref_dir);
  return dof_name(d.ref_node, d.ref_dir);
}

void parse_provenance(const std::string& id5, dsp::FrfProvenance& p) {
  if (id5.rfind(kProvenanceTag, 0) != 0) return;
  std::istringstream in(id5.substr(std::strlen(kProvenanceTag)));
  std::string token;
  while (in >> token) {
    const size_t eq = token.find('=');
    if (eq == std::string::npos) continue;
    const std::string key = token.substr(0, eq), value = token.substr(eq + 1);
    const std::optional<double> num = text::parse_double(value);
    if (key == "est") p.estimator = value;
    else if (key == "win") p.window = value;
    else if (key == "dtr") p.detrend = value;
    else if (key == "nfft" && num) p.nfft = static_cast<Index>(*num);
    else if (key == "ovl" && num) p.overlap = *num;
    else if (key == "avg" && num) p.averages = static_cast<Index>(*num);
    else if (key == "fs" && num) p.sample_rate = *num;
  }
}

}  // namespace

namespace detail {
StatedFrf read_uff58_frf(const fs::path& file) {
  const std::string source = file.string();
  StatedFrf stated;
  UffReader reader(read_file(file), source);
  const std::vector<Dataset58> datasets = reader.read_all();
  const Dataset58* first = nullptr;
  dsp::Frf frf;
  std::map<std::string, const Dataset58*> coherence;
  for (const Dataset58& d : datasets) {
    const std::string where = "dataset 58 at line " + std::to_string(d.line);
    if (d.abscissa_spec != 0 && d.abscissa_spec != kSpecFrequency) {
      if (d.func_type == kFuncFrf) throw InputError(source, where + " record 8", "a frequency abscissa (18)", std::to_string(d.abscissa_spec));
      continue;
    }
    if (d.func_type == kFuncCoherence) {
      coherence[response_name(d)] = &d;
      continue;
    }
    if (d.func_type != kFuncFrf) continue;
    if (d.abscissa_time) {
      throw InputError(source, where + " record 8 (abscissa units)", "a frequency unit (Hz, kHz) for an FRF", "unit " + quote(d.abscissa_unit));
    }
    const std::string out = response_name(d), in = reference_name(d);
    if (first == nullptr) {
      first = &d;
      frf.input = in;
      frf.freq_Hz = d.x;
      parse_provenance(d.id[4], frf.provenance);
    } else {
      if (in != frf.input) {
        throw InputError(source, where + " reference", "the reference of the first FRF (" + frf.input + ")", quote(in));
      }
      const double scale = frf.freq_Hz.cwiseAbs().maxCoeff();
      if (d.x.size() != frf.freq_Hz.size() || (d.x - frf.freq_Hz).cwiseAbs().maxCoeff() > 1e-5 * scale) {
        throw InputError(source, where + " abscissa", "the frequency grid of the first FRF (" + std::to_string(frf.freq_Hz.size()) + " points)",
                         "a different grid (" + std::to_string(d.x.size()) + " points)");
      }
    }
    if (std::find(frf.outputs.begin(), frf.outputs.end(), out) != frf.outputs.end()) {
      throw InputError(source, where + " response", "one FRF per response", quote(out) + " twice");
    }
    frf.outputs.push_back(out);
    frf.H.push_back(d.y);
    stated.units.push_back(d.frf_unit);
  }
  if (first == nullptr) {
    throw InputError(source, "datasets", "at least one dataset 58 of function type 4 (FRF)",
                     std::to_string(datasets.size()) + " datasets 58, none an FRF");
  }
  // Coherence is kept when every output has one on the same grid.
  bool all = true;
  for (const std::string& o : frf.outputs) {
    const auto it = coherence.find(o);
    all = all && it != coherence.end() && it->second->x.size() == frf.freq_Hz.size();
  }
  if (all) {
    for (const std::string& o : frf.outputs) frf.coherence.emplace_back(coherence[o]->y.real());
  }
  // UFF 58 has no function type for a standard deviation: it follows from the coherence and the
  // Welch settings of ID line 5 (dsp/frf_variance.hpp), when both are there.
  frf.std_H = dsp::std_from_coherence(frf);
  frf.provenance.source = source;
  stated.frf = std::move(frf);
  return stated;
}
}  // namespace detail

}  // namespace piezobench::io

namespace piezobench::io::detail {
namespace {

bool unique(const std::vector<std::string>& names) {
  std::set<std::string> seen;
  for (const std::string& n : names) {
    if (!seen.insert(n).second) return false;
  }
  return true;
}

// A time history's channel name: the piezobench tag of ID line 2, else the response entity name
// of record 6 ("Mic 01"), else its node and direction ("3+Z"), else ID line 1; names that repeat
// across records get the node and direction ("Point:3+Z"), then ID line 1, then "#k" appended.
std::vector<std::string> time_history_names(const std::vector<const Dataset58*>& records) {
  std::vector<std::string> names;
  for (const Dataset58* d : records) {
    if (std::string s = tagged(d->id[1], kResponseTag); !s.empty()) names.push_back(s);
    else if (usable_label(d->rsp_entity)) names.push_back(d->rsp_entity);
    else if (d->rsp_node != 0) names.push_back(dof_name(d->rsp_node, d->rsp_dir));
    else if (usable_label(d->id[0])) names.push_back(d->id[0]);
    else names.push_back(dof_name(d->rsp_node, d->rsp_dir));
  }
  if (unique(names)) return names;
  std::vector<std::string> with_dof = names;
  for (size_t i = 0; i < records.size(); ++i) {
    if (std::count(names.begin(), names.end(), names[i]) > 1) with_dof[i] = names[i] + ":" + dof_name(records[i]->rsp_node, records[i]->rsp_dir);
  }
  if (unique(with_dof)) return with_dof;
  std::vector<std::string> by_id = with_dof;
  for (size_t i = 0; i < records.size(); ++i) {
    if (std::count(with_dof.begin(), with_dof.end(), with_dof[i]) > 1 && usable_label(records[i]->id[0])) by_id[i] = records[i]->id[0];
  }
  if (unique(by_id)) return by_id;
  for (size_t i = 0; i < records.size(); ++i) by_id[i] += "#" + std::to_string(i + 1);
  return by_id;
}

}  // namespace

UffTimeHistories read_uff58_time_histories(const fs::path& file) {
  const std::string source = file.string();
  UffReader reader(read_file(file), source);
  const std::vector<Dataset58> datasets = reader.read_all();
  std::vector<const Dataset58*> records;
  for (const Dataset58& d : datasets) {
    if (d.func_type == kFuncTime || d.abscissa_spec == kSpecTime) records.push_back(&d);
  }
  if (records.empty()) {
    throw InputError(source, "datasets", "at least one dataset 58 of function type 1 (time response)",
                     std::to_string(datasets.size()) + " datasets 58, none a time history");
  }
  const Dataset58& first = *records.front();
  UffTimeHistories out;
  out.names = time_history_names(records);
  out.data.resize(static_cast<Index>(first.n), static_cast<Index>(records.size()));
  out.time_scale = first.abscissa_scale;
  if (first.even) {
    out.increment_s = first.abscissa_inc * first.abscissa_scale;
  } else {
    out.t = first.x;
  }
  for (size_t j = 0; j < records.size(); ++j) {
    const Dataset58& d = *records[j];
    const std::string where = "dataset 58 at line " + std::to_string(d.line);
    if (!d.abscissa_time) {
      throw InputError(source, where + " record 8 (abscissa units)", "a time unit (s, ms) for a time history", "unit " + quote(d.abscissa_unit));
    }
    if (d.ord_type == kOrdComplexSingle || d.ord_type == kOrdComplexDouble) {
      throw InputError(source, where + " record 7 (ordinate data type)", "real values (2 or 4) for a time history", std::to_string(d.ord_type));
    }
    if (d.n != first.n || d.even != first.even ||
        (d.even ? std::abs(d.abscissa_inc * d.abscissa_scale - out.increment_s) > 1e-9 * out.increment_s
                : (d.x - first.x).cwiseAbs().maxCoeff() > 0.0)) {
      throw InputError(source, where + " record 7", "the samples of the first time history (" + std::to_string(first.n) + " values, " +
                           (first.even ? "increment " + format_number(out.increment_s, 6) + " s" : std::string("uneven")) + ")",
                       std::to_string(d.n) + " values, " + (d.even ? "increment " + format_number(d.abscissa_inc * d.abscissa_scale, 6) + " s" : std::string("uneven")));
    }
    out.data.col(static_cast<Index>(j)) = d.y.real();
    out.units.push_back(d.ord_unit);
  }
  return out;
}

}  // namespace piezobench::io::detail
