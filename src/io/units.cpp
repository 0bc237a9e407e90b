#include "piezobench/io/units.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"

namespace piezobench::io {

namespace {

struct Entry {
  const char* symbol;
  Quantity quantity;
  double to_si;
  const char* si;
  bool listed;  // shown in known_units() (aliases are not)
};

// The one unit table (see units.hpp). Micro: ASCII "u", the micro sign U+00B5 and the Greek
// letter mu U+03BC, as spreadsheets and DAQ software write all three.
constexpr std::array kUnitTable = {
    Entry{"nm", Quantity::kLength, 1e-9, "m", true},
    Entry{"um", Quantity::kLength, 1e-6, "m", true},
    Entry{"\xC2\xB5m", Quantity::kLength, 1e-6, "m", false},
    Entry{"\xCE\xBCm", Quantity::kLength, 1e-6, "m", false},
    Entry{"mm", Quantity::kLength, 1e-3, "m", true},
    Entry{"cm", Quantity::kLength, 1e-2, "m", true},
    Entry{"m", Quantity::kLength, 1.0, "m", true},
    Entry{"us", Quantity::kTime, 1e-6, "s", true},
    Entry{"\xC2\xB5s", Quantity::kTime, 1e-6, "s", false},
    Entry{"\xCE\xBCs", Quantity::kTime, 1e-6, "s", false},
    Entry{"ms", Quantity::kTime, 1e-3, "s", true},
    Entry{"s", Quantity::kTime, 1.0, "s", true},
    Entry{"sec", Quantity::kTime, 1.0, "s", false},
    Entry{"min", Quantity::kTime, 60.0, "s", true},
    Entry{"uV", Quantity::kVoltage, 1e-6, "V", true},
    Entry{"\xC2\xB5V", Quantity::kVoltage, 1e-6, "V", false},
    Entry{"\xCE\xBCV", Quantity::kVoltage, 1e-6, "V", false},
    Entry{"mV", Quantity::kVoltage, 1e-3, "V", true},
    Entry{"V", Quantity::kVoltage, 1.0, "V", true},
    Entry{"kV", Quantity::kVoltage, 1e3, "V", true},
    Entry{"mN", Quantity::kForce, 1e-3, "N", true},
    Entry{"N", Quantity::kForce, 1.0, "N", true},
    Entry{"kN", Quantity::kForce, 1e3, "N", true},
    Entry{"Hz", Quantity::kFrequency, 1.0, "Hz", true},
    Entry{"hz", Quantity::kFrequency, 1.0, "Hz", false},
    Entry{"kHz", Quantity::kFrequency, 1e3, "Hz", true},
    Entry{"pF", Quantity::kCapacitance, 1e-12, "F", true},
    Entry{"nF", Quantity::kCapacitance, 1e-9, "F", true},
    Entry{"uF", Quantity::kCapacitance, 1e-6, "F", true},
    Entry{"\xC2\xB5"
          "F",
          Quantity::kCapacitance, 1e-6, "F", false},
    Entry{"\xCE\xBC"
          "F",
          Quantity::kCapacitance, 1e-6, "F", false},
    Entry{"F", Quantity::kCapacitance, 1.0, "F", true},
    Entry{"uA", Quantity::kCurrent, 1e-6, "A", true},
    Entry{"\xC2\xB5"
          "A",
          Quantity::kCurrent, 1e-6, "A", false},
    Entry{"\xCE\xBC"
          "A",
          Quantity::kCurrent, 1e-6, "A", false},
    Entry{"mA", Quantity::kCurrent, 1e-3, "A", true},
    Entry{"A", Quantity::kCurrent, 1.0, "A", true},
    Entry{"g", Quantity::kMass, 1e-3, "kg", true},
    Entry{"kg", Quantity::kMass, 1.0, "kg", true},
    Entry{"um/s", Quantity::kVelocity, 1e-6, "m/s", true},
    Entry{"mm/s", Quantity::kVelocity, 1e-3, "m/s", true},
    Entry{"m/s", Quantity::kVelocity, 1.0, "m/s", true},
    Entry{"m/s^2", Quantity::kAcceleration, 1.0, "m/s^2", true},
    Entry{"m/s2", Quantity::kAcceleration, 1.0, "m/s^2", false},
    Entry{"m/s\xC2\xB2", Quantity::kAcceleration, 1.0, "m/s^2", false},
    Entry{"Pa", Quantity::kPressure, 1.0, "Pa", true},
    Entry{"kPa", Quantity::kPressure, 1e3, "Pa", true},
    Entry{"MPa", Quantity::kPressure, 1e6, "Pa", true},
    Entry{"mbar", Quantity::kPressure, 1e2, "Pa", true},
    Entry{"bar", Quantity::kPressure, 1e5, "Pa", true},
    Entry{"-", Quantity::kDimensionless, 1.0, "", true},
    Entry{"1", Quantity::kDimensionless, 1.0, "", true},
};

// The dimension of each SI symbol of the table (exponents of m, kg, s, A).
Dimension dimension_of_si(std::string_view si) {
  if (si == "m") return {1, 0, 0, 0};
  if (si == "s") return {0, 0, 1, 0};
  if (si == "V") return {2, 1, -3, -1};
  if (si == "N") return {1, 1, -2, 0};
  if (si == "Hz") return {0, 0, -1, 0};
  if (si == "F") return {-2, -1, 4, 2};
  if (si == "A") return {0, 0, 0, 1};
  if (si == "kg") return {0, 1, 0, 0};
  if (si == "m/s") return {1, 0, -1, 0};
  if (si == "m/s^2") return {1, 0, -2, 0};
  if (si == "Pa") return {-1, 1, -2, 0};
  return {0, 0, 0, 0};
}

Unit from_entry(const Entry& e) { return Unit{e.symbol, e.quantity, e.to_si, e.si, dimension_of_si(e.si)}; }

std::optional<Unit> table_unit(std::string_view symbol) {
  for (const Entry& e : kUnitTable) {
    if (symbol == e.symbol) return from_entry(e);
  }
  return std::nullopt;
}

// The quantity of the table with this dimension (kCompound when none; frequency before 1/s).
Quantity quantity_of(const Dimension& d) {
  for (const Entry& e : kUnitTable) {
    if (dimension_of_si(e.si) == d && e.quantity != Quantity::kDimensionless) return e.quantity;
  }
  return d == Dimension{} ? Quantity::kDimensionless : Quantity::kCompound;
}

// A compound unit as the product of SI symbols with exponents, in order of appearance.
struct Product {
  double factor = 1.0;
  std::vector<std::pair<std::string, int>> powers;  // SI symbol, exponent
  bool valid = true;                                // false: a power beyond +-12 somewhere (no unit has one)

