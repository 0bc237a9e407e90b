#include "piezobench/io/frf_file.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdarg>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "csv_table.hpp"
#include "mat_file.hpp"
#include "uff58.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/io/units.hpp"

namespace piezobench::io {
namespace fs = std::filesystem;
using text::quote;
using Eigen::Index;

std::string to_string(FrfFormat f) {
  switch (f) {
    case FrfFormat::kCsv: return "csv";
    case FrfFormat::kMat: return "mat";
    case FrfFormat::kUff58: return "uff58";
  }
  return "csv";
}

FrfFormat frf_format_from_string(const std::string& s) {
  const std::string l = text::to_lower(s);
  if (l == "csv") return FrfFormat::kCsv;
  if (l == "mat") return FrfFormat::kMat;
  if (l == "uff58" || l == "uff" || l == "unv" || l == "uf" || l == "58") return FrfFormat::kUff58;
  throw InputError("", "format", "csv, mat or uff58", quote(s));
}

FrfFormat frf_format_from_path(const fs::path& file) {
  const std::string ext = text::to_lower(file.extension().string());
  if (ext == ".csv") return FrfFormat::kCsv;
  if (ext == ".mat") return FrfFormat::kMat;
  if (ext == ".uff" || ext == ".unv" || ext == ".uf") return FrfFormat::kUff58;
  throw InputError(file.string(), "file", "an FRF file (.csv, .mat, .uff, .unv)", "extension " + quote(ext));
}

void FrfWriteOptions::validate() const {
  if (reference_node < 0 || reference_node > 999999999) {
    throw InputError("FrfWriteOptions", "reference_node", "a node number in [0, 999999999]", std::to_string(reference_node));
  }
  if (date.size() > 80 || date.find_first_of("\r\n") != std::string::npos) {
    throw InputError("FrfWriteOptions", "date", "one line of at most 80 characters", quote(date));
  }
}

void write_frf(const dsp::Frf& frf, const fs::path& file, const FrfWriteOptions& options) {
  switch (frf_format_from_path(file)) {
    case FrfFormat::kCsv: return write_frf_csv(frf, file, options);
    case FrfFormat::kMat: return write_frf_mat(frf, file, options);
    case FrfFormat::kUff58: return write_frf_uff58(frf, file, options);
  }
}

namespace {
detail::StatedFrf stated_frf_csv(const fs::path& file, const FrfReadOptions& options);
detail::StatedFrf stated_frf_mat(const fs::path& file);

// The unit of output i's H: the override (H_NAME, else NAME / input), else what the file states.
std::string frf_unit(const detail::StatedFrf& stated, size_t i, const FrfReadOptions& options) {
  const auto& o = options.unit_overrides;
  const std::string& name = stated.frf.outputs[i];
  if (const auto h = o.find("H_" + name); h != o.end()) return h->second;
  auto in = o.find(stated.frf.input.empty() ? std::string("input") : stated.frf.input);
  if (in == o.end()) in = o.find("input");
  const auto out = o.find(name);
  if (out == o.end() && in == o.end()) return stated.units[i];
  return "(" + (out != o.end() ? out->second : std::string("1")) + ")" + (in != o.end() ? "/(" + in->second + ")" : std::string());
}

// H in SI: each output's unit (frf_unit) parsed by the unit table and applied; warnings for an
// output without a unit and for a file unit an override replaces.
FrfFile to_si(detail::StatedFrf stated, const FrfReadOptions& options, const std::string& source) {
  const dsp::Frf& frf = stated.frf;
  if (stated.units.size() != frf.outputs.size()) stated.units.resize(frf.outputs.size());
  for (const auto& [key, unit] : options.unit_overrides) {
    const bool output = std::find(frf.outputs.begin(), frf.outputs.end(), key) != frf.outputs.end() ||
                        (key.rfind("H_", 0) == 0 && std::find(frf.outputs.begin(), frf.outputs.end(), key.substr(2)) != frf.outputs.end());
    if (!output && key != "input" && key != frf.input) {
      throw InputError(source, "--units " + key, "an output (" + text::join(frf.outputs) + "), H_OUTPUT or the input (" +
                                                    (frf.input.empty() ? std::string("input") : frf.input + " or input") + ")",
                       quote(key) + ", which names no channel of the FRF");
    }
  }
  FrfFile out;
  for (size_t i = 0; i < frf.outputs.size(); ++i) {
    const std::string unit = frf_unit(stated, i, options);
    const std::string& name = frf.outputs[i];
    if (unit != stated.units[i] && !stated.units[i].empty()) {
      out.warnings.push_back(source + ": output " + name + ": unit " + quote(unit) + " from --units replaces " + quote(stated.units[i]) +
                             " in the file");
    }
    if (unit.empty()) {
      out.warnings.push_back(source + ": output " + name + " has no unit: H taken as SI (give it with --units H_" + name + "=UNIT)");
      out.units.emplace_back();
      continue;
    }
    const Unit u = unit_from_string(unit, source, "unit of H_" + name);
    if (u.to_si != 1.0) stated.frf.H[i] *= u.to_si;
    if (u.to_si != 1.0 && i < stated.frf.std_H.size()) stated.frf.std_H[i] *= u.to_si;  // std in H's unit
    out.units.push_back(u.si_symbol.empty() ? "1" : u.si_symbol);
  }
  out.frf = std::move(stated.frf);
  out.frf.validate(source);  // every message names source
  return out;
}
}  // namespace

FrfFile read_frf_file(const fs::path& file, const FrfReadOptions& options) {
  const std::string source = file.string();
  switch (frf_format_from_path(file)) {
    case FrfFormat::kCsv: return to_si(stated_frf_csv(file, options), options, source);
    case FrfFormat::kMat: return to_si(stated_frf_mat(file), options, source);
    case FrfFormat::kUff58: return to_si(detail::read_uff58_frf(file), options, source);
  }
  return {};
}

dsp::Frf read_frf(const fs::path& file, const FrfReadOptions& options) { return read_frf_file(file, options).frf; }
dsp::Frf read_frf_csv(const fs::path& file, const FrfReadOptions& options) { return to_si(stated_frf_csv(file, options), options, file.string()).frf; }
dsp::Frf read_frf_mat(const fs::path& file, const FrfReadOptions& options) { return to_si(stated_frf_mat(file), options, file.string()).frf; }
dsp::Frf read_frf_uff58(const fs::path& file, const FrfReadOptions& options) {
  return to_si(detail::read_uff58_frf(file), options, file.string()).frf;
}

// ---- CSV ------------------------------------------------------------------------------------

namespace {
// The unit of output i's H from the write options ("" when not known).
std::string written_unit(const FrfWriteOptions& options, size_t i) {
  if (i >= options.output_units.size() || (options.output_units[i].empty() && options.input_unit.empty())) return "";
  const Unit out = options.output_units[i].empty() ? Unit{} : unit_from_string(options.output_units[i], "FrfWriteOptions", "output_units");
  const Unit in = options.input_unit.empty() ? Unit{} : unit_from_string(options.input_unit, "FrfWriteOptions", "input_unit");
  const std::string symbol = divide(out, in).symbol;
  return symbol.empty() ? "1" : symbol;
}
}  // namespace

void write_frf_csv(const dsp::Frf& frf, const fs::path& file, const FrfWriteOptions& options) {
  frf.validate(file.string());
  for (const std::string& name : frf.outputs) {
    if (name.find_first_of(",\"\r\n") != std::string::npos || name != text::trim(name)) {
      throw InputError(file.string(), "output " + name, "a name without commas, quotes, line breaks or edge spaces", quote(name));
    }
  }
  const bool coh = !frf.coherence.empty();
  const bool sd = !frf.std_H.empty();
  write_atomically(file, [&](std::ostream& out) {
    std::string line = "freq_Hz";
    for (size_t i = 0; i < frf.outputs.size(); ++i) {
      const std::string& name = frf.outputs[i];
      const std::string unit = written_unit(options, i);
      const std::string suffix = unit.empty() ? std::string() : " [" + unit + "]";
      line += ",re_" + name + suffix + ",im_" + name + suffix;
      if (coh) line += ",coh_" + name;
      if (sd) line += ",std_" + name + suffix;
    }
    out << line << '\n';
    for (Index k = 0; k < frf.freq_Hz.size(); ++k) {
      line = format_number(frf.freq_Hz(k), 17);
      for (size_t i = 0; i < frf.outputs.size(); ++i) {
        line += ',' + format_number(frf.H[i](k).real(), 17);
        line += ',' + format_number(frf.H[i](k).imag(), 17);
        if (coh) line += ',' + format_number(frf.coherence[i](k), 17);
        if (sd) line += ',' + format_number(frf.std_H[i](k), 17);
      }
      out << line << '\n';
      if (!out) return;
    }
  });
}

namespace {
// The factor to Hz of the frequency column: freq_Hz, or freq / f / frequency with a frequency unit.
double csv_frequency_factor(const detail::CsvColumn& column, const std::string& source) {
  const std::string first = text::to_lower(column.name);
  if (first == "freq_hz" && column.unit.empty()) return 1.0;
  if ((first == "freq" || first == "f" || first == "frequency") && !column.unit.empty()) {
    const Unit u = unit_from_string(column.unit, source, "header column 1");
    if (u.quantity != Quantity::kFrequency) throw InputError(source, "header column 1", "a frequency in Hz or kHz", "unit " + quote(column.unit));
    return u.to_si;
  }
  throw InputError(source, "header column 1", "freq_Hz (or freq [Hz], freq [kHz])", quote(column.name));
}

enum class FrfPart { kRe, kIm, kCoh, kStd };

// The part and output a header cell names: re_NAME, im_NAME, coh_NAME or std_NAME.
std::pair<FrfPart, std::string> frf_column_part(const std::string& cell, const std::string& source, const std::string& where) {
  std::pair<FrfPart, std::string> out;
  if (cell.rfind("re_", 0) == 0) {
    out = {FrfPart::kRe, cell.substr(3)};
  } else if (cell.rfind("im_", 0) == 0) {
    out = {FrfPart::kIm, cell.substr(3)};
  } else if (cell.rfind("coh_", 0) == 0) {
    out = {FrfPart::kCoh, cell.substr(4)};
  } else if (cell.rfind("std_", 0) == 0) {
    out = {FrfPart::kStd, cell.substr(4)};
  } else {
    throw InputError(source, where, "re_NAME, im_NAME, coh_NAME or std_NAME", quote(cell));
  }
  if (out.second.empty()) throw InputError(source, where, "a channel name after the prefix", quote(cell));
  return out;
}

// What the header of an FRF CSV says: the outputs in order, the unit stated for each, and the
// column of each output's re, im, coh and std (-1 when absent).
struct FrfCsvHeader {
  std::vector<std::string> outputs;
  std::vector<std::string> stated_units;  // per output, as written
  std::map<std::string, std::array<int, 4>> seen;
  size_t with_coh = 0, with_std = 0;  // outputs with a coherence, a standard deviation
};

FrfCsvHeader read_frf_csv_header(const std::vector<detail::CsvColumn>& columns, const std::string& source) {
  FrfCsvHeader h;
  for (size_t c = 1; c < columns.size(); ++c) {
    const std::string& cell = columns[c].name;
    const std::string where = "header column " + std::to_string(c + 1);
    const auto [part, name] = frf_column_part(cell, source, where);
    auto [it, inserted] = h.seen.try_emplace(name, std::array<int, 4>{-1, -1, -1, -1});
    if (inserted) {
      h.outputs.push_back(name);
      h.stated_units.emplace_back();
    }
    // The unit of H on re_, im_ and std_ (`re_de [um/V]`): the same on all; coherence has none.
    const std::string& unit = columns[c].unit;
    std::string& stated = h.stated_units[static_cast<size_t>(std::find(h.outputs.begin(), h.outputs.end(), name) - h.outputs.begin())];
    if (part == FrfPart::kCoh) {
      if (!unit.empty() && unit != "-" && unit != "1") throw InputError(source, where, "no unit for a coherence (or - or 1)", "unit " + quote(unit));
    } else if (!unit.empty() || !stated.empty()) {
      const bool first_part = h.seen[name][0] < 0 && h.seen[name][1] < 0;
      if (first_part) stated = unit;
      else if (stated != unit) throw InputError(source, where, "the unit of the other part of " + name + " (" + quote(stated) + ")", "unit " + quote(unit));
    }
    int& slot = it->second[static_cast<size_t>(part)];
    if (slot >= 0) throw InputError(source, where, "each column once", quote(cell) + " twice");
    slot = static_cast<int>(c);
  }
  return h;
}

// Every output has re and im; coherence and standard deviation for every output or for none.
void check_frf_csv_parts(FrfCsvHeader& h, const std::string& source) {
  if (h.outputs.empty()) throw InputError(source, "header", "at least one output (re_NAME,im_NAME)", "only freq_Hz");
  for (const std::string& name : h.outputs) {
    const auto& slots = h.seen[name];
    if (slots[3] >= 0) ++h.with_std;
    if (slots[0] < 0) throw InputError(source, "header", "a column re_" + name, "im_" + name + " or coh_" + name + " without it");
    if (slots[1] < 0) throw InputError(source, "header", "a column im_" + name, "re_" + name + " without it");
    if (slots[2] >= 0) ++h.with_coh;
  }
  if (h.with_coh != 0 && h.with_coh != h.outputs.size()) {
    throw InputError(source, "header", "coh_NAME columns for every output or for none",
                     std::to_string(h.with_coh) + " of " + std::to_string(h.outputs.size()));
  }
  if (h.with_std != 0 && h.with_std != h.outputs.size()) {
    throw InputError(source, "header", "std_NAME columns for every output or for none",
                     std::to_string(h.with_std) + " of " + std::to_string(h.outputs.size()));
  }
}

detail::StatedFrf stated_frf_csv(const fs::path& file, const FrfReadOptions& options) {
  const detail::CsvTable table(file, {options.delimiter, options.decimal});
  const std::string& source = table.source();
  const auto& columns = table.columns();

  // Header: the frequency column, then which output and which part each other column holds.
  const double freq_factor = csv_frequency_factor(columns[0], source);
  FrfCsvHeader h = read_frf_csv_header(columns, source);
  check_frf_csv_parts(h, source);
  // Table columns: freq, then re, im, coh, std per output in output order (the absent ones unread).
  const int per_output = 4;
  std::vector<int> target(columns.size(), -1);
  target[0] = 0;
  for (size_t i = 0; i < h.outputs.size(); ++i) {
    const auto& slots = h.seen[h.outputs[i]];
    for (int p = 0; p < per_output; ++p) {
      if (slots[static_cast<size_t>(p)] >= 0) target[static_cast<size_t>(slots[static_cast<size_t>(p)])] = 1 + static_cast<int>(i) * per_output + p;
    }
  }
  const Eigen::MatrixXd data = table.read(target, 1 + static_cast<Index>(h.outputs.size()) * per_output);
  dsp::Frf frf;
  frf.outputs = std::move(h.outputs);
  frf.freq_Hz = data.col(0) * freq_factor;
  for (size_t i = 0; i < frf.outputs.size(); ++i) {
    const Index base = 1 + static_cast<Index>(i) * per_output;
    Eigen::VectorXcd hv(data.rows());
    hv.real() = data.col(base);
    hv.imag() = data.col(base + 1);
    frf.H.push_back(std::move(hv));
    if (h.with_coh != 0) frf.coherence.emplace_back(data.col(base + 2));
    if (h.with_std != 0) frf.std_H.emplace_back(data.col(base + 3));
  }
  frf.provenance.source = source;
  return {std::move(frf), std::move(h.stated_units)};
}
}  // namespace

// ---- MAT ------------------------------------------------------------------------------------

namespace {
constexpr const char* kFreq = "freq_Hz";

std::vector<std::pair<std::string, detail::MatValue>> provenance_fields(const dsp::FrfProvenance& p) {
  std::vector<std::pair<std::string, detail::MatValue>> f;
  f.emplace_back("source", detail::make_text("source", p.source));
  f.emplace_back("estimator", detail::make_text("estimator", p.estimator));
  f.emplace_back("window", detail::make_text("window", p.window));
  f.emplace_back("nfft", detail::make_scalar("nfft", static_cast<double>(p.nfft)));
  f.emplace_back("overlap", detail::make_scalar("overlap", p.overlap));
  f.emplace_back("detrend", detail::make_text("detrend", p.detrend));
  f.emplace_back("averages", detail::make_scalar("averages", static_cast<double>(p.averages)));
  f.emplace_back("sample_rate_Hz", detail::make_scalar("sample_rate_Hz", p.sample_rate));
  f.emplace_back("effective_averages", detail::make_scalar("effective_averages", p.effective_averages));
  return f;
}
}  // namespace

void write_frf_mat(const dsp::Frf& frf, const fs::path& file, const FrfWriteOptions& options) {
  options.validate();
  frf.validate(file.string());
  for (const std::string& name : frf.outputs) {
    if (!detail::is_matlab_identifier("H_" + name)) {
      throw InputError(file.string(), "output " + name, "a MATLAB name (letter, then letters, digits, _; <= 61)", quote(name));
    }
  }
  detail::write_mat_atomically(file, options.mat_version == MatVersion::kV73, /*compress=*/false, [&](detail::MatWriter& w) {
    w.write(detail::make_real_column(kFreq, frf.freq_Hz));
    w.write(detail::make_text("input", frf.input));
    w.write(detail::make_text("outputs", text::join(frf.outputs, ",")));
    for (size_t i = 0; i < frf.outputs.size(); ++i) {
      w.write(detail::make_complex_column("H_" + frf.outputs[i], frf.H[i]));
      if (!frf.coherence.empty()) w.write(detail::make_real_column("coh_" + frf.outputs[i], frf.coherence[i]));
      if (!frf.std_H.empty()) w.write(detail::make_real_column("std_" + frf.outputs[i], frf.std_H[i]));
    }
    w.write(detail::make_struct("provenance", provenance_fields(frf.provenance)));
    std::vector<std::pair<std::string, detail::MatValue>> units;
    for (size_t i = 0; i < frf.outputs.size(); ++i) {
      const std::string unit = written_unit(options, i);
      if (!unit.empty()) units.emplace_back("H_" + frf.outputs[i], detail::make_text("H_" + frf.outputs[i], unit));
    }
    if (!units.empty()) w.write(detail::make_struct("units", std::move(units)));
  });
}

namespace {
// An FRF MAT file open for reading, with its variables.
struct FrfMatSource {
  const fs::path& file;
  std::string source;
  detail::MatFilePtr mat;
  std::vector<detail::MatVarInfo> vars;
  std::vector<std::string> names;  // of the variables

