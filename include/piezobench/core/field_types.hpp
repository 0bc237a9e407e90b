#pragma once
// The kinds of value a field declaration (core/fields.hpp) holds, as the generic documents tell them
// apart: optional, list, fixed-size array, pair, complex number, Eigen vector or matrix, and a list
// of (key, value) pairs. One set of traits for part.json (campaign/part.cpp), results.json
// (io/fields_json.hpp) and the Python classes (python/src/described.hpp).
#include <Eigen/Core>
#include <array>
#include <complex>
#include <cstddef>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace piezobench::core {

template <class T> inline constexpr bool kIsOptional = false;
template <class T> inline constexpr bool kIsOptional<std::optional<T>> = true;
template <class T> inline constexpr bool kIsVector = false;
template <class T, class A> inline constexpr bool kIsVector<std::vector<T, A>> = true;
template <class T> inline constexpr bool kIsStdArray = false;
template <class T, std::size_t N> inline constexpr bool kIsStdArray<std::array<T, N>> = true;
template <class T> inline constexpr bool kIsPair = false;
template <class A, class B> inline constexpr bool kIsPair<std::pair<A, B>> = true;
template <class T> inline constexpr bool kIsComplex = false;
template <class T> inline constexpr bool kIsComplex<std::complex<T>> = true;
template <class T> inline constexpr bool kIsEigen = std::is_base_of_v<Eigen::EigenBase<T>, T>;
// A list of (key, value) pairs: results.json writes it as an object.
template <class T> inline constexpr bool kIsPairList = false;
template <class A, class B, class Al> inline constexpr bool kIsPairList<std::vector<std::pair<A, B>, Al>> = true;

}  // namespace piezobench::core