  void multiply(const Product& other, int exponent) {
    valid = valid && other.valid;
    factor *= std::pow(other.factor, exponent);
    for (const auto& power : other.powers) {
      const std::string& symbol = power.first;
      const int e = power.second;
      const int add = std::clamp(e, -12, 12) * exponent;  // |e| <= 12 and |exponent| <= 9: no overflow
      valid = valid && std::abs(e) <= 12 && std::abs(add) <= 12;
      const auto it = std::find_if(powers.begin(), powers.end(), [&](const auto& p) { return p.first == symbol; });
      if (it == powers.end()) {
        powers.emplace_back(symbol, add);
      } else {
        it->second = std::clamp(it->second, -12, 12) + add;
        valid = valid && std::abs(it->second) <= 12;
      }
    }
  }
};

// Recursive descent over `expr := power (('*' | '.' | '/') power)*`, `power := atom ('^' int)?`,
// `atom := '(' expr ')' | '1' | a symbol of the table without '/'`; nullopt when the text is not one.
class CompoundParser {
 public:
  explicit CompoundParser(std::string_view text) : s_(text) {}

  std::optional<Product> parse() {
    std::optional<Product> p = expr();
    if (!p || pos_ != s_.size()) return std::nullopt;
    return p;
  }

 private:
  void blanks() {
    while (pos_ < s_.size() && s_[pos_] == ' ') ++pos_;
  }

  std::optional<Product> expr() {
    std::optional<Product> out = power();
    if (!out) return std::nullopt;
    for (blanks(); pos_ < s_.size() && (s_[pos_] == '*' || s_[pos_] == '.' || s_[pos_] == '/'); blanks()) {
      const bool divide = s_[pos_++] == '/';
      const std::optional<Product> next = power();
      if (!next) return std::nullopt;
      out->multiply(*next, divide ? -1 : 1);
    }
    return out;
  }

  std::optional<int> exponent() {
    if (s_.substr(pos_, 2) == "\xC2\xB2") return pos_ += 2, 2;  // superscript two
    if (s_.substr(pos_, 2) == "\xC2\xB3") return pos_ += 2, 3;  // superscript three
    if (pos_ >= s_.size() || s_[pos_] != '^') return 1;
    size_t end = ++pos_;
    if (end < s_.size() && s_[end] == '-') ++end;
    while (end < s_.size() && std::isdigit(static_cast<unsigned char>(s_[end]))) ++end;
    const std::optional<long long> e = text::parse_int(s_.substr(pos_, end - pos_));
    if (!e || *e < -9 || *e > 9) return std::nullopt;
    pos_ = end;
    return static_cast<int>(*e);
  }

  std::optional<Product> power() {
    blanks();
    Product base;
    if (pos_ < s_.size() && s_[pos_] == '(') {
      ++pos_;
      std::optional<Product> inner = expr();
      blanks();
      if (!inner || pos_ >= s_.size() || s_[pos_] != ')') return std::nullopt;
      ++pos_;
      base = *inner;
    } else {
      size_t end = pos_;
      while (end < s_.size() && std::string_view("*./()^ ").find(s_[end]) == std::string_view::npos &&
             s_.substr(end, 2) != "\xC2\xB2" && s_.substr(end, 2) != "\xC2\xB3") {
        ++end;
      }
      std::string_view atom = s_.substr(pos_, end - pos_);
      int trailing = 1;  // "s2" for s^2, as in m/s2
      std::optional<Unit> u = atom.empty() ? std::nullopt : table_unit(atom);
      if (!u && atom.size() > 1 && (atom.back() == '2' || atom.back() == '3')) {
        trailing = atom.back() - '0';
        u = table_unit(atom.substr(0, atom.size() - 1));
      }
      if (atom == "1") u.reset();
      else if (!u || u->si_symbol.find('/') != std::string::npos) return std::nullopt;
      pos_ = end;
      if (u) {
        base.factor = u->to_si;
        if (!u->si_symbol.empty()) base.powers.emplace_back(u->si_symbol, 1);
        if (trailing != 1) {
          Product p;
          p.multiply(base, trailing);
          base = p;
        }
      }
    }
    const std::optional<int> e = exponent();
    if (!e) return std::nullopt;
    Product out;
    out.multiply(base, *e);
    return out;
  }

