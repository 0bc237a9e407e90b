#pragma once
// Text helpers of the readers and writers (io, fem): trimming, splitting, strict number parsing
// and quoting pieces of a file in error messages. Whole files: core/file.hpp.
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace piezobench::text {

[[nodiscard]] bool is_space(char c);
// Without leading and trailing white space (blank, tab, CR, LF, FF, VT).
[[nodiscard]] std::string_view trim(std::string_view s);
[[nodiscard]] std::string to_lower(std::string s);
// Splits at every `sep` (no quoting; empty fields kept).
[[nodiscard]] std::vector<std::string_view> split(std::string_view s, char sep);
// White-space separated tokens (commas also separate when `commas` is true; no empty tokens).
[[nodiscard]] std::vector<std::string_view> tokens(std::string_view line, bool commas = false);
// Calls f(line number (1-based), line without its "\n" or "\r\n") for each line; stops when f
// returns false.
void for_each_line(std::string_view text, const std::function<bool(std::size_t, std::string_view)>& f);

// A number at the start of `s` (after blanks and an optional '+'), advancing `s` past it; nullopt
// (and `s` unchanged) when there is none. "nan"/"inf" are numbers (callers report them as
// non-finite values rather than as text); an overflow is an infinity, an underflow a zero.
[[nodiscard]] std::optional<double> take_double(std::string_view& s);
[[nodiscard]] std::optional<long long> take_int(std::string_view& s);
// Strict: the whole (trimmed) token must be a number as above. Fortran 'D' exponents are accepted
// when `fortran` is true.
[[nodiscard]] std::optional<double> parse_double(std::string_view token, bool fortran = false);
[[nodiscard]] std::optional<long long> parse_int(std::string_view token);

// The code point of the UTF-8 sequence at s[i], advancing i past it; nullopt (i unchanged) when
// the bytes there are not a well-formed sequence (truncated, an overlong form, a surrogate or a
// code point past U+10FFFF).
[[nodiscard]] std::optional<char32_t> take_utf8(std::string_view s, std::size_t& i);
// Appends the code point c (at most U+10FFFF) to `out` as UTF-8.
void append_utf8(std::string& out, char32_t c);
// True when `s` is well-formed UTF-8 (take_utf8 takes it whole).
[[nodiscard]] bool is_utf8(std::string_view s);
// Text of a file as UTF-8: `s` itself when it is well-formed UTF-8, else every byte read as
// ISO 8859-1 (Latin-1), the 8-bit text of Windows-era writers: UFF files and CSV headers with
// "m/s\xB2" (m/s squared) or "\xB5m" (micrometres) become "m/s\u00B2" and "\u00B5m".
[[nodiscard]] std::string utf8_from_legacy(std::string_view s);

// Shows a piece of a file in an error message: quoted, at most 40 characters, non-printable bytes
// as \xNN.
[[nodiscard]] std::string quote(std::string_view text);
// "a, b, c"
[[nodiscard]] std::string join(const std::vector<std::string>& items, const std::string& sep = ", ");

}  // namespace piezobench::text
