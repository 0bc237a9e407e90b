#pragma once
// The station's TOML tables read with errors that name the file, the line and the full key
// ("station.toml: line 42: phases[3].retries: expected an integer >= 0, found -1"). Internal to
// src/station (station_file.cpp, answers.cpp); parsing itself is io/toml_table.hpp's.
#include <optional>
#include <string>
#include <vector>

#include <toml++/toml.h>

namespace piezobench::station::detail {

class TableReader {
 public:
  TableReader(const toml::table& table, std::string file, std::string prefix);

  [[nodiscard]] std::string key(const std::string& k) const;
  [[nodiscard]] const toml::table& table() const { return table_; }
  // "FILE: line L" of a node (the table's own line when the node has no source position).
  [[nodiscard]] std::string where(const toml::node* node = nullptr) const;
  [[noreturn]] void fail(const std::string& k, const std::string& expected, const std::string& found,
                         const toml::node* node = nullptr) const;

  void only(const std::vector<std::string>& known) const;  // unknown keys are errors
  [[nodiscard]] std::optional<std::string> text(const std::string& k) const;
  [[nodiscard]] std::string required_text(const std::string& k) const;
  [[nodiscard]] std::optional<double> number(const std::string& k) const;  // finite
  [[nodiscard]] std::optional<long> integer(const std::string& k, long min) const;
  [[nodiscard]] std::optional<bool> flag(const std::string& k) const;
  [[nodiscard]] std::vector<std::string> texts(const std::string& k) const;  // absent: empty
  // Element i of array k (for the line of an error about it); nullptr when there is none.
  [[nodiscard]] const toml::node* element(const std::string& k, std::size_t i) const;
  // Sub-tables of an array of tables (absent: empty), each with its own reader.
  [[nodiscard]] std::vector<TableReader> tables(const std::string& k) const;
  [[nodiscard]] std::optional<TableReader> sub(const std::string& k) const;

 private:
  const toml::table& table_;
  std::string file_, prefix_;
};

}  // namespace piezobench::station::detail
