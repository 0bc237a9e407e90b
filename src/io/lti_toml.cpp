#include "piezobench/io/lti_toml.hpp"

#include <fmt/format.h>

#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <toml++/toml.h>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::io {

namespace {

class Reader {
 public:
  Reader(const toml::table& table, std::string source) : table_(table), source_(std::move(source)) {}

  [[nodiscard]] bool has(const char* key) const { return table_.contains(key); }

  [[nodiscard]] double number(const std::string& key, const toml::node& node) const {
    const auto value = toml_number(node);
    if (!value) throw InputError(source_, key, "a number", describe_toml(node));
    if (!std::isfinite(*value)) throw InputError(source_, key, "a finite number", std::to_string(*value));
    return *value;
  }

  [[nodiscard]] double number(const char* key) const { return number(key, *table_.get(key)); }

  [[nodiscard]] const toml::array& array(const std::string& key, const toml::node& node) const {
    const toml::array* a = node.as_array();
    if (a == nullptr) throw InputError(source_, key, "an array", describe_toml(node));
    // Bounds the order before any n x n matrix is built (a 100,000-coefficient denominator ran out
    // of memory in the conversion to a state space).
    if (a->size() > kMaxLtiOrder + 1) {
      throw InputError(source_, key, "at most " + std::to_string(kMaxLtiOrder + 1) + " entries (systems of order <= " +
                       std::to_string(kMaxLtiOrder) + ")", std::to_string(a->size()) + " entries");
    }
    return *a;
  }

  [[nodiscard]] lti::Vector vector(const char* key) const {
    const toml::array& a = array(key, *table_.get(key));
    if (a.empty()) throw InputError(source_, key, "a non-empty array of numbers", "an empty array");
    lti::Vector v(static_cast<lti::Index>(a.size()));
    for (std::size_t i = 0; i < a.size(); ++i) v(static_cast<lti::Index>(i)) = number(key_at(key, i), a[i]);
    return v;
  }

  // A list of real numbers or [re, im] pairs; may be empty.
  [[nodiscard]] lti::CVector complex_vector(const char* key) const {
    const toml::array& a = array(key, *table_.get(key));
    lti::CVector v(static_cast<lti::Index>(a.size()));
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string k = key_at(key, i);
      if (a[i].is_array()) {
        const toml::array& pair = *a[i].as_array();
        if (pair.size() != 2) throw InputError(source_, k, "a number or a pair [re, im]", describe_toml(a[i]));
        v(static_cast<lti::Index>(i)) = lti::Complex(number(k + "[0]", pair[0]), number(k + "[1]", pair[1]));
      } else {
        v(static_cast<lti::Index>(i)) = number(k, a[i]);
      }
    }
    return v;
  }

  // A matrix as a list of rows of equal length; an empty list is a matrix with no rows.
  [[nodiscard]] lti::Matrix matrix(const char* key, lti::Index cols_if_empty) const {
    const toml::array& rows = array(key, *table_.get(key));
    if (rows.empty()) return lti::Matrix(0, cols_if_empty);
    std::vector<std::vector<double>> values;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const toml::array& row = array(key_at(key, i), rows[i]);
      std::vector<double> r;
      for (std::size_t j = 0; j < row.size(); ++j) r.push_back(number(key_at(key_at(key, i), j), row[j]));
      if (!values.empty() && r.size() != values.front().size()) {
        throw InputError(source_, key_at(key, i), "a row of " + std::to_string(values.front().size()) + " numbers",
                         std::to_string(r.size()) + " numbers");
      }
      values.push_back(std::move(r));
    }
    lti::Matrix m(static_cast<lti::Index>(values.size()), static_cast<lti::Index>(values.front().size()));
    for (std::size_t i = 0; i < values.size(); ++i) {
      for (std::size_t j = 0; j < values[i].size(); ++j) m(static_cast<lti::Index>(i), static_cast<lti::Index>(j)) = values[i][j];
    }
    return m;
  }

  [[nodiscard]] const std::string& source() const { return source_; }

 private:
  static std::string key_at(const std::string& key, std::size_t i) { return key + "[" + std::to_string(i) + "]"; }

  const toml::table& table_;
  std::string source_;
};

const std::set<std::string>& known_keys() {
  static const std::set<std::string> keys = {"num", "den", "zeros", "poles", "gain", "A", "B", "C", "D",
                                             "delay", "sample_time", "description"};
  return keys;
}

LtiFile build(const toml::table& table, const std::string& source) {
  for (const auto& [key, node] : table) {
    if (known_keys().count(std::string(key.str())) == 0) {
      throw InputError(source, std::string(key.str()),
                       "one of num, den, zeros, poles, gain, A, B, C, D, delay, sample_time, description",
                       "an unknown key");
    }
  }
  const Reader r(table, source);
  const bool tf = r.has("num") || r.has("den");
  const bool zpk = r.has("zeros") || r.has("poles") || r.has("gain");
  const bool ss = r.has("A") || r.has("B") || r.has("C") || r.has("D");
  if (int(tf) + int(zpk) + int(ss) != 1) {
    throw InputError(source, "form", "exactly one of a transfer function (num, den), a zpk (zeros, poles, gain) "
                     "or a state space (A, B, C, D)", tf + zpk + ss == 0 ? std::string("none") : std::string("a mix"));
  }
  const double ts = r.has("sample_time") ? r.number("sample_time") : 0.0;
  const double delay = r.has("delay") ? r.number("delay") : 0.0;
  if (ts < 0.0) throw InputError(source, "sample_time", "a sample time >= 0 s", std::to_string(ts));
  if (delay < 0.0) throw InputError(source, "delay", "a delay >= 0 s", std::to_string(delay));

  LtiFile out;
  if (const auto* d = table.get("description")) {
    const auto text = d->value<std::string>();
    if (!text) throw InputError(source, "description", "a string", describe_toml(*d));
    out.description = *text;
  }
  auto require = [&](const char* key) {
    if (!r.has(key)) throw InputError(source, key, "a value (this form requires the key)", "no such key");
  };
  try {
    if (tf) {
      require("num");
      require("den");
      out.form = LtiForm::kTransferFunction;
      const lti::TransferFunction h(r.vector("num"), r.vector("den"), ts, delay);
      h.validate(source);
      out.system = lti::to_state_space(h);
    } else if (zpk) {
      require("zeros");
      require("poles");
      require("gain");
      out.form = LtiForm::kZpk;
      const lti::Zpk h(r.complex_vector("zeros"), r.complex_vector("poles"), r.number("gain"), ts, delay);
      h.validate(source);
      out.system = lti::to_state_space(h);
    } else {
      require("A");
      require("B");
      require("C");
      out.form = LtiForm::kStateSpace;
      lti::Matrix a = r.matrix("A", 0);
      lti::Matrix b = r.matrix("B", 0);
      lti::Matrix c = r.matrix("C", a.cols());
      lti::Matrix d = r.has("D") ? r.matrix("D", b.cols()) : lti::Matrix::Zero(c.rows(), b.cols());
      if (a.rows() == 0 && b.rows() == 0) b.resize(0, d.cols());
      out.system = lti::StateSpace(a, b, c, d, ts);
      if (delay > 0.0) out.system.input_delay = lti::Vector::Constant(out.system.inputs(), delay);
      out.system.validate(source);
    }
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
