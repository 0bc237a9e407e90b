#pragma once
// What every binding file shares: numpy arrays in and out, options from keyword arguments, typed
// results, and the GIL released around long work.
//
// Arrays in: 1-D float64 (complex128) contiguous arrays are used in place; anything else that numpy
// can turn into that (lists, float32, strided views) is converted once. A wrong number of
// dimensions or a non-finite value is an InputError naming the argument.
// Arrays out: the result's Eigen storage is handed to numpy (no copy); matrices keep Eigen's
// column-major layout (numpy sees Fortran order).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Dense>
#include <complex>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "piezobench/core/error.hpp"

namespace piezobench::lti {
struct StateSpace;
struct RootLocusOptions;
struct RootLocus;
struct FrequencyResponse;
}
namespace piezobench::dsp {
struct Frf;
}

namespace piezobench::python {

namespace py = pybind11;
using Complex = std::complex<double>;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using ComplexArray = py::array_t<Complex, py::array::c_style | py::array::forcecast>;
using DoubleMatrixArray = py::array_t<double, py::array::f_style | py::array::forcecast>;
using ComplexMatrixArray = py::array_t<Complex, py::array::f_style | py::array::forcecast>;

// "shape (3, 4)" of any object numpy can read (for messages).
std::string describe_shape(const py::array& a);
// repr() of a Python object, cut to 60 characters.
std::string short_repr(py::handle obj);

// ---- arrays in ------------------------------------------------------------------------------
// `source` names the function (e.g. "dsp.h1"), `field` the argument. check_finite = false leaves
// the finiteness check to the library (e.g. Welch, whose message gives the channel and index).
DoubleArray vector_arg(py::handle obj, const std::string& source, const std::string& field,
                       bool check_finite = true);
ComplexArray complex_vector_arg(py::handle obj, const std::string& source, const std::string& field,
                                bool check_finite = true);
// 2-D (a 1-D array is one column when one_d_is_column, else refused).
DoubleMatrixArray matrix_arg(py::handle obj, const std::string& source, const std::string& field,
                             bool one_d_is_column = false);
ComplexMatrixArray complex_matrix_arg(py::handle obj, const std::string& source, const std::string& field,
                                      bool one_d_is_column = true);

inline std::span<const double> span(const DoubleArray& a) { return {a.data(), static_cast<std::size_t>(a.size())}; }
inline Eigen::Map<const Eigen::VectorXd> map(const DoubleArray& a) { return {a.data(), a.size()}; }
inline Eigen::Map<const Eigen::VectorXcd> map(const ComplexArray& a) { return {a.data(), a.size()}; }
inline Eigen::Map<const Eigen::MatrixXd> map(const DoubleMatrixArray& a) {
  return {a.data(), a.ndim() > 0 ? a.shape(0) : 0, a.ndim() > 1 ? a.shape(1) : 1};
}
inline Eigen::Map<const Eigen::MatrixXcd> map(const ComplexMatrixArray& a) {
  return {a.data(), a.ndim() > 0 ? a.shape(0) : 0, a.ndim() > 1 ? a.shape(1) : 1};
}
// Owned copies, for library functions that take Eigen objects by const reference.
Eigen::VectorXd to_vector(py::handle obj, const std::string& source, const std::string& field);
Eigen::VectorXcd to_complex_vector(py::handle obj, const std::string& source, const std::string& field);
Eigen::MatrixXd to_matrix(py::handle obj, const std::string& source, const std::string& field,
                          bool one_d_is_column = false);
Eigen::MatrixXcd to_complex_matrix(py::handle obj, const std::string& source, const std::string& field);

// ---- arrays out (no copy: numpy owns the moved Eigen object) ----------------------------------
py::array to_numpy(Eigen::VectorXd&& v);
py::array to_numpy(Eigen::VectorXcd&& v);
py::array to_numpy(Eigen::MatrixXd&& m);
py::array to_numpy(Eigen::MatrixXcd&& m);
inline py::array to_numpy(const Eigen::VectorXd& v) { return to_numpy(Eigen::VectorXd(v)); }
inline py::array to_numpy(const Eigen::VectorXcd& v) { return to_numpy(Eigen::VectorXcd(v)); }
inline py::array to_numpy(const Eigen::MatrixXd& m) { return to_numpy(Eigen::MatrixXd(m)); }
inline py::array to_numpy(const Eigen::MatrixXcd& m) { return to_numpy(Eigen::MatrixXcd(m)); }
// A read-only view of storage owned by the Python object `owner` (kept alive by the view).
py::array view(const Eigen::VectorXd& v, py::handle owner);
py::array view(const Eigen::MatrixXd& m, py::handle owner);

// ---- typed results ---------------------------------------------------------------------------
// A piezobench.Result: attribute access to `fields`, to_dict(), a readable repr. `type` is its
// class name as shown by repr (e.g. "TwoDofTuning").
py::object result(const std::string& type, py::dict fields);

// Typed results bound as classes (ident.IffPlantFit, campaign.UnitAnalysis, ...): read-only
// properties in the order of the C++ struct, to_dict() (nested typed results as dicts, arrays kept)
// and a repr listing them. typed() adds to_dict and __repr__ to a py::class_.
py::object typed_to_dict(py::handle self);
std::string typed_repr(py::handle self);
template <class Class>
Class& typed(Class& cls) {
  cls.def("to_dict", [](py::handle self) { return typed_to_dict(self); },
          "The fields as a dict (nested results as dicts; arrays stay numpy arrays).");
  cls.def("__repr__", [](py::handle self) { return typed_repr(self); });
  return cls;
}

// A JSON document as Python values; objects become Results (typed by `type`, nested ones by their
// key) when as_results, else dicts (campaign.cpp).
py::object from_json(const nlohmann::json& j, const std::string& type, bool as_results);

// ---- options from keyword arguments ----------------------------------------------------------
// One table per options struct: the Python name of each field is the C++ member's name, the
// default is the C++ struct's default (read from a default-constructed T), and help() lists them.
// Unknown keywords, values of the wrong type and non-finite numbers are InputErrors naming the
// keyword; the library's validate() then checks ranges.
template <class T>
class Options {
 public:
  struct Field {
    std::string name, type, doc;
    std::function<void(T&, py::handle, const std::string&)> set;
    std::function<py::object(const T&)> get;
  };