  [[nodiscard]] bool has(const std::string& n) const { return std::find(names.begin(), names.end(), n) != names.end(); }
  [[nodiscard]] detail::MatValue read(const std::string& n) const { return detail::read_mat_variable(mat.get(), file, n); }
};

// The outputs: the `outputs` list, else every H_NAME variable.
std::vector<std::string> frf_mat_outputs(const FrfMatSource& m) {
  std::vector<std::string> outputs;
  if (m.has("outputs")) {
    const std::string list = detail::to_text(m.read("outputs"), m.source, "outputs");
    for (std::string_view part : text::split(list, ',')) {
      if (!text::trim(part).empty()) outputs.emplace_back(text::trim(part));
    }
  } else {
    for (const std::string& n : m.names) {
      if (n.rfind("H_", 0) == 0 && n.size() > 2) outputs.push_back(n.substr(2));
    }
  }
  if (outputs.empty()) throw InputError(m.source, "H_<name>", "at least one FRF variable", "none (variables: " + text::join(m.names) + ")");
  return outputs;
}

// H of every output, and its coherence and standard deviation (for every output or for none).
void read_frf_mat_responses(const FrfMatSource& m, dsp::Frf& frf) {
  size_t with_coh = 0, with_std = 0;
  for (const std::string& o : frf.outputs) {
    if (m.has("std_" + o)) ++with_std;
    const std::string hname = "H_" + o;
    if (!m.has(hname)) throw InputError(m.source, hname, "the FRF of output " + o + " (listed in outputs)", "no such variable");
    frf.H.push_back(detail::to_complex_vector(m.read(hname), m.source, hname));
    if (m.has("coh_" + o)) ++with_coh;
  }
  if (with_coh != 0 && with_coh != frf.outputs.size()) {
    throw InputError(m.source, "coh_<name>", "coherence for every output or for none",
                     std::to_string(with_coh) + " of " + std::to_string(frf.outputs.size()));
  }
  if (with_coh != 0) {
    for (const std::string& o : frf.outputs) frf.coherence.push_back(detail::to_real_vector(m.read("coh_" + o), m.source, "coh_" + o));
  }
  if (with_std != 0 && with_std != frf.outputs.size()) {
    throw InputError(m.source, "std_<name>", "a standard deviation for every output or for none",
                     std::to_string(with_std) + " of " + std::to_string(frf.outputs.size()));
  }
  for (size_t i = 0; i < frf.outputs.size() && with_std != 0; ++i) {
    frf.std_H.push_back(detail::to_real_vector(m.read("std_" + frf.outputs[i]), m.source, "std_" + frf.outputs[i]));
  }
}

// The `provenance` struct's fields (a 1x1 struct; anything else is ignored).
void read_frf_mat_provenance(const detail::MatValue& p, const std::string& source, dsp::FrfProvenance& out) {
  if (p.class_type != MAT_C_STRUCT || p.count() != 1) return;
  const auto text = [&](const char* field) {
    const detail::MatValue* f = p.field(field);
    return f != nullptr ? detail::to_text(*f, source, std::string("provenance.") + field) : std::string();
  };
  const auto number = [&](const char* field) {
    const detail::MatValue* f = p.field(field);
    if (f == nullptr) return 0.0;
    const Eigen::VectorXd v = detail::to_real_vector(*f, source, std::string("provenance.") + field);
    if (v.size() != 1 || !std::isfinite(v(0))) {
      throw InputError(source, std::string("provenance.") + field, "a finite scalar", detail::describe(*f));
    }
    return v(0);
  };
  out.source = text("source");
  out.estimator = text("estimator");
  out.window = text("window");
  out.detrend = text("detrend");
  out.nfft = static_cast<Index>(number("nfft"));
  out.overlap = number("overlap");
  out.averages = static_cast<Index>(number("averages"));
  out.sample_rate = number("sample_rate_Hz");
  out.effective_averages = number("effective_averages");
}

// Units of H: a `units` struct (field H_NAME or NAME, e.g. 'um/V'), else (v7.3) the `units`
// attribute of the H_NAME dataset. A field naming no output is an InputError.
std::vector<std::string> frf_mat_units(const FrfMatSource& m, const std::vector<std::string>& outputs) {
  std::vector<std::string> units(outputs.size());
  for (size_t i = 0; i < outputs.size(); ++i) {
    const auto info = std::find_if(m.vars.begin(), m.vars.end(), [&](const auto& v) { return v.name == "H_" + outputs[i]; });
    if (info != m.vars.end()) units[i] = info->unit;
  }
  const auto units_var = std::find_if(m.vars.begin(), m.vars.end(), [](const auto& v) { return text::to_lower(v.name) == "units"; });
  if (units_var == m.vars.end()) return units;
  const detail::MatValue u = m.read(units_var->name);
  if (u.class_type != MAT_C_STRUCT || u.count() != 1) throw InputError(m.source, units_var->name, "a 1x1 struct of units (H_NAME = 'um/V')", detail::describe(u));
  for (const std::string& f : u.field_names) {
    const std::string where = units_var->name + "." + f;
    const std::string name = f.rfind("H_", 0) == 0 ? f.substr(2) : f;
    const auto it = std::find(outputs.begin(), outputs.end(), name);
    if (it == outputs.end()) {
      if (f == kFreq || f == "freq" || f.rfind("coh_", 0) == 0) continue;
      throw InputError(m.source, where, "the unit of an output (H_" + text::join(outputs, ", H_") + ")", quote(f) + ", which names no output");
    }
    const std::string unit(text::trim(detail::to_text(*u.field(f), m.source, where)));
    std::string& slot = units[static_cast<size_t>(it - outputs.begin())];
    if (!slot.empty() && slot != unit) throw InputError(m.source, where, "the unit the H_" + name + " attribute gives (" + slot + ")", quote(unit));
    slot = unit;
  }
  return units;
}

detail::StatedFrf stated_frf_mat(const fs::path& file) {
  FrfMatSource m{file, file.string(), detail::open_mat_for_reading(file), {}, {}};
  m.vars = detail::list_mat_variables(m.mat.get(), file);
  for (const auto& v : m.vars) m.names.push_back(v.name);
  if (!m.has(kFreq)) {
    throw InputError(m.source, kFreq, "a frequency vector in Hz", "no such variable (variables: " + text::join(m.names) + ")");
  }
  dsp::Frf frf;
  frf.freq_Hz = detail::to_real_vector(m.read(kFreq), m.source, kFreq);
  if (m.has("input")) frf.input = detail::to_text(m.read("input"), m.source, "input");
  frf.outputs = frf_mat_outputs(m);
  read_frf_mat_responses(m, frf);
  if (m.has("provenance")) read_frf_mat_provenance(m.read("provenance"), m.source, frf.provenance);
  if (frf.provenance.source.empty()) frf.provenance.source = m.source;
  std::vector<std::string> units = frf_mat_units(m, frf.outputs);
  return {std::move(frf), std::move(units)};
}
}  // namespace

}  // namespace piezobench::io
