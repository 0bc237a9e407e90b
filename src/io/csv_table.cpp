#include "csv_table.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

#include "piezobench/io/timeseries.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"

namespace piezobench::io::detail {
namespace fs = std::filesystem;
using text::quote;
using text::trim;
using text::parse_double;
using text::split;

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

bool is_comment_or_blank(std::string_view line) {
  const std::string_view t = trim(line);
  return t.empty() || t.front() == '#';
}

// Splits a line at `delimiter`; ' ' splits at runs of blanks (spaces and tabs) and ignores blanks
// at both ends.
void split_fields(std::string_view line, char delimiter, std::vector<std::string_view>& out) {
  out.clear();
  if (delimiter != ' ') {
    size_t start = 0;
    for (;;) {
      const size_t pos = line.find(delimiter, start);
      if (pos == std::string_view::npos) {
        out.push_back(line.substr(start));
        return;
      }
      out.push_back(line.substr(start, pos - start));
      start = pos + 1;
    }
  }
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i >= line.size()) break;
    size_t j = i;
    while (j < line.size() && !is_blank(line[j])) ++j;
    out.push_back(line.substr(i, j - i));
    i = j;
  }
}

// Header cells split at blanks: a unit written apart ("Time [s]", "u (V)") belongs to the name
// before it.
std::vector<std::string> blank_header_cells(std::string_view line) {
  std::vector<std::string_view> parts;
  split_fields(line, ' ', parts);
  std::vector<std::string> cells;
  for (std::string_view p : parts) {
    if (!cells.empty() && (p.front() == '[' || p.front() == '(')) {
      cells.back() += " " + std::string(p);
    } else {
      cells.emplace_back(p);
    }
  }
  return cells;
}

std::string delimiter_name(char d) {
  switch (d) {
    case '\t': return "tab";
    case ' ': return "blank";
    default: return std::string("'") + d + "'";
  }
}

std::string unquote(std::string_view s) {
  s = trim(s);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = trim(s.substr(1, s.size() - 2));
  return std::string(s);
}

CsvColumn parse_header_cell(const std::string& cell, const std::string& source, size_t line_no, size_t column,
                            const std::string& dialect) {
  const std::string text = unquote(cell);
  const std::string where = "header (line " + std::to_string(line_no) + ", column " + std::to_string(column + 1) + ")";
  CsvColumn out;
  const size_t open = text.find('[');
  if (open != std::string::npos) {
    const size_t close = text.find(']', open);
    if (close == std::string::npos || !trim(std::string_view(text).substr(close + 1)).empty()) {
      throw InputError(source, where, "NAME, NAME [UNIT] or NAME (UNIT) (" + dialect + ")", quote(text));
    }
    out.unit = std::string(trim(std::string_view(text).substr(open + 1, close - open - 1)));
    out.name = std::string(trim(std::string_view(text).substr(0, open)));
  } else if (!text.empty() && text.back() == ')' && text.find('(') != std::string::npos) {
    const size_t paren = text.rfind('(');
    out.unit = std::string(trim(std::string_view(text).substr(paren + 1, text.size() - paren - 2)));
    out.name = std::string(trim(std::string_view(text).substr(0, paren)));
  } else {
    out.name = text;
  }
  if (out.name.empty()) throw InputError(source, where, "a column name", quote(text));
  return out;
}

}  // namespace

void CsvDialect::validate() const {
  if (delimiter != 0 && delimiter != ',' && delimiter != ';' && delimiter != '\t' && delimiter != ' ') {
    throw InputError("options", "delimiter", "',', ';', tab or blank", quote(std::string(1, delimiter)));
  }
  if (decimal != 0 && decimal != '.' && decimal != ',') {
    throw InputError("options", "decimal", "'.' or ','", quote(std::string(1, decimal)));
  }
  if (delimiter == ',' && decimal == ',') {
    throw InputError("options", "decimal", "a decimal separator other than the delimiter", "',' for both");
  }
}