  explicit Options(std::string name) : name_(std::move(name)) {}

  template <class M>
  Options& add(const char* name, M T::*member, const char* doc) {
    Field f{name, type_name<M>(), doc, {}, {}};
    std::string key = name;
    f.set = [member, key](T& t, py::handle value, const std::string& source) {
      t.*member = convert<M>(value, source, key);
    };
    f.get = [member](const T& t) { return to_python(t.*member); };
    fields_.push_back(std::move(f));
    return *this;
  }

  // An enum spelled as text (to_string / from_string of the library).
  template <class E>
  Options& add_enum(const char* name, E T::*member, std::string (*to)(E), E (*from)(const std::string&),
                    const char* doc) {
    Field f{name, "str", doc, {}, {}};
    std::string key = name;
    f.set = [member, from, key](T& t, py::handle value, const std::string& source) {
      const std::string text = convert<std::string>(value, source, key);
      try {
        t.*member = from(text);
      } catch (const InputError& e) {  // the library names its own field: name the keyword
        throw InputError(source, key, "a known name (" + std::string(e.what()) + ")", "\"" + text + "\"");
      }
    };
    f.get = [member, to](const T& t) { return py::object(py::str(to(t.*member))); };
    fields_.push_back(std::move(f));
    return *this;
  }

  // A nested options struct, given as a dict of its own keywords.
  template <class S>
  Options& add_nested(const char* name, S T::*member, const Options<S>& table, const char* doc) {
    Field f{name, "dict", doc, {}, {}};
    std::string key = name;
    f.set = [member, &table, key](T& t, py::handle value, const std::string& source) {
      if (!py::isinstance<py::dict>(value)) {
        throw InputError(source, key, "a dict of " + table.name() + " keywords", short_repr(value));
      }
      t.*member = table.from_kwargs(py::reinterpret_borrow<py::dict>(value), source, t.*member);
    };
    f.get = [member, &table](const T& t) { return py::object(table.to_dict(t.*member)); };
    fields_.push_back(std::move(f));
    return *this;
  }

