#pragma once
// Python classes derived from the field declarations beside the result structs (core/fields.hpp):
// bind_described<S>(m) makes S a read-only class with one property per declared field (the field's
// name, docstring "SI unit: meaning"), and does the same for every declared struct its fields hold,
// so that every member of a result is reachable from Python with no list to keep in step.
// def_fields<S>(cls, part) adds S's fields to a class that holds an S (campaign.CampaignResult holds
// the CampaignResult of a run) or that binds some fields in its own layout (dsp.Frf's H as one array).
//
// Values: numbers in SI as the struct holds them; lists of numbers as numpy arrays (a list of Eigen
// vectors as one 2-D array, a row each; paths as str); enums by their
// names; a declared struct as its class (a view that keeps its owner alive); lists and optionals of
// those likewise (None when absent). Every class has fields() (the declaration, for the tests),
// keys() and [name] (so dict(r) and f(**r) work, as with the dicts they replace), to_dict() and a repr.
#include <complex>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "common.hpp"
#include "piezobench/core/field_types.hpp"
#include "piezobench/core/fields.hpp"

namespace piezobench::python {

namespace described_detail {
template <class T> struct IsDescribedList : std::false_type {};
template <class T, class A> struct IsDescribedList<std::vector<T, A>> : std::bool_constant<core::Described<T>> {};
// A list of Eigen vectors of one length (lti::RootLocus's poles per gain): one 2-D array, a row each.
template <class T> struct IsVectorList : std::false_type {};
template <class T> constexpr bool is_column() {
  if constexpr (core::kIsEigen<T>) {
    return T::ColsAtCompileTime == 1;
  } else {
    return false;
  }
}
template <class T, class A> struct IsVectorList<std::vector<T, A>> : std::bool_constant<is_column<T>()> {};

template <class V> py::object stacked_rows(const std::vector<V>& v) {
  using Scalar = typename V::Scalar;
  const Eigen::Index n = v.empty() ? 0 : v.front().size();
  Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> out(static_cast<Eigen::Index>(v.size()), n);
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (v[i].size() != n) {
      throw NumericalError("python", "rows of unequal length (" + std::to_string(v[i].size()) + " and " + std::to_string(n) + ")", false);
    }
    out.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  }
  return to_numpy(std::move(out));
}
}  // namespace described_detail

template <class S> void bind_described(py::module_& m);

template <class T> py::object py_value(const T& v, py::handle owner) {
  using namespace described_detail;
  if constexpr (std::is_enum_v<T>) {
    return py::str(to_string(v));
  } else if constexpr (core::kIsOptional<T> || std::is_pointer_v<T>) {  // a derived field's pointer into its owner
    return v ? py_value(*v, owner) : py::none();
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    return to_numpy(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()))));
  } else if constexpr (std::is_same_v<T, std::vector<std::complex<double>>>) {
    return to_numpy(Eigen::VectorXcd(Eigen::Map<const Eigen::VectorXcd>(v.data(), static_cast<Eigen::Index>(v.size()))));
  } else if constexpr (core::kIsEigen<T>) {
    return to_numpy(v);  // a copy, as the other numeric arrays
  } else if constexpr (IsVectorList<T>::value) {
    return stacked_rows(v);
  } else if constexpr (std::is_same_v<T, std::filesystem::path>) {
    return py::str(v.string());
  } else if constexpr (IsDescribedList<T>::value || std::is_same_v<T, std::vector<std::filesystem::path>>) {
    py::list l;
    for (const auto& x : v) l.append(py_value(x, owner));
    return l;
  } else if constexpr (core::Described<T>) {
    return py::cast(&v, py::return_value_policy::reference_internal, owner);
  } else {
    return py::cast(v);
  }
}

// The declaration of S as [(name, SI unit, shown unit, meaning)] (what the tests enumerate).
template <class S> py::list declared_fields() {
  py::list out;
  core::for_each_field<S>([&](const auto& f) {
    out.append(py::make_tuple(std::string(f.name), std::string(f.shown.si), std::string(f.shown.unit), std::string(f.meaning)));
  });
  return out;
}

// Adds to `cls` (a py::class_ of T) one read-only property per field of S's declaration, read from
// `part(const T&)` (a const S&), except the fields named in `own` (bound by the caller in another
// layout), and fields() / keys() / [name] over the whole declaration.
template <class S, class Class, class Part>
void def_fields(Class& cls, Part part, std::initializer_list<std::string_view> own = {}) {
  using T = typename Class::type;
  core::for_each_field<S>([&](const auto& f) {
    for (const std::string_view o : own) {
      if (o == f.name) return;
    }
    const std::string doc = f.shown.si.empty() ? std::string(f.meaning) : std::string(f.shown.si) + ": " + std::string(f.meaning);
    cls.def_property_readonly(
        std::string(f.name).c_str(), [f, part](py::object self) { return py_value(f.of(part(self.cast<const T&>())), self); },
        doc.c_str());
  });
  cls.def_static("fields", [] { return declared_fields<S>(); }, "The field declaration: [(name, SI unit, shown unit, meaning)].");
  cls.def_static("keys", [] {
    py::list names;
    core::for_each_field<S>([&](const auto& f) { names.append(std::string(f.name)); });
    return names;
  }, "The declared field names (with [name]: dict(r) and f(**r) work).");
  cls.def("__getitem__", [](py::object self, const std::string& name) { return self.attr(name.c_str()); }, "A field by name.");
}

// Binds, in m, every declared struct S's fields hold that is not bound yet.
template <class S> void bind_held(py::module_& m) {
  core::for_each_field<S>([&](const auto& f) {
    using E = core::element_t<typename std::remove_cvref_t<decltype(f)>::Member>;
    if constexpr (core::Described<E>) bind_described<E>(m);
  });
}

template <class S> void bind_described(py::module_& m) {
  if (py::detail::get_type_info(typeid(S)) != nullptr) return;  // bound already (here or by its module)
  constexpr auto& d = core::kFields<S>;
  py::class_<S> c(m, std::string(d.name).c_str(), std::string(d.meaning).c_str());
  def_fields<S>(c, [](const S& s) -> const S& { return s; });
  typed(c);
  bind_held<S>(m);
}

// {declared name: (Python class, [field names])} for S and every declared struct its fields hold;
// a struct that is not bound raises (the tests' check that Python reaches every member).
template <class S> void collect_declarations(py::dict& out) {
  constexpr auto& d = core::kFields<S>;
  const std::string name(d.name);
  if (out.contains(name)) return;
  py::list names;
  core::for_each_field<S>([&](const auto& f) { names.append(std::string(f.name)); });
  out[py::str(name)] = py::make_tuple(py::type::of<S>(), names);
  core::for_each_field<S>([&](const auto& f) {
    using E = core::element_t<typename std::remove_cvref_t<decltype(f)>::Member>;
    if constexpr (core::Described<E>) collect_declarations<E>(out);
  });
}

// {declared name: (Python class, [field names])} for the structs S... and those they hold (a module's
// `declarations()`).
template <class... S> py::dict declarations_of() {
  py::dict out;
  (collect_declarations<S>(out), ...);
  return out;
}

// The class of S as bound (to add its derived properties and methods).
template <class S> py::class_<S> bound_class() { return py::reinterpret_borrow<py::class_<S>>(py::type::of<S>()); }

}  // namespace piezobench::python
