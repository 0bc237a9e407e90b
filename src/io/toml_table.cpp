#include "piezobench/io/toml_table.hpp"

#include <fstream>
#include <sstream>
#include <vector>

#include "piezobench/core/error.hpp"

namespace piezobench::io {
namespace fs = std::filesystem;

std::string describe_toml(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer:
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array of " + std::to_string(node.as_array()->size());
    case toml::node_type::table: return "a table";
    default: return "a date or time";
  }
}

std::optional<double> toml_number(const toml::node& node) {
  if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
  if (const auto* f = node.as_floating_point()) return f->get();
  return std::nullopt;
}

namespace {

// A lexical pass over the text, enough of TOML to know where keys are: strings (basic, literal,
// multi-line) and comments are skipped, '[' at the start of a line opens a table header, '=' ends
// a key, '[' / '{' in a value nest. It never rejects what it does not understand (toml++ does):
// it only counts key parts and nesting, and throws when a limit is passed.
class LimitScan {
 public:
  LimitScan(const std::string& text, const std::string& source, const TomlLimits& limits)
      : t_(text), source_(source), limits_(limits) {}

  void run() {
    bool key_mode = true;     // at a key (line start, inside a header, after '{' or ',' in an inline table)
    bool line_start = true;
    std::size_t parts = 1;
    std::vector<char> stack;  // '[' arrays and '{' inline tables of the current value
    while (i_ < t_.size()) {
      const char c = t_[i_];
      if (c == '\n') {
        ++line_;
        ++i_;
        if (stack.empty()) {
          key_mode = true;
          line_start = true;
          parts = 1;
        }
        continue;
      }
      if (c == ' ' || c == '\t' || c == '\r') {
        ++i_;
        continue;
      }
      if (c == '#') {
        while (i_ < t_.size() && t_[i_] != '\n') ++i_;
        continue;
      }
      if (c == '"' || c == '\'') {
        skip_string(c);
        line_start = false;
        continue;
      }
      if (key_mode) {
        if (c == '}' && !stack.empty() && stack.back() == '{') {  // an empty inline table or a trailing ','
          stack.pop_back();
          key_mode = false;
          ++i_;
          continue;
        }
        if (line_start && c == '[' && stack.empty()) {
          ++i_;  // a table header: its key runs to ']'
          line_start = false;
          continue;
        }
        line_start = false;
        if (c == '.') {
          if (++parts > limits_.max_key_parts) fail("a dotted key or table header", "more than " + std::to_string(limits_.max_key_parts) + " parts");
        } else if (c == '=') {
          key_mode = false;
        } else if (c == ']' && stack.empty()) {
          parts = 1;  // end of a header; the rest of the line is a comment or an error for toml++
        }
        ++i_;
        continue;
      }
      // A value.
      if (c == '[' || c == '{') {
        stack.push_back(c);
        if (stack.size() > limits_.max_nesting) fail("arrays and inline tables", "nested more than " + std::to_string(limits_.max_nesting) + " deep");
        if (c == '{') {
          key_mode = true;
          parts = 1;
        }
      } else if (c == ']' || c == '}') {
        if (!stack.empty()) stack.pop_back();
      } else if (c == ',' && !stack.empty() && stack.back() == '{') {
        key_mode = true;
        parts = 1;
      }
      ++i_;
    }
  }

 private:
  // Skips a string starting at i_ (quote `q`), multi-line when tripled; counts its newlines.
  void skip_string(char q) {
    const bool multi = t_.compare(i_, 3, std::string(3, q)) == 0;
    i_ += multi ? 3 : 1;
    while (i_ < t_.size()) {
      const char c = t_[i_];
      if (c == '\\' && q == '"') {
        if (i_ + 1 < t_.size() && t_[i_ + 1] == '\n') ++line_;
        i_ += 2;
        continue;
      }
      if (c == '\n') {
        if (!multi) return;  // unterminated: toml++ reports it
        ++line_;
      }
      if (c == q && (!multi || t_.compare(i_, 3, std::string(3, q)) == 0)) {
        i_ += multi ? 3 : 1;
        return;
      }
      ++i_;
    }
  }

  [[noreturn]] void fail(const std::string& what, const std::string& found) const {
    throw InputError(source_, "line " + std::to_string(line_), what + " within piezobench's TOML limits", found);
  }

  const std::string& t_;
  const std::string& source_;
  const TomlLimits& limits_;
  std::size_t i_ = 0, line_ = 1;
};

void check_size(std::size_t bytes, const std::string& source, const TomlLimits& limits) {
  if (bytes > limits.max_bytes) {
    throw InputError(source, "file size", "at most " + std::to_string(limits.max_bytes) + " bytes of TOML",
                     std::to_string(bytes) + " bytes");
  }
}

}  // namespace

toml::table parse_toml(const std::string& text, const std::string& source, const TomlLimits& limits) {
  check_size(text.size(), source, limits);
  LimitScan(text, source, limits).run();
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(source, "line " + std::to_string(e.source().begin.line) + ", column " + std::to_string(e.source().begin.column),
                     "valid TOML", std::string(e.description()));
  }
}

std::string read_toml_text(const fs::path& file, const TomlLimits& limits) {
  const std::string source = file.string();
  std::error_code ec;
  const fs::file_status st = fs::status(file, ec);
  if (ec || !fs::exists(st)) throw InputError(source, "file", "an existing TOML file", "no such file");
  if (fs::is_directory(st)) throw InputError(source, "file", "a TOML file", "a directory");
  if (fs::is_regular_file(st)) {
    const auto size = fs::file_size(file, ec);
    if (!ec) check_size(static_cast<std::size_t>(size), source, limits);
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(source, "file", "a readable TOML file", "a file that cannot be opened");
  // Read at most one byte past the limit (a FIFO or device has no size to check first).
  std::string text(limits.max_bytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw InputError(source, "file", "a readable TOML file", "a read error");
  text.resize(static_cast<std::size_t>(in.gcount()));
  check_size(text.size(), source, limits);
  return text;
}

toml::table read_toml_file(const fs::path& file, const TomlLimits& limits) {
  return parse_toml(read_toml_text(file, limits), file.string(), limits);
}

}  // namespace piezobench::io