  [[nodiscard]] const std::string& name() const { return name_; }

  // `base` with the keywords applied (no validation beyond types and finiteness).
  T from_kwargs(const py::dict& kwargs, const std::string& source, T base = {}) const {
    for (auto item : kwargs) {
      const std::string key = py::str(item.first);
      const Field* f = find(key);
      if (f == nullptr) throw InputError(source, key, "one of the " + name_ + " keywords (" + names() + ")", "an unknown keyword");
      f->set(base, item.second, source);
    }
    return base;
  }
  // Only the keywords of `kwargs` that this table knows are applied and removed from `kwargs`.
  T take(py::dict& kwargs, const std::string& source, T base = {}) const {
    for (const Field& f : fields_) {
      py::str key(f.name);
      if (kwargs.contains(key)) {
        f.set(base, kwargs[key], source);
        PyDict_DelItem(kwargs.ptr(), key.ptr());
      }
    }
    return base;
  }
  [[nodiscard]] py::dict to_dict(const T& t) const {
    py::dict d;
    for (const Field& f : fields_) d[py::str(f.name)] = f.get(t);
    return d;
  }
  // "name: type = default  doc" lines, for docstrings.
  [[nodiscard]] std::string doc(const std::string& indent = "    ") const {
    std::string out;
    T defaults{};
    for (const Field& f : fields_) {
      out += indent + f.name + ": " + f.type + " = " + std::string(py::repr(f.get(defaults))) + "\n";
      out += indent + "    " + f.doc + "\n";
    }
    return out;
  }
  [[nodiscard]] std::string names() const {
    std::string out;
    for (const Field& f : fields_) out += (out.empty() ? "" : ", ") + f.name;
    return out;
  }

 private:
  const Field* find(const std::string& key) const {
    for (const Field& f : fields_)
      if (f.name == key) return &f;
    return nullptr;
  }

  template <class M>
  static std::string type_name() {
    if constexpr (std::is_same_v<M, bool>) return "bool";
    else if constexpr (std::is_integral_v<M>) return "int";
    else if constexpr (std::is_floating_point_v<M>) return "float";
    else if constexpr (std::is_same_v<M, std::string>) return "str";
    else if constexpr (std::is_same_v<M, std::optional<double>>) return "float | None";
    else if constexpr (std::is_same_v<M, std::optional<std::filesystem::path>>) return "str | None";
    else return "list";
  }

  template <class M>
  static M convert(py::handle value, const std::string& source, const std::string& key);

  template <class M>
  static py::object to_python(const M& v) {
    if constexpr (std::is_same_v<M, Eigen::VectorXcd> || std::is_same_v<M, Eigen::VectorXd>) {
      return py::object(to_numpy(v));
    } else if constexpr (std::is_same_v<M, std::optional<std::filesystem::path>>) {
      return v ? py::object(py::str(v->string())) : py::object(py::none());
    } else {
      return py::cast(v);
    }
  }