CsvTable::CsvTable(const fs::path& file, CsvDialect dialect) : source_(file.string()), dialect_(dialect) {
  dialect.validate();
  content_ = read_file(file);
  if (const size_t nul = content_.find('\0'); nul != std::string::npos) {
    throw InputError(source_, "file", "a text (CSV) file", "binary data (a NUL byte at offset " + std::to_string(nul) + ")");
  }
  const std::string_view text(content_);
  // Skips a UTF-8 byte order mark (spreadsheets write one).
  size_t pos = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  size_t line_no = 0;
  const auto next_line = [&](std::string_view& line) {
    if (pos >= text.size()) return false;
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end + 1;
    ++line_no;
    return true;
  };
  std::string_view header, line;
  bool have_header = false;
  while (next_line(line)) {
    if (!is_comment_or_blank(line)) {
      header = line;
      have_header = true;
      break;
    }
    const std::string_view body = trim(line);
    if (!body.empty()) comments_.emplace_back(line_no, std::string(trim(body.substr(1))));
  }
  if (!have_header) throw InputError(source_, "header", "a header row (column names)", "no line other than comments");
  header_line_ = line_no;
  data_start_ = std::min(pos, text.size());
  std::string_view first_data;
  {
    const size_t save_pos = pos, save_line = line_no;
    while (next_line(line)) {
      if (!is_comment_or_blank(line)) {
        first_data = line;
        break;
      }
    }
    pos = save_pos;
    line_no = save_line;
  }

  // The delimiter: the first of tab, ';', ',' that splits the header into 2 fields or more and the
  // first data line into as many; else runs of blanks under the same rule; else ',' (one column).
  std::vector<std::string_view> fields;
  if (dialect_.delimiter == 0) {
    delimiter_detected_ = true;
    dialect_.delimiter = ',';
    bool found = false;
    for (const char d : {'\t', ';', ','}) {
      split_fields(header, d, fields);
      const size_t h = fields.size();
      if (h < 2) continue;
      split_fields(first_data, d, fields);
      if (first_data.empty() || fields.size() == h) {
        dialect_.delimiter = d;
        found = true;
        break;
      }
    }
    if (!found) {
      const size_t h = blank_header_cells(header).size();
      split_fields(first_data, ' ', fields);
      if (h >= 2 && (first_data.empty() || fields.size() == h)) dialect_.delimiter = ' ';
    }
  }
  // The decimal separator: a comma when the delimiter is not one and the first data line has one.
  if (dialect_.decimal == 0) {
    decimal_detected_ = true;
    dialect_.decimal = dialect_.delimiter != ',' && first_data.find(',') != std::string_view::npos ? ',' : '.';
  }
  if (dialect_.delimiter == ',' && dialect_.decimal == ',') {
    throw InputError(source_, "decimal", "a decimal separator other than the delimiter (" + dialect_text() + ")", "','");
  }

  std::vector<std::string> cells;
  if (dialect_.delimiter == ' ') {
    cells = blank_header_cells(header);
  } else {
    split_fields(header, dialect_.delimiter, fields);
    for (std::string_view f : fields) cells.emplace_back(f);
  }
  std::set<std::string> seen;
  for (size_t c = 0; c < cells.size(); ++c) {
    columns_.push_back(parse_header_cell(cells[c], source_, header_line_, c, dialect_text()));
    if (!seen.insert(columns_.back().name).second) {
      throw InputError(source_, "header", "distinct column names", quote(columns_.back().name) + " twice (" + dialect_text() + ")");
    }
  }
}

std::string CsvTable::dialect_text() const {
  std::string out = delimiter_name(dialect_.delimiter) + "-separated";
  if (delimiter_detected_) out += " (detected)";
  out += dialect_.decimal == ',' ? ", decimal comma" : ", decimal point";
  if (decimal_detected_) out += " (detected)";
  return out;
}

Eigen::MatrixXd CsvTable::read(const std::vector<int>& target, Eigen::Index ntargets) const {
  const std::string_view text(content_);
  const size_t ncols = columns_.size();
  // Upper bound of the number of rows, so the matrix is allocated once.
  const auto max_rows = static_cast<Eigen::Index>(std::count(text.begin() + static_cast<std::ptrdiff_t>(data_start_), text.end(), '\n') + 1);
  Eigen::MatrixXd data(max_rows, ntargets);
  Eigen::Index rows = 0;
  size_t pos = data_start_;
  size_t line_no = header_line_;
  std::vector<std::string_view> fields;
  fields.reserve(ncols);
  std::string buffer;
  const char delimiter = dialect_.delimiter;
  const bool comma_decimal = dialect_.decimal == ',';
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (is_comment_or_blank(line)) continue;
    split_fields(line, delimiter, fields);
    if (fields.size() != ncols) {
      throw InputError(source_, "line " + std::to_string(line_no),
                       std::to_string(ncols) + " fields like the header (" + dialect_text() + ")", std::to_string(fields.size()));
    }
    for (size_t c = 0; c < ncols; ++c) {
      if (target[c] < 0) continue;
      std::string_view cell = fields[c];
      if (comma_decimal && cell.find(',') != std::string_view::npos) {
        buffer.assign(cell);
        std::replace(buffer.begin(), buffer.end(), ',', '.');
        cell = buffer;
      }
      const std::optional<double> v = parse_double(cell);
      if (!v) {
        const std::string_view shown = trim(fields[c]);
        throw InputError(source_, columns_[c].name + " (line " + std::to_string(line_no) + ")",
                         "a number (" + dialect_text() + ")", shown.empty() ? std::string("an empty cell") : quote(shown));
      }
      if (!std::isfinite(*v)) {
        throw InputError(source_, columns_[c].name + " (line " + std::to_string(line_no) + ")", "a finite number",
                         quote(trim(fields[c])) + " at sample " + std::to_string(rows));
      }
      data(rows, target[c]) = *v;
    }
    ++rows;
  }
  if (rows == 0) throw InputError(source_, "data", "at least one data row after the header", "none");
  return data.topRows(rows);
}

}  // namespace piezobench::io::detail

namespace piezobench::io {

char csv_delimiter_from_string(const std::string& s) {
  const std::string l = text::to_lower(s);
  if (l.empty() || l == "auto") return 0;
  if (l == "," || l == "comma") return ',';
  if (l == ";" || l == "semicolon") return ';';
  if (l == "tab" || l == "\t" || l == "\\t") return '\t';
  if (l == "space" || l == "blank" || l == "blanks" || l == " ") return ' ';
  throw InputError("command line", "--delimiter", "auto, ',', ';', tab or space", text::quote(s));
}

char csv_decimal_from_string(const std::string& s) {
  const std::string l = text::to_lower(s);
  if (l.empty() || l == "auto") return 0;
  if (l == "." || l == "point") return '.';
  if (l == "," || l == "comma") return ',';
  throw InputError("command line", "--decimal", "auto, '.' or ','", text::quote(s));
}

}  // namespace piezobench::io
