#pragma once
// Field declarations: a result struct lists its fields once, beside its definition, and every
// document is derived from that list (part.json, results.json, the Python classes, the report's
// tables, docs/fields.md). One entry per member:
//
//     constexpr auto describe(core::Type<StrokeResult>) {
//       using S = StrokeResult;
//       return core::fields<S>("StrokeResult", "stroke and sensitivity of a quasi-static record",
//           core::field("stroke", &S::stroke, core::shown::kMicrometre, "max - min of the smoothed d_e"),
//           core::field("va_min", &S::va_min, core::shown::kVolt, "lowest Va of the record"));
//     }
//
// `describe` lives in the struct's namespace (found by argument-dependent lookup through
// core::Type<S>) and is constexpr, so the list is a compile-time table of member pointers that
// for_each_field visits generically.
//
// Contract of an entry (a member `field`, or a `derived` value read from one of the struct's parts):
//  - name: the member's name; the key in part.json (SI values) and the Python attribute.
//  - shown: the member's SI unit and the unit documents show it in, with the ONE factor between
//    them (shown = SI value * per_si). results.json's key is `name_UNIT` (UNIT with "/" spelled
//    "_per_", e.g. "sensitivity_um_per_V") unless the entry names another key (`.key("...")`).
//  - meaning: one line for people (the Python docstring, docs/fields.md, the report's column).
//  - where it appears besides part.json and Python: results.json (default; `.part_only()` keeps a
//    curve or an internal out) and the report's parameter table of the struct (`.in_report()`).
//
// Non-finite numbers: every document encodes them one way, as the strings "nan", "inf" and "-inf"
// (JSON has no such numbers; io/json.hpp's to_json); an absent optional value is null.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace piezobench::core {

// A member's SI unit and the unit the documents show it in.
struct Shown {
  std::string_view si;    // "m", "N/m", "rad/s", "1" (a ratio); "" for text, flags, counts, nested results
  std::string_view unit;  // as shown: "um", "N/um", "Hz"; "" for a ratio or no quantity
  double per_si = 1.0;    // shown value = SI value * per_si
};

// The displayed units of the project's documents (the one place their factors are written).
namespace shown {
inline constexpr double kTwoPi = 6.283185307179586476925286766559;
inline constexpr Shown kNone{"", "", 1.0};     // text, flags, counts, lists, nested results
inline constexpr Shown kRatio{"1", "", 1.0};   // dimensionless: ratios, damping, relative errors
inline constexpr Shown kMetreAsUm{"m", "um", 1e6};
inline constexpr Shown kMetre{"m", "m", 1.0};
inline constexpr Shown kMetrePerVoltAsUmPerV{"m/V", "um/V", 1e6};
inline constexpr Shown kMetrePerNewtonAsUmPerN{"m/N", "um/N", 1e6};
inline constexpr Shown kNewtonPerMetreAsNPerUm{"N/m", "N/um", 1e-6};
inline constexpr Shown kVoltPerMetreAsVPerUm{"V/m", "V/um", 1e-6};
inline constexpr Shown kFaradAsUf{"F", "uF", 1e6};
inline constexpr Shown kHertz{"Hz", "Hz", 1.0};
inline constexpr Shown kRadPerSecondAsHz{"rad/s", "Hz", 1.0 / kTwoPi};
inline constexpr Shown kRadPerSecond{"rad/s", "rad/s", 1.0};
inline constexpr Shown kVolt{"V", "V", 1.0};
inline constexpr Shown kVoltPerVolt{"V/V", "V/V", 1.0};
inline constexpr Shown kNewtonPerVolt{"N/V", "N/V", 1.0};
inline constexpr Shown kSecond{"s", "s", 1.0};
inline constexpr Shown kKilogram{"kg", "kg", 1.0};
inline constexpr Shown kNewtonSecondPerMetre{"N s/m", "Ns/m", 1.0};
inline constexpr Shown kMetrePerSecond2{"m/s^2", "m/s^2", 1.0};
inline constexpr Shown kOhm{"Ohm", "ohm", 1.0};
inline constexpr Shown kPascal{"Pa", "Pa", 1.0};
inline constexpr Shown kDegree{"deg", "deg", 1.0};
inline constexpr Shown kDecibel{"dB", "dB", 1.0};
}  // namespace shown

// Where a field appears besides part.json and Python.
enum Appears : unsigned { kPartOnly = 0U, kResults = 1U, kReport = 2U };

// The tag `describe` is found by.
template <class S> struct Type {};

// What every entry declares besides how its value is read (Self: the entry's type, for the modifiers).
template <class Self> struct Entry {
  std::string_view name;
  Shown shown;
  std::string_view meaning;
  unsigned appears = kResults;
  std::string_view results_key = {};  // "" = name_UNIT

  [[nodiscard]] constexpr bool in(Appears where) const { return (appears & where) != 0U; }
  // Modifiers (constexpr copies): another results.json key, left out of results.json, in the report table.
  [[nodiscard]] constexpr Self key(std::string_view k) const { Self f = self(); f.results_key = k; return f; }
  [[nodiscard]] constexpr Self part_only() const { Self f = self(); f.appears = kPartOnly; return f; }
  [[nodiscard]] constexpr Self in_report() const { Self f = self(); f.appears |= kReport; return f; }

 private:
  [[nodiscard]] constexpr const Self& self() const { return static_cast<const Self&>(*this); }
};

// A member of the struct.
template <class S, class M> struct Field : Entry<Field<S, M>> {
  using Struct = S;
  using Member = M;
  static constexpr bool kDerived = false;
  M S::*member = nullptr;

  [[nodiscard]] constexpr const M& of(const S& s) const { return s.*member; }
  [[nodiscard]] constexpr M& of(S& s) const { return s.*member; }
};

