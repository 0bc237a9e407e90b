#include "piezobench/io/lti_toml.hpp"

#include <fmt/format.h>

#include <fstream>
#include <initializer_list>
#include <optional>
#include <set>
#include <sstream>
#include <toml++/toml.h>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/io/toml_describe.hpp"
#include "piezobench/io/toml_reader.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::io {

namespace {

std::string at_index(std::string_view k, std::size_t i) { return std::string(k) + "[" + std::to_string(i) + "]"; }

// The array at key k (`node`), bounded before any n x n matrix is built (a 100,000-coefficient
// denominator ran out of memory in the conversion to a state space).
const toml::array& bounded_array(const TomlReader& r, std::string_view k, const toml::node& node) {
  const toml::array* a = node.as_array();
  if (a == nullptr) r.fail(k, "an array", describe_toml(node), &node);
  if (a->size() > kMaxLtiOrder + 1) {
    r.fail(k, "at most " + std::to_string(kMaxLtiOrder + 1) + " entries (systems of order <= " + std::to_string(kMaxLtiOrder) + ")",
           std::to_string(a->size()) + " entries", &node);
  }
  return *a;
}

lti::Vector read_vector(const TomlReader& r, const char* k) {
  const toml::array& a = bounded_array(r, k, *r.get(k));
  if (a.empty()) r.fail(k, "a non-empty array of numbers", "an empty array");
  lti::Vector v(static_cast<lti::Index>(a.size()));
  for (std::size_t i = 0; i < a.size(); ++i) v(static_cast<lti::Index>(i)) = r.number_at(a[i], at_index(k, i));
  return v;
}

// A list of real numbers or [re, im] pairs; may be empty.
lti::CVector read_complex_vector(const TomlReader& r, const char* k) {
  const toml::array& a = bounded_array(r, k, *r.get(k));
  lti::CVector v(static_cast<lti::Index>(a.size()));
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string ki = at_index(k, i);
    if (const toml::array* pair = a[i].as_array()) {
      if (pair->size() != 2) r.fail(ki, "a number or a pair [re, im]", describe_toml(a[i]), &a[i]);
      v(static_cast<lti::Index>(i)) = lti::Complex(r.number_at((*pair)[0], at_index(ki, 0)), r.number_at((*pair)[1], at_index(ki, 1)));
    } else {
      v(static_cast<lti::Index>(i)) = r.number_at(a[i], ki);
    }
  }
  return v;
}

// A matrix as a list of rows of equal length; an empty list is a matrix with no rows.
lti::Matrix read_matrix(const TomlReader& r, const char* k, lti::Index cols_if_empty) {
  const toml::array& rows = bounded_array(r, k, *r.get(k));
  if (rows.empty()) return lti::Matrix(0, cols_if_empty);
  std::vector<std::vector<double>> values;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string ki = at_index(k, i);
    const toml::array& row = bounded_array(r, ki, rows[i]);
    std::vector<double> v;
    for (std::size_t j = 0; j < row.size(); ++j) v.push_back(r.number_at(row[j], at_index(ki, j)));
    if (!values.empty() && v.size() != values.front().size()) {
      r.fail(ki, "a row of " + std::to_string(values.front().size()) + " numbers", std::to_string(v.size()) + " numbers", &rows[i]);
    }
    values.push_back(std::move(v));
  }
  lti::Matrix m(static_cast<lti::Index>(values.size()), static_cast<lti::Index>(values.front().size()));
  for (std::size_t i = 0; i < values.size(); ++i) {
    for (std::size_t j = 0; j < values[i].size(); ++j) m(static_cast<lti::Index>(i), static_cast<lti::Index>(j)) = values[i][j];
  }
  return m;
}

