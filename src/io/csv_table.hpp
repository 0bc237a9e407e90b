#pragma once
// The one CSV table reader behind the time-series and FRF CSV files: the dialects labs write
// (delimiter ',', ';', tab or blanks; decimal point or comma; detected or forced), blank lines and
// '#' comments anywhere, a header row of `name`, `name [unit]` or `name (unit)` cells.
#include <Eigen/Dense>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace piezobench::io::detail {

struct CsvDialect {
  char delimiter = 0;  // 0: detect; ',', ';', '\t', or ' ' (runs of blanks)
  char decimal = 0;    // 0: detect; '.' or ','

  // InputError (source "options") for anything else, or a comma for both.
  void validate() const;
};

struct CsvColumn {
  std::string name;  // the header cell without its unit
  std::string unit;  // as written ("" = none)
};

class CsvTable {
 public:
  // Reads the file, takes the first line that is neither blank nor a '#' comment as the header and
  // settles the dialect from it and the first data line. InputError naming the file otherwise.
  CsvTable(const std::filesystem::path& file, CsvDialect dialect);

  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const std::vector<CsvColumn>& columns() const { return columns_; }
  // Comment lines before the header: (line number, text after '#', trimmed).
  [[nodiscard]] const std::vector<std::pair<size_t, std::string>>& comments() const { return comments_; }
  [[nodiscard]] char delimiter() const { return dialect_.delimiter; }
  [[nodiscard]] char decimal() const { return dialect_.decimal; }
  // For messages: "';'-separated (detected), decimal comma (detected)".
  [[nodiscard]] std::string dialect_text() const;

  // Parses the data rows: column c goes to column target[c] of the result when target[c] >= 0 (the
  // other columns are only counted). InputError naming the column and line for a cell that is not
  // a finite number, or a row with another number of fields (the message gives the dialect).
  [[nodiscard]] Eigen::MatrixXd read(const std::vector<int>& target, Eigen::Index ntargets) const;

 private:
  std::string source_;
  std::string content_;
  size_t data_start_ = 0;  // offset of the line after the header
  size_t header_line_ = 0;
  CsvDialect dialect_;
  bool delimiter_detected_ = false;
  bool decimal_detected_ = false;
  std::vector<CsvColumn> columns_;
  std::vector<std::pair<size_t, std::string>> comments_;
};

}  // namespace piezobench::io::detail