// A derived field: a value the struct holds in one of its parts, declared like a member with a
// getter instead of a member pointer (UnitAnalysis's k1 is its stiffness analysis' k1, read by
// `k1_of`), so that each number lives in one place. The getter returns the value (a number or an
// optional) or a pointer into the struct (nullptr: absent). results.json, the report, docs/fields.md
// and Python (a read-only property) show it like a member; part.json leaves it out (the part it is
// read from is there) and its reader ignores the key.
template <class S, class V> struct Derived : Entry<Derived<S, V>> {
  using Struct = S;
  using Member = V;
  static constexpr bool kDerived = true;
  V (*get)(const S&) = nullptr;

  [[nodiscard]] constexpr V of(const S& s) const { return get(s); }
};

namespace fields_detail {
template <class F> constexpr F named(F f, std::string_view name, Shown shown, std::string_view meaning) {
  f.name = name;
  f.shown = shown;
  f.meaning = meaning;
  return f;
}
}  // namespace fields_detail

template <class S, class M>
constexpr Field<S, M> field(std::string_view name, M S::*member, Shown shown, std::string_view meaning) {
  Field<S, M> f;
  f.member = member;
  return fields_detail::named(f, name, shown, meaning);
}

template <class S, class V>
constexpr Derived<S, V> derived(std::string_view name, V (*get)(const S&), Shown shown, std::string_view meaning) {
  Derived<S, V> f;
  f.get = get;
  return fields_detail::named(f, name, shown, meaning);
}

// A struct's declaration: its name and meaning, and its fields in order.
template <class S, class... Fs> struct FieldList {
  std::string_view name;
  std::string_view meaning;
  std::tuple<Fs...> fields;
};

template <class S, class... Fs>
constexpr FieldList<S, Fs...> fields(std::string_view name, std::string_view meaning, Fs... f) {
  static_assert((std::is_base_of_v<typename Fs::Struct, S> && ...), "every field of a declaration is a member of its struct (or of a base)");
  return FieldList<S, Fs...>{name, meaning, std::tuple<Fs...>{f...}};
}

// A derived struct's declaration: its base's fields (base: the base's kFields), then its own.
template <class S, class B, class... Bs, class... Fs>
constexpr FieldList<S, Bs..., Fs...> extended_fields(std::string_view name, std::string_view meaning, const FieldList<B, Bs...>& base,
                                                     Fs... f) {
  static_assert(std::is_base_of_v<B, S>, "a declaration extends the declaration of a base of its struct");
  return FieldList<S, Bs..., Fs...>{name, meaning, std::tuple_cat(base.fields, std::tuple<Fs...>{f...})};
}

// True for a struct with a declaration.
template <class S> concept Described = requires { describe(Type<S>{}); };

template <class S> inline constexpr auto kFields = describe(Type<S>{});

// Calls f(field) for every field of S's declaration, in order.
template <class S, class F> constexpr void for_each_field(F&& f) {
  std::apply([&](const auto&... field) { (f(field), ...); }, kFields<S>.fields);
}

// The type a field holds once its optional, list and array wrappers are taken off (what a document
// walks into: a described struct, a number, a text ...).
template <class T> struct Element { using type = T; };
template <class T> struct Element<std::optional<T>> : Element<T> {};
template <class T, class A> struct Element<std::vector<T, A>> : Element<T> {};
template <class T, std::size_t N> struct Element<std::array<T, N>> : Element<T> {};
template <class T> struct Element<T*> : Element<std::remove_const_t<T>> {};
template <class T> using element_t = typename Element<T>::type;

template <class S> constexpr std::size_t field_count() { return std::tuple_size_v<decltype(kFields<S>.fields)>; }

// What a declaration says of one entry, found by its member pointer or derived getter (a `which` the
// declaration does not list gives an empty name).
struct Declared {
  std::string_view name;
  Shown shown;
  std::string_view meaning;
};
template <class S, class W> Declared declared(W which) {
  Declared out;
  for_each_field<S>([&](const auto& f) {
    using F = std::remove_cvref_t<decltype(f)>;
    if constexpr (F::kDerived) {
      if constexpr (std::is_same_v<decltype(f.get), W>) {
        if (f.get == which) out = {f.name, f.shown, f.meaning};
      }
    } else if constexpr (std::is_same_v<decltype(f.member), W>) {
      if (f.member == which) out = {f.name, f.shown, f.meaning};
    }
  });
  return out;
}

// "um/V" -> "um_per_V", "m/s^2" -> "m_per_s2", "N s/m" -> "N_s_per_m".
std::string unit_key_suffix(std::string_view unit);
// results.json's key of a field: its own key, else the name, followed by _UNIT when there is a
// shown unit and the name does not already end with it ("resonance_Hz" stays).
std::string results_key(std::string_view name, const Shown& shown, std::string_view own_key = {});
template <class F> std::string results_key(const F& f) { return results_key(f.name, f.shown, f.results_key); }
// "um" -> "[um]" for a table heading; "" for a ratio or no quantity.
std::string unit_heading(const Shown& shown);
// A report table's column of a field: the name without its unit suffix, words apart, and the shown
// unit ("static_gain", um/V -> "static gain [um/V]"; "resonance_Hz" -> "resonance [Hz]").
std::string report_heading(std::string_view name, const Shown& shown);
template <class F> std::string report_heading(const F& f) { return report_heading(f.name, f.shown); }

}  // namespace piezobench::core