// One of the three forms, checked by lti's validate().
lti::StateSpace read_system(const TomlReader& r, LtiForm form, double ts, double delay) {
  const std::string& source = r.file();
  const auto require = [&](std::initializer_list<const char*> keys) {
    for (const char* k : keys) {
      if (!r.has(k)) r.fail(k, "a value (this form requires the key)", "nothing (the key is required)");
    }
  };
  if (form == LtiForm::kTransferFunction) {
    require({"num", "den"});
    const lti::TransferFunction h(read_vector(r, "num"), read_vector(r, "den"), ts, delay);
    h.validate(source);
    return lti::to_state_space(h);
  }
  if (form == LtiForm::kZpk) {
    require({"zeros", "poles", "gain"});
    const lti::Zpk h(read_complex_vector(r, "zeros"), read_complex_vector(r, "poles"), r.required_number("gain"), ts, delay);
    h.validate(source);
    return lti::to_state_space(h);
  }
  require({"A", "B", "C"});
  lti::Matrix a = read_matrix(r, "A", 0);
  lti::Matrix b = read_matrix(r, "B", 0);
  lti::Matrix c = read_matrix(r, "C", a.cols());
  lti::Matrix d = r.has("D") ? read_matrix(r, "D", b.cols()) : lti::Matrix::Zero(c.rows(), b.cols());
  if (a.rows() == 0 && b.rows() == 0) b.resize(0, d.cols());
  lti::StateSpace sys(a, b, c, d, ts);
  if (delay > 0.0) sys.input_delay = lti::Vector::Constant(sys.inputs(), delay);
  sys.validate(source);
  return sys;
}

LtiFile build(const toml::table& table, const std::string& source) {
  const TomlReader r(table, source);
  r.only({"num", "den", "zeros", "poles", "gain", "A", "B", "C", "D", "delay", "sample_time", "description"});
  const bool tf = r.has("num") || r.has("den");
  const bool zpk = r.has("zeros") || r.has("poles") || r.has("gain");
  const bool ss = r.has("A") || r.has("B") || r.has("C") || r.has("D");
  if (int(tf) + int(zpk) + int(ss) != 1) {
    throw InputError(source, "form", "exactly one of a transfer function (num, den), a zpk (zeros, poles, gain) "
                     "or a state space (A, B, C, D)", tf + zpk + ss == 0 ? std::string("none") : std::string("a mix"));
  }
  const double ts = r.number("sample_time").value_or(0.0);
  const double delay = r.number("delay").value_or(0.0);
  if (ts < 0.0) r.fail("sample_time", "a sample time >= 0 s", format_number_exact(ts));
  if (delay < 0.0) r.fail("delay", "a delay >= 0 s", format_number_exact(delay));
  LtiFile out;
  out.description = r.string("description").value_or("");
  out.form = tf ? LtiForm::kTransferFunction : zpk ? LtiForm::kZpk : LtiForm::kStateSpace;
  try {
    out.system = read_system(r, out.form, ts, delay);
  } catch (const InputError& e) {
    if (e.source().empty()) throw e.with_source(source);
    throw;
  }
  return out;
}

}  // namespace

std::string to_string(LtiForm form) {
  switch (form) {
    case LtiForm::kTransferFunction: return "tf";
    case LtiForm::kZpk: return "zpk";
    case LtiForm::kStateSpace: return "ss";
  }
  return "ss";
}

LtiFile parse_lti_toml(const std::string& text, const std::string& source) {
  return build(parse_toml(text, source), source);
}

LtiFile read_lti_toml(const std::filesystem::path& path) {
  return build(read_toml_file(path), path.string());
}

namespace {

// A TOML basic string: quotes, backslashes and control characters escaped.
std::string toml_quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

std::string to_lti_toml(const lti::TransferFunction& tf, const std::string& description) {
  auto list = [](const lti::Vector& v) {
    std::string out = "[";
    for (lti::Index i = 0; i < v.size(); ++i) out += (i == 0 ? "" : ", ") + fmt::format("{:.17g}", v(i));
    return out + "]";
  };
  std::string text;
  if (!description.empty()) text += "description = " + toml_quoted(description) + "\n";
  text += "num = " + list(tf.num) + "\n";
  text += "den = " + list(tf.den) + "\n";
  if (tf.delay > 0.0) text += fmt::format("delay = {:.17g}\n", tf.delay);
  if (tf.sample_time > 0.0) text += fmt::format("sample_time = {:.17g}\n", tf.sample_time);
  return text;
}

void write_lti_toml(const lti::TransferFunction& tf, const std::filesystem::path& path, const std::string& description) {
  write_text_atomically(path, to_lti_toml(tf, description));
}

}  // namespace piezobench::io