  std::string name_;
  std::vector<Field> fields_;
};

// Conversions of one keyword value; InputError(source, key, expected, found) when it does not fit.
double number_arg(py::handle value, const std::string& source, const std::string& key);
long long integer_arg(py::handle value, const std::string& source, const std::string& key);
bool bool_arg(py::handle value, const std::string& source, const std::string& key);
std::string string_arg(py::handle value, const std::string& source, const std::string& key);
// The items of a list, tuple or other iterable (not a string).
py::list list_arg(py::handle value, const std::string& source, const std::string& key, const std::string& expected);

template <class T>
template <class M>
M Options<T>::convert(py::handle value, const std::string& source, const std::string& key) {
  if constexpr (std::is_same_v<M, bool>) {
    return bool_arg(value, source, key);
  } else if constexpr (std::is_integral_v<M>) {
    const long long v = integer_arg(value, source, key);
    if constexpr (std::is_unsigned_v<M>) {
      if (v < 0) throw InputError(source, key, "a non-negative integer", std::to_string(v));
    }
    return static_cast<M>(v);
  } else if constexpr (std::is_floating_point_v<M>) {
    return number_arg(value, source, key);
  } else if constexpr (std::is_same_v<M, std::string>) {
    return string_arg(value, source, key);
  } else if constexpr (std::is_same_v<M, std::optional<double>>) {
    if (value.is_none()) return std::nullopt;
    return number_arg(value, source, key);
  } else if constexpr (std::is_same_v<M, std::optional<std::filesystem::path>>) {
    if (value.is_none()) return std::nullopt;
    return std::filesystem::path(string_arg(py::str(value), source, key));
  } else if constexpr (std::is_same_v<M, std::vector<double>>) {
    auto a = vector_arg(value, source, key);
    return std::vector<double>(a.data(), a.data() + a.size());
  } else if constexpr (std::is_same_v<M, std::vector<std::string>>) {
    if (py::isinstance<py::str>(value)) throw InputError(source, key, "a list of strings", short_repr(value));
    std::vector<std::string> out;
    for (auto item : list_arg(value, source, key, "a list of strings")) out.push_back(string_arg(item, source, key));
    return out;
  } else if constexpr (std::is_same_v<M, std::vector<long>>) {
    std::vector<long> out;
    for (auto item : list_arg(value, source, key, "a list of integers")) out.push_back(static_cast<long>(integer_arg(item, source, key)));
    return out;
  } else if constexpr (std::is_same_v<M, Eigen::VectorXcd>) {
    return to_complex_vector(value, source, key);
  } else if constexpr (std::is_same_v<M, Eigen::VectorXd>) {
    return to_vector(value, source, key);
  } else {
    static_assert(sizeof(M) == 0, "no keyword conversion for this member type");
  }
}

// Runs f() with the GIL released (for work of more than a few milliseconds).
template <class F>
auto without_gil(F&& f) {
  py::gil_scoped_release release;
  return f();
}

// The keyword arguments as a dict (an empty one for none).
inline py::dict kwargs_dict(const py::kwargs& kw) { return py::dict(kw); }
// InputError for keywords left over after every table took its own.
void reject_leftovers(const py::dict& kwargs, const std::string& source, const std::string& known);

// A system given as lti.StateSpace, lti.TransferFunction or lti.Zpk, as a state space (lti.cpp).
lti::StateSpace state_space_arg(py::handle obj, const std::string& source, const std::string& field);

// A frequency response as a complex128 array (len(omega), outputs, inputs); with squeeze_siso a
// single-input single-output response is 1-D (lti.cpp; lti.freqresp squeezes, fem's does not).
py::array response_array(const lti::FrequencyResponse& r, bool squeeze_siso);

// Keyword tables shared by several modules (defined in lti.cpp and dsp.cpp).
template <class T>
class Options;
const Options<lti::RootLocusOptions>& root_locus_options();
// An argument that must be a dsp.Frf.
const dsp::Frf& frf_arg(py::handle obj, const std::string& source, const std::string& field);

// The binding of each module (one source file each).
void bind_lti(py::module_& m);
void bind_dsp(py::module_& m);
void bind_ident(py::module_& m);
void bind_control(py::module_& m);
void bind_apa(py::module_& m);
void bind_fem(py::module_& m);
void bind_io(py::module_& m);
void bind_bench(py::module_& m);
void bind_campaign(py::module_& m);
void bind_hysteresis(py::module_& ident, py::module_& control, py::module_& io);  // hysteresis.cpp

}  // namespace piezobench::python
