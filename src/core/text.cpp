#include "piezobench/core/text.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <system_error>

namespace piezobench::text {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::optional<char32_t> take_utf8(std::string_view s, size_t& i) {
  if (i >= s.size()) return std::nullopt;
  const auto b = static_cast<unsigned char>(s[i]);
  const int more = b < 0x80 ? 0 : (b >> 5) == 0x6 ? 1 : (b >> 4) == 0xE ? 2 : (b >> 3) == 0x1E ? 3 : -1;
  if (more < 0 || i + static_cast<size_t>(more) >= s.size()) return std::nullopt;
  char32_t c = more == 0 ? b : more == 1 ? (b & 0x1Fu) : more == 2 ? (b & 0x0Fu) : (b & 0x07u);
  for (int k = 1; k <= more; ++k) {
    const auto next = static_cast<unsigned char>(s[i + static_cast<size_t>(k)]);
    if ((next >> 6) != 0x2) return std::nullopt;
    c = (c << 6) | (next & 0x3Fu);
  }
  static constexpr char32_t kMin[4] = {0, 0x80, 0x800, 0x10000};  // below: an overlong form
  if (c < kMin[more] || c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) return std::nullopt;
  i += static_cast<size_t>(more) + 1;
  return c;
}

void append_utf8(std::string& out, char32_t c) {
  if (c < 0x80) {
    out += static_cast<char>(c);
  } else if (c < 0x800) {
    out += static_cast<char>(0xC0 | (c >> 6));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    out += static_cast<char>(0xE0 | (c >> 12));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (c >> 18));
    out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  }
}

bool is_utf8(std::string_view s) {
  size_t i = 0;
  while (i < s.size()) {
    if (!take_utf8(s, i)) return false;
  }
  return true;
}

std::string utf8_from_legacy(std::string_view s) {
  if (is_utf8(s)) return std::string(s);
  std::string out;
  out.reserve(s.size() + s.size() / 4);
  for (const char ch : s) append_utf8(out, static_cast<unsigned char>(ch));  // Latin-1 byte = code point
  return out;
}

std::string to_lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> parts;
  size_t start = 0;
  for (;;) {
    const size_t pos = s.find(sep, start);
    if (pos == std::string_view::npos) {
      parts.push_back(s.substr(start));
      return parts;
    }
    parts.push_back(s.substr(start, pos - start));
    start = pos + 1;
  }
}

std::vector<std::string_view> tokens(std::string_view line, bool commas) {
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

void for_each_line(std::string_view text, const std::function<bool(std::size_t, std::string_view)>& f) {
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

namespace {

// Index of the first character of the number in s: after blanks and one '+' (which from_chars
// rejects but spreadsheets and Fortran write); npos when a sign follows the '+'.
std::size_t number_start(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
  if (i < s.size() && s[i] == '+') {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) return std::string_view::npos;
  }
  return i;
}

}  // namespace

std::optional<double> take_double(std::string_view& s) {
  const std::size_t i = number_start(s);
  if (i == std::string_view::npos) return std::nullopt;
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data() + i, s.data() + s.size(), value);
  if (ec == std::errc::result_out_of_range) {
    // Overflow is a non-finite value for the caller to report; underflow is a zero.
    value = std::strtod(std::string(s.data() + i, ptr).c_str(), nullptr);
  } else if (ec != std::errc()) {
    return std::nullopt;
  }
  s.remove_prefix(static_cast<std::size_t>(ptr - s.data()));
  return value;
}

std::optional<long long> take_int(std::string_view& s) {
  const std::size_t i = number_start(s);
  if (i == std::string_view::npos) return std::nullopt;
  long long value = 0;
  const auto [ptr, ec] = std::from_chars(s.data() + i, s.data() + s.size(), value);
  if (ec != std::errc()) return std::nullopt;
  s.remove_prefix(static_cast<std::size_t>(ptr - s.data()));
  return value;
}

std::optional<double> parse_double(std::string_view token, bool fortran) {
  token = trim(token);
  if (token.empty()) return std::nullopt;
  std::string buffer;
  if (fortran && token.find_first_of("dD") != std::string_view::npos) {
    buffer.assign(token);
    std::replace(buffer.begin(), buffer.end(), 'd', 'e');
    std::replace(buffer.begin(), buffer.end(), 'D', 'E');
    token = buffer;
  }
  const auto v = take_double(token);
  if (!v || !token.empty()) return std::nullopt;
  return v;
}

std::optional<long long> parse_int(std::string_view token) {
  token = trim(token);
  const auto v = take_int(token);
  if (!v || !token.empty()) return std::nullopt;
  return v;
}

std::string quote(std::string_view text) {
  std::string out = "'";
  const size_t limit = 40;
  for (size_t i = 0; i < text.size() && i < limit; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (std::isprint(c) != 0) {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  if (text.size() > limit) out += "...";
  return out + "'";
}

std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += sep;
    out += items[i];
  }
  return out;
}

}  // namespace piezobench::text
