#include "common.hpp"

#include <cmath>

namespace piezobench::python {

std::string describe_shape(const py::array& a) {
  std::string s = "shape (";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  if (a.ndim() == 1) s += ",";
  return s + ")";
}

std::string short_repr(py::handle obj) {
  std::string r = py::repr(obj);
  if (r.size() > 60) r = r.substr(0, 57) + "...";
  return r;
}

namespace {

template <class A>
A ensure_array(py::handle obj, const std::string& source, const std::string& field, const char* what) {
  if (obj.is_none()) throw InputError(source, field, what, "None");
  A a = A::ensure(obj);
  if (!a) {
    PyErr_Clear();
    throw InputError(source, field, what, short_repr(obj));
  }
  return a;
}

template <class T>
void require_finite(const T* data, py::ssize_t n, const std::string& source, const std::string& field) {
  for (py::ssize_t i = 0; i < n; ++i) {
    if (!std::isfinite(std::abs(data[i]))) {
      throw InputError(source, field, "finite values", "a non-finite value at index " + std::to_string(i));
    }
  }
}

}  // namespace

DoubleArray vector_arg(py::handle obj, const std::string& source, const std::string& field, bool check_finite) {
  auto a = ensure_array<DoubleArray>(obj, source, field, "a 1-D array of real numbers");
  if (a.ndim() != 1) throw InputError(source, field, "a 1-D array", describe_shape(a));
  if (check_finite) require_finite(a.data(), a.size(), source, field);
  return a;
}

ComplexArray complex_vector_arg(py::handle obj, const std::string& source, const std::string& field,
                                bool check_finite) {
  auto a = ensure_array<ComplexArray>(obj, source, field, "a 1-D array of complex numbers");
  if (a.ndim() != 1) throw InputError(source, field, "a 1-D array", describe_shape(a));
  if (check_finite) require_finite(a.data(), a.size(), source, field);
  return a;
}

DoubleMatrixArray matrix_arg(py::handle obj, const std::string& source, const std::string& field,
                             bool one_d_is_column) {
  auto a = ensure_array<DoubleMatrixArray>(obj, source, field, "a 2-D array of real numbers");
  if (!(a.ndim() == 2 || (one_d_is_column && a.ndim() == 1))) {
    throw InputError(source, field, one_d_is_column ? "a 1-D or 2-D array" : "a 2-D array", describe_shape(a));
  }
  require_finite(a.data(), a.size(), source, field);
  return a;
}

ComplexMatrixArray complex_matrix_arg(py::handle obj, const std::string& source, const std::string& field,
                                      bool one_d_is_column) {
  auto a = ensure_array<ComplexMatrixArray>(obj, source, field, "a 2-D array of complex numbers");
  if (!(a.ndim() == 2 || (one_d_is_column && a.ndim() == 1))) {
    throw InputError(source, field, one_d_is_column ? "a 1-D or 2-D array" : "a 2-D array", describe_shape(a));
  }
  require_finite(a.data(), a.size(), source, field);
  return a;
}

Eigen::VectorXd to_vector(py::handle obj, const std::string& source, const std::string& field) {
  return map(vector_arg(obj, source, field));
}
Eigen::VectorXcd to_complex_vector(py::handle obj, const std::string& source, const std::string& field) {
  return map(complex_vector_arg(obj, source, field));
}
Eigen::MatrixXd to_matrix(py::handle obj, const std::string& source, const std::string& field, bool one_d_is_column) {
  return map(matrix_arg(obj, source, field, one_d_is_column));
}
Eigen::MatrixXcd to_complex_matrix(py::handle obj, const std::string& source, const std::string& field) {
  return map(complex_matrix_arg(obj, source, field, true));
}

namespace {

template <class E>
py::array owned(E&& e, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides) {
  using Plain = std::decay_t<E>;
  using Scalar = typename Plain::Scalar;
  auto* heap = new Plain(std::forward<E>(e));
  py::capsule owner(heap, [](void* p) { delete static_cast<Plain*>(p); });
  return py::array_t<Scalar>(std::move(shape), std::move(strides), heap->data(), owner);
}

}  // namespace

py::array to_numpy(Eigen::VectorXd&& v) {
  const py::ssize_t n = v.size();
  return owned(std::move(v), {n}, {static_cast<py::ssize_t>(sizeof(double))});
}
py::array to_numpy(Eigen::VectorXcd&& v) {
  const py::ssize_t n = v.size();
  return owned(std::move(v), {n}, {static_cast<py::ssize_t>(sizeof(Complex))});
}
py::array to_numpy(Eigen::MatrixXd&& m) {
  const py::ssize_t r = m.rows(), c = m.cols(), s = sizeof(double);
  return owned(std::move(m), {r, c}, {s, s * r});
}
py::array to_numpy(Eigen::MatrixXcd&& m) {
  const py::ssize_t r = m.rows(), c = m.cols(), s = sizeof(Complex);
  return owned(std::move(m), {r, c}, {s, s * r});
}

py::array view(const Eigen::VectorXd& v, py::handle owner) {
  py::array a = py::array_t<double>({static_cast<py::ssize_t>(v.size())}, {static_cast<py::ssize_t>(sizeof(double))},
                                    v.data(), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}
py::array view(const Eigen::MatrixXd& m, py::handle owner) {
  const py::ssize_t r = m.rows(), c = m.cols(), s = sizeof(double);
  py::array a = py::array_t<double>({r, c}, {s, s * r}, m.data(), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::object result(const std::string& type, py::dict fields) {
  static py::object cls = py::module_::import("piezobench._result").attr("Result");
  return cls(type, fields);
}

py::object typed_to_dict(py::handle self) {
  static py::object f = py::module_::import("piezobench._result").attr("typed_to_dict");
  return f(self);
}

std::string typed_repr(py::handle self) {
  static py::object f = py::module_::import("piezobench._result").attr("typed_repr");
  return py::str(f(self));
}

double number_arg(py::handle value, const std::string& source, const std::string& key) {
  if (py::isinstance<py::bool_>(value) || !(PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr()) ||
                                            PyNumber_Check(value.ptr()))) {
    throw InputError(source, key, "a number", short_repr(value));
  }
  double v = 0.0;
  try {
    v = value.cast<double>();
  } catch (const py::cast_error&) {
    throw InputError(source, key, "a number", short_repr(value));
  }
  if (!std::isfinite(v)) throw InputError(source, key, "a finite number", short_repr(value));
  return v;
}

long long integer_arg(py::handle value, const std::string& source, const std::string& key) {
  if (py::isinstance<py::bool_>(value) || PyIndex_Check(value.ptr()) == 0) {
    // Whole floats (e.g. 1e4) are accepted as integers.
    if (PyFloat_Check(value.ptr())) {
      const double d = PyFloat_AsDouble(value.ptr());
      if (std::isfinite(d) && d == std::floor(d) && std::abs(d) < 9.0e15) return static_cast<long long>(d);
    }
    throw InputError(source, key, "an integer", short_repr(value));
  }
  try {
    return value.cast<long long>();
  } catch (const py::cast_error&) {
    throw InputError(source, key, "an integer within 64 bits", short_repr(value));
  }
}

bool bool_arg(py::handle value, const std::string& source, const std::string& key) {
  if (!py::isinstance<py::bool_>(value) && !(PyLong_Check(value.ptr()) && (value.cast<long long>() == 0 ||
                                                                          value.cast<long long>() == 1))) {
    throw InputError(source, key, "True or False", short_repr(value));
  }
  return value.cast<bool>();
}

std::string string_arg(py::handle value, const std::string& source, const std::string& key) {
  if (!py::isinstance<py::str>(value)) throw InputError(source, key, "a string", short_repr(value));
  return value.cast<std::string>();
}

py::list list_arg(py::handle value, const std::string& source, const std::string& key, const std::string& expected) {
  if (value.is_none() || py::isinstance<py::str>(value)) throw InputError(source, key, expected, short_repr(value));
  PyObject* l = PySequence_List(value.ptr());
  if (l == nullptr) {
    PyErr_Clear();
    throw InputError(source, key, expected, short_repr(value));
  }
  return py::reinterpret_steal<py::list>(l);
}

void reject_leftovers(const py::dict& kwargs, const std::string& source, const std::string& known) {
  for (auto item : kwargs) {
    throw InputError(source, std::string(py::str(item.first)), "one of the keywords (" + known + ")",
                     "an unknown keyword");
  }
}

}  // namespace piezobench::python
