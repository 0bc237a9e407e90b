#pragma once
// Private text helpers of the fem readers and writers (fem depends on lti only, not on io).
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "piezobench/core/error.hpp"

namespace piezobench::fem::detail {

// The whole file; InputError(file, "file", ...) when it cannot be read.
inline std::string read_file(const std::filesystem::path& file) {
  std::error_code status_ec;
  const auto status = std::filesystem::status(file, status_ec);
  if (std::filesystem::is_directory(status)) throw InputError(file.string(), "file", "a readable file", "a directory");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "file", "a readable file", "it cannot be opened");
  std::string text;
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (!ec) text.reserve(static_cast<std::size_t>(size));
  text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file.string(), "file", "a readable file", "a read error");
  return text;
}

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

inline std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// Whitespace-separated tokens (commas also separate when `commas` is true).
inline std::vector<std::string_view> tokens(std::string_view line, bool commas = false) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  const auto sep = [commas](char c) { return is_space(c) || (commas && c == ','); };
  while (i < line.size()) {
    while (i < line.size() && sep(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !sep(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// Splits text into lines (without the terminator); calls f(line_number (1-based), line); stops
// when f returns false.
inline void for_each_line(std::string_view text, const std::function<bool(std::size_t, std::string_view)>& f) {
  std::size_t start = 0;
  std::size_t number = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!f(++number, line)) return;
    start = end + 1;
  }
}

// Parses a number at the start of `s` (after blanks); advances `s`. Accepts a leading '+' and
// "nan"/"inf" (so that callers can report them as non-finite rather than as text).
inline std::optional<double> take_double(std::string_view& s) {
  std::size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
  if (i < s.size() && s[i] == '+') ++i;
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data() + i, s.data() + s.size(), value);
  if (ec != std::errc()) return std::nullopt;
  s.remove_prefix(static_cast<std::size_t>(ptr - s.data()));
  return value;
}

inline std::optional<long long> take_int(std::string_view& s) {
  std::size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
  if (i < s.size() && s[i] == '+') ++i;
  long long value = 0;
  const auto [ptr, ec] = std::from_chars(s.data() + i, s.data() + s.size(), value);
  if (ec != std::errc()) return std::nullopt;
  s.remove_prefix(static_cast<std::size_t>(ptr - s.data()));
  return value;
}

// The whole token must be a number.
inline std::optional<double> parse_double(std::string_view token) {
  token = trim(token);
  const auto v = take_double(token);
  if (!v || !token.empty()) return std::nullopt;
  return v;
}
inline std::optional<long long> parse_int(std::string_view token) {
  token = trim(token);
  const auto v = take_int(token);
  if (!v || !token.empty()) return std::nullopt;
  return v;
}

// Shows a piece of a file in an error message: quoted, at most 40 characters.
inline std::string quote(std::string_view text) {
  text = trim(text);
  std::string s(text.substr(0, 40));
  if (text.size() > 40) s += "...";
  return "'" + s + "'";
}

inline std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

inline std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Writes a file under a temporary name beside the target and renames it over the target; a
// failure leaves no partial file. InputError(target, "file", ...) on I/O failure.
inline void write_atomically(const std::filesystem::path& target, const std::function<void(std::ostream&)>& body) {
  const std::filesystem::path temp = target.string() + ".tmp-piezobench";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(target.string(), "file", "a writable location", "it cannot be created");
    try {
      body(out);
      out.flush();
    } catch (...) {
      out.close();
      std::error_code ec;
      std::filesystem::remove(temp, ec);
      throw;
    }
    if (!out) {
      out.close();
      std::error_code ec;
      std::filesystem::remove(temp, ec);
      throw InputError(target.string(), "file", "a successful write", "an I/O error (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, target, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw InputError(target.string(), "file", "a successful rename of the temporary file", ec.message());
  }
}

}  // namespace piezobench::fem::detail