  std::string_view s_;
  size_t pos_ = 0;
};

// A compound that is a quantity of the table takes the table's SI symbol (N/mm^2 is Pa, V/V is "").
void canonical_symbol(Unit& u) {
  if (u.quantity == Quantity::kCompound) return;
  for (const Entry& e : kUnitTable) {
    if (e.listed && e.to_si == 1.0 && dimension_of_si(e.si) == u.dimension && e.quantity == u.quantity) {
      u.si_symbol = e.si;
      return;
    }
  }
}

std::string power_text(const std::string& symbol, int e) { return e == 1 ? symbol : symbol + "^" + std::to_string(e); }

Unit unit_of_product(std::string_view text, const Product& p) {
  Unit u;
  u.symbol = std::string(text);
  u.to_si = p.factor;
  std::string num, den;
  for (const auto& [symbol, e] : p.powers) {
    if (e == 0) continue;
    const Dimension d = dimension_of_si(symbol);
    for (size_t i = 0; i < d.size(); ++i) u.dimension[i] += d[i] * e;
    if (e > 0) num += (num.empty() ? "" : "*") + power_text(symbol, e);
    else den += "/" + power_text(symbol, -e);
  }
  u.si_symbol = num.empty() && den.empty() ? std::string() : (num.empty() ? "1" : num) + den;
  u.quantity = quantity_of(u.dimension);
  canonical_symbol(u);
  return u;
}

}  // namespace

Unit divide(const Unit& numerator, const Unit& denominator) {
  Unit u;
  u.symbol = denominator.symbol.empty() ? numerator.symbol : (numerator.symbol.empty() ? "1" : numerator.symbol) + "/" + denominator.symbol;
  u.to_si = numerator.to_si / denominator.to_si;
  for (size_t i = 0; i < u.dimension.size(); ++i) u.dimension[i] = numerator.dimension[i] - denominator.dimension[i];
  const auto wrap = [](const std::string& s) { return s.find_first_of("/*") == std::string::npos ? s : "(" + s + ")"; };
  u.si_symbol = denominator.si_symbol.empty() ? numerator.si_symbol
                                              : (numerator.si_symbol.empty() ? "1" : numerator.si_symbol) + "/" + wrap(denominator.si_symbol);
  u.quantity = quantity_of(u.dimension);
  canonical_symbol(u);
  return u;
}

std::string to_string(Quantity q) {
  switch (q) {
    case Quantity::kLength: return "length";
    case Quantity::kTime: return "time";
    case Quantity::kVoltage: return "voltage";
    case Quantity::kForce: return "force";
    case Quantity::kFrequency: return "frequency";
    case Quantity::kCapacitance: return "capacitance";
    case Quantity::kCurrent: return "current";
    case Quantity::kMass: return "mass";
    case Quantity::kVelocity: return "velocity";
    case Quantity::kAcceleration: return "acceleration";
    case Quantity::kPressure: return "pressure";
    case Quantity::kDimensionless: return "dimensionless";
    case Quantity::kCompound: return "compound";
  }
  return "dimensionless";
}

std::optional<Unit> find_unit(std::string_view raw) {
  // A Latin-1 label ("m/s\xB2" from a Windows-era UFF or CSV writer) is read as the UTF-8 it means.
  const std::string decoded = text::utf8_from_legacy(text::trim(raw));
  const std::string_view symbol = decoded;
  if (std::optional<Unit> u = table_unit(symbol)) return u;
  if (symbol.empty() || symbol.size() > 80) return std::nullopt;
  const std::optional<Product> p = CompoundParser(symbol).parse();
  // A factor that over- or underflows would scale the samples by 0 or inf: no unit.
  if (p && p->valid && std::isfinite(p->factor) && p->factor > 0.0) return unit_of_product(symbol, *p);
  return std::nullopt;
}

std::string known_units() {
  std::string out;
  for (const Entry& e : kUnitTable) {
    if (!e.listed) continue;
    if (!out.empty()) out += ", ";
    out += e.symbol;
  }
  return out;
}

Unit unit_from_string(std::string_view symbol, const std::string& source, const std::string& field) {
  if (std::optional<Unit> u = find_unit(symbol)) return *u;
  throw InputError(source, field, "a known unit (" + known_units() + ", or products and quotients of them such as um/V)",
                   "unit " + text::quote(text::trim(symbol)));
}

}  // namespace piezobench::io
