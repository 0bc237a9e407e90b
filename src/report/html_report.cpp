#include "piezobench/report/html_report.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string_view>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/version.hpp"
#include "piezobench/report/embedded_assets.hpp"

namespace piezobench::report {
namespace {

using nlohmann::json;
constexpr const char* kSource = "report document";

// ---- validation helpers -----------------------------------------------------------------------

std::string shorten(std::string text, std::size_t limit = 60) {
  if (text.size() > limit) text = text.substr(0, limit) + "...";
  return text;
}

// What a JSON value is, for "found ..." in an error message.
std::string describe(const json& value) {
  switch (value.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return value.get<bool>() ? "true" : "false";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return "the number " + value.dump();
    case json::value_t::string:
      return "the string " +
             shorten(json(value.get<std::string>()).dump(-1, ' ', false, json::error_handler_t::replace));
    case json::value_t::array:
      return "a list of " + std::to_string(value.size());
    case json::value_t::object:
      return "an object";
    default:
      return "a value of another kind";
  }
}

[[noreturn]] void fail(const std::string& field, const std::string& expected, const std::string& found) {
  throw InputError(kSource, field, expected, found);
}

// Object check plus: no key outside `allowed` (a typo of a known key would be silently ignored).
void require_object(const json& value, const std::string& field, std::initializer_list<std::string_view> allowed) {
  if (!value.is_object()) fail(field, "an object", describe(value));
  if (allowed.size() == 0) return;
  for (const auto& item : value.items()) {
    bool known = false;
    for (const auto key : allowed) known = known || item.key() == key;
    if (!known) {
      std::string keys;
      for (const auto key : allowed) keys += (keys.empty() ? "" : ", ") + std::string(key);
      fail(field + "." + item.key(), "one of the keys " + keys, "an unknown key");
    }
  }
}

std::string child(const std::string& field, std::string_view key) {
  return field + "." + std::string(key);
}
std::string element(const std::string& field, std::size_t i) {
  return field + "[" + std::to_string(i) + "]";
}

std::optional<std::string> optional_string(const json& object, std::string_view key, const std::string& field) {
  const auto it = object.find(key);
  if (it == object.end() || it->is_null()) return std::nullopt;
  if (!it->is_string()) fail(child(field, key), "a string", describe(*it));
  return it->get<std::string>();
}

std::string required_string(const json& object, std::string_view key, const std::string& field) {
  auto text = optional_string(object, key, field);
  if (!text) fail(child(field, key), "a string", "nothing");
  return *text;
}

bool optional_bool(const json& object, std::string_view key, const std::string& field) {
  const auto it = object.find(key);
  if (it == object.end() || it->is_null()) return false;
  if (!it->is_boolean()) fail(child(field, key), "true or false", describe(*it));
  return it->get<bool>();
}

const json& required_array(const json& object, std::string_view key, const std::string& field) {
  const auto it = object.find(key);
  if (it == object.end()) fail(child(field, key), "a list", "nothing");
  if (!it->is_array()) fail(child(field, key), "a list", describe(*it));
  return *it;
}

bool is_id(const std::string& id) {
  if (id.empty() || id.size() > 64) return false;
  for (const char c : id) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-')) return false;
  }
  return true;
}

bool is_nonfinite_word(const json& value) {
  if (!value.is_string()) return false;
  const auto& s = value.get_ref<const std::string&>();
  return s == "nan" || s == "inf" || s == "-inf";
}

// ---- the validated document -------------------------------------------------------------------

struct Figure {
  std::string id, title, text;
  json client;  // what report.js draws: the figure with defaults filled in, gaps as null
};

struct Table {
  std::string title, text;
  std::vector<std::string> columns;
  const json* rows = nullptr;  // validated: lists of numbers, strings, booleans or null
};

struct Section {
  std::string id, title, text;
  std::vector<std::string> warnings;
  std::vector<Table> tables;
  std::vector<Figure> figures;
};

struct Cell {
  enum class Kind { kNumber, kText, kNotMeasured } kind = Kind::kNotMeasured;
  double number = 0.0;
  std::string text;
};

struct Unit {
  std::string id;
  std::string name;  // the unit's name when results.json gives one, else its id
  std::optional<std::string> not_analysed;  // "file: reason" of a unit that could not be analysed
  bool accepted = false;
  bool marginal = false;  // no check failed, one is marginal (results.json's `marginal`; absent: false)
  std::vector<std::string> reasons;
  std::vector<Cell> cells;  // one per kColumns entry
};

struct Column {
  const char* title;
  const char* unit;
  std::array<const char*, 2> path;  // second entry nullptr for a top-level key
};

// The key figures of the acceptance table, where CLI.md puts them in results.json.
constexpr std::array<Column, 11> kColumns{{
    {"Flatness", "um", {"flatness_um", nullptr}},
    {"C sensor", "uF", {"capacitance_uF", "sensor"}},
    {"C actuator", "uF", {"capacitance_uF", "actuator"}},
    {"Stroke", "um", {"stroke_um", nullptr}},
    {"k1", "N/um", {"stiffness_N_per_um", "k1"}},
    {"k2", "N/um", {"stiffness_N_per_um", "k2"}},
    {"k (resonance)", "N/um", {"stiffness_N_per_um", "resonance"}},
    {"Resonance", "Hz", {"frf", "resonance_Hz"}},
    {"Anti-resonance", "Hz", {"frf", "antiresonance_Hz"}},
    {"Static gain", "um/V", {"frf", "static_gain_um_per_V"}},
    {"HPF corner", "Hz", {"hpf_corner_Hz", nullptr}},
}};

struct Document {
  std::string title, subtitle;
  std::vector<Unit> units;
  const json* batch = nullptr;
  const json* iff_optimal_gain = nullptr;
  std::vector<Section> sections;
  std::size_t figure_count = 0;
};

Cell read_cell(const json& unit, const Column& column, const std::string& field) {
  const json* value = &unit;
  std::string path = field;
  for (const char* key : column.path) {
    if (key == nullptr) break;
    if (!value->is_object()) fail(path, "an object", describe(*value));
    const auto it = value->find(key);
    path = child(path, key);
    if (it == value->end() || it->is_null()) return {};
    value = &*it;
  }
  Cell cell;
  if (value->is_number()) {
    cell.kind = Cell::Kind::kNumber;
    cell.number = value->get<double>();
  } else if (value->is_string()) {
    cell.kind = Cell::Kind::kText;
    cell.text = value->get<std::string>();
  } else {
    fail(path, "a number, a string or null (not measured)", describe(*value));
  }
  return cell;
}

std::vector<Unit> read_units(const json& results) {
  const std::string field = "results";
  const json& list = required_array(results, "units", field);
  std::vector<Unit> units;
  std::map<std::string, std::size_t> seen;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string at = element(child(field, "units"), i);
    const json& u = list[i];
    require_object(u, at, {});
    Unit unit;
    const auto id = u.find("id");
    if (id == u.end()) fail(child(at, "id"), "a string or a number", "nothing");
    if (id->is_string()) {
      unit.id = id->get<std::string>();
    } else if (id->is_number_integer() || id->is_number_unsigned()) {
      unit.id = id->dump();
    } else {
      fail(child(at, "id"), "a string or an integer", describe(*id));
    }
    if (const auto [it, fresh] = seen.emplace(unit.id, i); !fresh) {
      fail(child(at, "id"), "an id used once",
           describe(*id) + ", already the id of " + element(child(field, "units"), it->second));
    }
    const auto accepted = u.find("accepted");
    if (accepted == u.end() || !accepted->is_boolean()) {
      fail(child(at, "accepted"), "true or false", accepted == u.end() ? "nothing" : describe(*accepted));
    }
    unit.accepted = accepted->get<bool>();
    if (const auto m = u.find("marginal"); m != u.end() && !m->is_null()) {
      if (!m->is_boolean()) fail(child(at, "marginal"), "true or false", describe(*m));
      unit.marginal = m->get<bool>();
      if (unit.marginal && unit.accepted) fail(child(at, "marginal"), "false for an accepted unit", "true");
    }
    unit.name = optional_string(u, "name", at).value_or(unit.id);
    if (const auto na = u.find("not_analysed"); na != u.end() && !na->is_null()) {
      const std::string nat = child(at, "not_analysed");
      require_object(*na, nat, {"file", "key", "reason"});
      const std::string file = optional_string(*na, "file", nat).value_or("");
      const std::string reason = required_string(*na, "reason", nat);
      // The file first, unless the reason already names it.
      unit.not_analysed = file.empty() || reason.find(file) != std::string::npos ? reason : file + ": " + reason;
      if (unit.accepted) fail(child(at, "accepted"), "false for a unit that was not analysed", "true");
    }
    if (const auto reasons = u.find("reasons"); reasons != u.end() && !reasons->is_null()) {
      if (!reasons->is_array()) fail(child(at, "reasons"), "a list of strings", describe(*reasons));
      for (std::size_t k = 0; k < reasons->size(); ++k) {
        const json& r = (*reasons)[k];
        if (!r.is_string()) fail(element(child(at, "reasons"), k), "a string", describe(r));
        unit.reasons.push_back(r.get<std::string>());
      }
    }
    if (!unit.accepted && unit.reasons.empty()) {
      fail(child(at, "reasons"), "at least one reason for a rejected or marginal unit", "none");
    }
    for (const Column& column : kColumns) unit.cells.push_back(read_cell(u, column, at));
    units.push_back(std::move(unit));
  }
  return units;
}

// A numeric series for the client: numbers stay, null and "nan"/"inf"/"-inf" become null.
json numeric_series(const json& values, const std::string& field) {
  json out = json::array();
  for (std::size_t i = 0; i < values.size(); ++i) {
    const json& v = values[i];
    if (v.is_number()) {
      out.push_back(v);
    } else if (v.is_null() || is_nonfinite_word(v)) {
      out.push_back(nullptr);
    } else {
      fail(element(field, i), "a number, null or one of \"nan\", \"inf\", \"-inf\"", describe(v));
    }
  }
  return out;
}

bool all_strings(const json& values) {
  if (values.empty()) return false;
  for (const json& v : values) {
    if (!v.is_string()) return false;
  }
  return true;
}

json read_trace(const json& t, const std::string& at, std::optional<bool>& category_x) {
  require_object(t, at, {"name", "x", "y", "y_upper", "mode", "dash", "group", "text"});
  json out = json::object();
  out["name"] = required_string(t, "name", at);
  const json& x = required_array(t, "x", at);
  const json& y = required_array(t, "y", at);
  if (y.size() != x.size()) {
    fail(child(at, "y"), std::to_string(x.size()) + " values (as many as x)", std::to_string(y.size()) + " values");
  }
  if (!x.empty()) {
    const bool category = all_strings(x);
    if (category_x && *category_x != category) {
      fail(child(at, "x"),
           *category_x ? "category names (strings), like the other traces of this figure"
                       : "numbers, like the other traces of this figure",
           category ? "strings" : "numbers");
    }
    category_x = category;
    out["x"] = category ? x : numeric_series(x, child(at, "x"));
  } else {
    out["x"] = json::array();
  }
  out["y"] = numeric_series(y, child(at, "y"));
  const std::string mode = optional_string(t, "mode", at).value_or("lines");
  if (mode != "lines" && mode != "markers" && mode != "lines+markers" && mode != "bars" && mode != "band") {
    fail(child(at, "mode"), "\"lines\", \"markers\", \"lines+markers\", \"bars\" or \"band\"", describe(t.at("mode")));
  }
  out["mode"] = mode;
  // A band is drawn between y (lower edge) and y_upper, which only a band has.
  if (mode == "band") {
    const json& upper = required_array(t, "y_upper", at);
    if (upper.size() != x.size()) fail(child(at, "y_upper"), std::to_string(x.size()) + " values (as many as x)", std::to_string(upper.size()) + " values");
    out["y_upper"] = numeric_series(upper, child(at, "y_upper"));
  } else if (t.contains("y_upper")) {
    fail(child(at, "y_upper"), "no y_upper (only a trace of mode \"band\" has one)", describe(t.at("y_upper")));
  }
  out["dash"] = optional_bool(t, "dash", at);
  if (auto group = optional_string(t, "group", at)) out["group"] = *group;
  if (const auto text = t.find("text"); text != t.end() && !text->is_null()) {
    const std::string field = child(at, "text");
    if (!text->is_array()) fail(field, "a list of strings (hover labels, one per point)", describe(*text));
    if (text->size() != x.size()) {
      fail(field, std::to_string(x.size()) + " labels (as many as x)", std::to_string(text->size()) + " labels");
    }
    for (std::size_t i = 0; i < text->size(); ++i) {
      if (!(*text)[i].is_string() && !(*text)[i].is_null()) fail(element(field, i), "a string or null", describe((*text)[i]));
    }
    out["text"] = *text;
  }
  return out;
}

Figure read_figure(const json& f, const std::string& at) {
  require_object(f, at, {"id", "title", "text", "x_label", "x_log", "panels"});
  Figure figure;
  figure.id = required_string(f, "id", at);
  if (!is_id(figure.id)) {
    fail(child(at, "id"), "1 to 64 characters among a-z, 0-9 and -", describe(f.at("id")));
  }
  figure.title = required_string(f, "title", at);
  figure.text = optional_string(f, "text", at).value_or("");
  const bool x_log = optional_bool(f, "x_log", at);
  const json& panels = required_array(f, "panels", at);
  if (panels.empty()) fail(child(at, "panels"), "at least one panel", "an empty list");
  std::optional<bool> category_x;
  json client_panels = json::array();
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const std::string pat = element(child(at, "panels"), p);
    const json& panel = panels[p];
    require_object(panel, pat, {"y_label", "y_log", "traces"});
    json client_panel = json::object();
    client_panel["y_label"] = optional_string(panel, "y_label", pat).value_or("");
    client_panel["y_log"] = optional_bool(panel, "y_log", pat);
    json traces = json::array();
    const json& list = required_array(panel, "traces", pat);
    for (std::size_t k = 0; k < list.size(); ++k) {
      traces.push_back(read_trace(list[k], element(child(pat, "traces"), k), category_x));
    }
    client_panel["traces"] = std::move(traces);
    client_panels.push_back(std::move(client_panel));
  }
  if (x_log && category_x.value_or(false)) {
    fail(child(at, "x_log"), "false for a figure whose x are category names", "true");
  }
  figure.client = json::object();
  figure.client["id"] = figure.id;
  figure.client["x_label"] = optional_string(f, "x_label", at).value_or("");
  figure.client["x_log"] = x_log;
  figure.client["x_category"] = category_x.value_or(false);
  figure.client["panels"] = std::move(client_panels);
  return figure;
}

Table read_table(const json& t, const std::string& at) {
  require_object(t, at, {"title", "text", "columns", "rows"});
  Table table;
  table.title = required_string(t, "title", at);
  table.text = optional_string(t, "text", at).value_or("");
  const json& columns = required_array(t, "columns", at);
  if (columns.empty()) fail(child(at, "columns"), "at least one column", "an empty list");
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (!columns[i].is_string()) fail(element(child(at, "columns"), i), "a string", describe(columns[i]));
    table.columns.push_back(columns[i].get<std::string>());
  }
  const json& rows = required_array(t, "rows", at);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const std::string rat = element(child(at, "rows"), r);
    if (!rows[r].is_array()) fail(rat, "a list of cells", describe(rows[r]));
    if (rows[r].size() != columns.size()) {
      fail(rat, std::to_string(columns.size()) + " cells (one per column)", std::to_string(rows[r].size()) + " cells");
    }
    for (std::size_t c = 0; c < rows[r].size(); ++c) {
      // A cell is a scalar, or a flat list of them (a declared field holding several numbers).
      const json& cell = rows[r][c];
      const bool flat_list = cell.is_array() && std::none_of(cell.begin(), cell.end(), [](const json& x) { return x.is_structured(); });
      if (cell.is_structured() && !flat_list) fail(element(rat, c), "a number, a string, true, false, null or a flat list of them", describe(cell));
    }
  }
  table.rows = &rows;
  return table;
}

Document read_document(const json& document) {
  const std::string root = "document";
  if (!document.is_object()) throw InputError(kSource, root, "a JSON object", describe(document));
  Document doc;
  for (const auto& item : document.items()) {
    const auto& k = item.key();
    if (k != "title" && k != "subtitle" && k != "results" && k != "sections") {
      fail(k, "one of the keys title, subtitle, results, sections", "an unknown key");
    }
  }
  const auto title = document.find("title");
  if (title == document.end() || !title->is_string() || title->get<std::string>().empty()) {
    fail("title", "a non-empty string", title == document.end() ? "nothing" : describe(*title));
  }
  doc.title = title->get<std::string>();
  if (const auto sub = document.find("subtitle"); sub != document.end() && !sub->is_null()) {
    if (!sub->is_string()) fail("subtitle", "a string", describe(*sub));
    doc.subtitle = sub->get<std::string>();
  }
  const auto results = document.find("results");
  if (results == document.end()) fail("results", "an object (the results.json document)", "nothing");
  if (!results->is_object()) fail("results", "an object (the results.json document)", describe(*results));
  doc.units = read_units(*results);
  if (const auto batch = results->find("batch"); batch != results->end() && !batch->is_null()) {
    if (!batch->is_object()) fail("results.batch", "an object", describe(*batch));
    doc.batch = &*batch;
  }
  if (const auto iff = results->find("iff"); iff != results->end() && iff->is_object()) {
    if (const auto g = iff->find("optimal_gain"); g != iff->end() && !g->is_null()) doc.iff_optimal_gain = &*g;
  }

  const auto sections = document.find("sections");
  if (sections == document.end()) fail("sections", "a list", "nothing");
  if (!sections->is_array()) fail("sections", "a list", describe(*sections));
  std::map<std::string, std::string> figure_ids, section_ids;
  for (std::size_t s = 0; s < sections->size(); ++s) {
    const std::string at = element("sections", s);
    const json& sj = (*sections)[s];
    require_object(sj, at, {"id", "title", "text", "warnings", "tables", "figures"});
    Section section;
    section.title = required_string(sj, "title", at);
    section.text = optional_string(sj, "text", at).value_or("");
    if (const auto w = sj.find("warnings"); w != sj.end() && !w->is_null()) {
      if (!w->is_array()) fail(child(at, "warnings"), "a list of strings", describe(*w));
      for (std::size_t i = 0; i < w->size(); ++i) {
        if (!(*w)[i].is_string()) fail(element(child(at, "warnings"), i), "a string", describe((*w)[i]));
        section.warnings.push_back((*w)[i].get<std::string>());
      }
    }
    if (const auto tables = sj.find("tables"); tables != sj.end() && !tables->is_null()) {
      if (!tables->is_array()) fail(child(at, "tables"), "a list", describe(*tables));
      for (std::size_t i = 0; i < tables->size(); ++i) section.tables.push_back(read_table((*tables)[i], element(child(at, "tables"), i)));
    }
    if (auto id = optional_string(sj, "id", at)) {
      if (!is_id(*id)) fail(child(at, "id"), "1 to 64 characters among a-z, 0-9 and -", describe(sj.at("id")));
      section.id = *id;
    } else {
      section.id = "section-" + std::to_string(s + 1);
    }
    if (const auto [it, fresh] = section_ids.emplace(section.id, at); !fresh) {
      fail(child(at, "id"), "an id used once", "\"" + section.id + "\", already the id of " + it->second);
    }
    const json& figures = required_array(sj, "figures", at);
    for (std::size_t f = 0; f < figures.size(); ++f) {
      const std::string fat = element(child(at, "figures"), f);
      Figure figure = read_figure(figures[f], fat);
      if (const auto [it, fresh] = figure_ids.emplace(figure.id, fat); !fresh) {
        fail(child(fat, "id"), "an id used once", "\"" + figure.id + "\", already the id of " + it->second);
      }
      section.figures.push_back(std::move(figure));
      ++doc.figure_count;
    }
    doc.sections.push_back(std::move(section));
  }
  return doc;
}

// ---- writing ----------------------------------------------------------------------------------

// Text for HTML element content and attribute values.
std::string escape(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 16);
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string number(double value, int significant) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  std::array<char, 64> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), value, std::chars_format::general, significant);
  return {buf.data(), r.ptr};
}

// Compact JSON (numbers to 9 significant digits, non-finite as null) for the <script> element.
void append_json(std::string& out, const json& value) {
  switch (value.type()) {
    case json::value_t::null:
      out += "null";
      break;
    case json::value_t::boolean:
      out += value.get<bool>() ? "true" : "false";
      break;
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
      out += value.dump();
      break;
    case json::value_t::number_float: {
      const double v = value.get<double>();
      out += std::isfinite(v) ? number(v, 9) : "null";
      break;
    }
    case json::value_t::string:
      out += value.dump(-1, ' ', false, json::error_handler_t::replace);
      break;
    case json::value_t::array: {
      out += '[';
      bool first = true;
      for (const json& v : value) {
        if (!first) out += ',';
        first = false;
        append_json(out, v);
      }
      out += ']';
      break;
    }
    case json::value_t::object: {
      out += '{';
      bool first = true;
      for (const auto& item : value.items()) {
        if (!first) out += ',';
        first = false;
        out += json(item.key()).dump(-1, ' ', false, json::error_handler_t::replace);
        out += ':';
        append_json(out, item.value());
      }
      out += '}';
      break;
    }
    default:
      out += "null";
  }
}

// JSON that is safe inside <script>: <, > and & only occur inside JSON strings, where \u003c etc.
// mean the same; so do U+2028/U+2029, which older JavaScript parsers take for line ends.
std::string script_safe(const std::string& json_text) {
  std::string out;
  out.reserve(json_text.size() + json_text.size() / 50);
  for (std::size_t i = 0; i < json_text.size(); ++i) {
    const char c = json_text[i];
    if (c == '<') {
      out += "\\u003c";
    } else if (c == '>') {
      out += "\\u003e";
    } else if (c == '&') {
      out += "\\u0026";
    } else if (c == '\xE2' && i + 2 < json_text.size() && json_text[i + 1] == '\x80' &&
               (json_text[i + 2] == '\xA8' || json_text[i + 2] == '\xA9')) {
      out += json_text[i + 2] == '\xA8' ? "\\u2028" : "\\u2029";
      i += 2;
    } else {
      out += c;
    }
  }
  return out;
}

// Plain text as paragraphs: a blank line starts a new one.
void paragraphs(std::string& out, const std::string& text, const char* attributes) {
  std::size_t begin = 0;
  while (begin < text.size()) {
    auto end = text.find("\n\n", begin);
    if (end == std::string::npos) end = text.size();
    const auto first = text.find_first_not_of(" \t\r\n", begin);
    if (first != std::string::npos && first < end) {
      out +=
          std::string("<p") + attributes + ">" + escape(std::string_view(text).substr(begin, end - begin)) + "</p>\n";
    }
    begin = end + 2;
  }
}

// A number for people: `significant` digits, positional between 0.001 and 1e6 (249000, 1.70,
// 0.00558), scientific outside (1.2e-05).
std::string readable(double value, int significant = 3) {
  if (!std::isfinite(value)) return number(value, significant);
  if (value == 0.0) return "0";
  // The exponent of the value once rounded (9.9996 -> 10.0, not 10.00).
  const double magnitude = std::abs(std::stod(number(value, significant)));
  if (magnitude < 1e-3 || magnitude >= 1e6) return number(value, significant);
  const int exponent = static_cast<int>(std::floor(std::log10(magnitude)));
  const int decimals = std::max(0, significant - 1 - exponent);
  const double scale = std::pow(10.0, exponent - significant + 1);
  const double rounded = decimals > 0 ? value : std::round(value / scale) * scale;
  std::array<char, 64> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), rounded, std::chars_format::fixed, decimals);
  return {buf.data(), r.ptr};
}

// A list of numbers (a declared field that holds several, e.g. time constants) in one cell.
std::string cell_list(const json& v) {
  std::string out;
  for (const json& x : v) {
    if (!out.empty()) out += ", ";
    out += x.is_number_float() ? readable(x.get<double>()) : x.is_string() ? escape(x.get<std::string>()) : escape(x.dump());
  }
  return out;
}

std::string table_cell(const json& v) {
  if (v.is_array()) return "<td class=\"num\">" + cell_list(v) + "</td>";
  if (v.is_null()) return "<td class=\"nm\" title=\"not available\">&ndash;</td>";
  if (v.is_boolean()) return std::string("<td>") + (v.get<bool>() ? "yes" : "no") + "</td>";
  if (v.is_number_integer() || v.is_number_unsigned()) return "<td class=\"num\">" + v.dump() + "</td>";
  if (v.is_number()) return "<td class=\"num\">" + readable(v.get<double>()) + "</td>";
  if (is_nonfinite_word(v)) return "<td class=\"nm\">" + escape(v.get<std::string>()) + "</td>";
  return "<td>" + escape(v.get<std::string>()) + "</td>";
}

void table_html(std::string& out, const Table& t) {
  out += "<div class=\"pb-table\"><h3>" + escape(t.title) + "</h3>\n";
  paragraphs(out, t.text, " class=\"caption\"");
  out += "<div class=\"table-wrap\"><table class=\"params\"><thead><tr>";
  for (const auto& c : t.columns) out += "<th>" + escape(c) + "</th>";
  out += "</tr></thead><tbody>\n";
  for (const json& row : *t.rows) {
    out += "<tr>";
    for (const json& v : row) out += table_cell(v);
    out += "</tr>\n";
  }
  out += "</tbody></table></div></div>\n";
}

std::string cell_html(const Cell& cell) {
  switch (cell.kind) {
    case Cell::Kind::kNumber:
      return "<td class=\"num\">" + number(cell.number, 4) + "</td>";
    case Cell::Kind::kText:
      return "<td class=\"num\">" + escape(cell.text) + "</td>";
    case Cell::Kind::kNotMeasured:
      break;
  }
  return "<td class=\"nm\" title=\"not measured\">&ndash;</td>";
}

void acceptance_table(std::string& out, const Document& doc) {
  out += "<section id=\"acceptance\"><h2>1. Acceptance</h2>\n";
  if (doc.units.empty()) {
    out += "<p>The results list no unit.</p></section>\n";
    return;
  }
  out += "<div class=\"table-wrap\"><table class=\"acceptance\">\n<thead><tr><th>Unit</th><th>Result</th>";
  for (const Column& c : kColumns) {
    out += "<th>" + escape(c.title) + "<span class=\"unit\">[" + escape(c.unit) + "]</span></th>";
  }
  out += "<th>Reasons</th></tr></thead>\n<tbody>\n";
  for (const Unit& u : doc.units) {
    const char* status = u.accepted ? "accepted" : u.not_analysed ? "not analysed" : u.marginal ? "marginal" : "rejected";
    out += u.not_analysed ? std::string("<tr class=\"not-analysed\">") : "<tr class=\"" + std::string(status) + "\">";
    out += "<th scope=\"row\">" + escape(u.name) + "</th>";
    out += "<td class=\"status\">" + std::string(status) + "</td>";
    for (const Cell& c : u.cells) out += cell_html(c);
    out += "<td class=\"reasons\">";
    if (!u.reasons.empty()) {
      out += "<ul>";
      for (const auto& r : u.reasons) out += "<li>" + escape(r) + "</li>";
      out += "</ul>";
    }
    out += "</td></tr>\n";
  }
  out +=
      "</tbody></table></div>\n<p class=\"note\">&ndash; not measured. Numbers to 4 significant digits; "
      "results.json has them in full.</p>\n</section>\n";
}

// Counts, and the units rejected or not analysed by name (the batch's tables are in the report's
// "Batch comparison" section).
void batch_summary(std::string& out, const Document& doc) {
  std::size_t accepted = 0;
  std::vector<const Unit*> rejected, marginal, not_analysed;
  for (const Unit& u : doc.units) {
    if (u.accepted) {
      ++accepted;
    } else {
      (u.not_analysed ? not_analysed : u.marginal ? marginal : rejected).push_back(&u);
    }
  }
  const auto names = [](const std::vector<const Unit*>& list) {
    std::string text;
    for (const Unit* u : list) text += (text.empty() ? ": " : ", ") + escape(u->name);
    return text;
  };
  out += "<section id=\"batch\"><h2>2. Batch summary</h2>\n<dl class=\"summary\">";
  out += "<dt>Units</dt><dd>" + std::to_string(doc.units.size()) + "</dd>";
  out += "<dt>Accepted</dt><dd>" + std::to_string(accepted) + "</dd>";
  if (!marginal.empty()) {
    out += "<dt>Marginal</dt><dd>" + std::to_string(marginal.size()) + names(marginal) +
           " (a limit within the value's 95 % interval: neither conformity nor nonconformity is proved, ISO 14253-1)</dd>";
  }
  out += "<dt>Rejected</dt><dd>" + std::to_string(rejected.size()) + names(rejected) + "</dd>";
  if (!not_analysed.empty()) {
    out += "<dt>Not analysed</dt><dd>" + std::to_string(not_analysed.size()) + names(not_analysed) + "<ul>";
    for (const Unit* u : not_analysed) out += "<li>" + escape(u->name) + ": " + escape(*u->not_analysed) + "</li>";
    out += "</ul></dd>";
  }
  if (doc.iff_optimal_gain != nullptr) {
    out += "<dt>IFF optimal gain g</dt><dd>" + (doc.iff_optimal_gain->is_number() ? readable(doc.iff_optimal_gain->get<double>())
                                                                                    : escape(doc.iff_optimal_gain->dump())) +
           " (a factor on the controller of eq. 2.4)</dd>";
  }
  out += "</dl>\n";
  if (!rejected.empty()) {
    out += "<p>Why each rejected unit is rejected: the Reasons column of the acceptance table.</p>\n";
  }
  out += "</section>\n";
}

void contents(std::string& out, const Document& doc) {
  out +=
      "<nav class=\"toc\" id=\"contents\"><h2>Contents</h2><ol>"
      "<li><a href=\"#acceptance\">Acceptance</a></li><li><a href=\"#batch\">Batch summary</a></li>";
  for (const Section& s : doc.sections) {
    out += "<li><a href=\"#sec-" + escape(s.id) + "\">" + escape(s.title) + "</a>";
    if (!s.figures.empty()) {
      out += "<ol>";
      for (const Figure& f : s.figures) {
        out += "<li><a href=\"#figure-" + escape(f.id) + "\">" + escape(f.title) + "</a></li>";
      }
      out += "</ol>";
    }
    out += "</li>";
  }
  out += "</ol></nav>\n";
}

}  // namespace

std::string render_html(const nlohmann::json& document) {
  const Document doc = read_document(document);
  const std::string_view library = plotting_library();
  // Inlined verbatim: the library must not end its own <script> element (checked by the tests).
  std::string out;
  out.reserve(library.size() + 64 * 1024);
  out +=
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<meta name=\"generator\" content=\"piezobench ";
  out += kVersion;
  out += ", plotly.js ";
  out += plotting_library_version();
  out += "\">\n<title>" + escape(doc.title) + "</title>\n<style>\n";
  out += report_style();
  out += "</style>\n</head>\n<body>\n<header>\n<h1>" + escape(doc.title) + "</h1>\n";
  if (!doc.subtitle.empty()) out += "<p class=\"subtitle\">" + escape(doc.subtitle) + "</p>\n";
  out += "<p id=\"pb-status\" data-state=\"pending\" data-figures=\"" + std::to_string(doc.figure_count) +
         "\">Drawing " + std::to_string(doc.figure_count) +
         " plots&hellip; (the plots need JavaScript; everything else reads without it)</p>\n</header>\n";
  contents(out, doc);
  out += "<main>\n";
  acceptance_table(out, doc);
  batch_summary(out, doc);
  json client = json::object();
  client["figures"] = json::array();
  int number_of_section = 3;
  for (const Section& s : doc.sections) {
    out += "<section class=\"report-section\" id=\"sec-" + escape(s.id) + "\"><h2>" +
           std::to_string(number_of_section++) + ". " + escape(s.title) + "</h2>\n";
    paragraphs(out, s.text, "");
    for (const auto& w : s.warnings) out += "<p class=\"warning\" role=\"alert\">" + escape(w) + "</p>\n";
    for (const Table& t : s.tables) table_html(out, t);
    if (!s.figures.empty()) {
      out +=
          "<p class=\"hint\">Drag to zoom, double-click to reset, click a legend entry to hide or show a "
          "unit in every panel, hover for values.</p>\n";
    }
    for (const Figure& f : s.figures) {
      out += "<figure class=\"pb-figure\" id=\"figure-" + escape(f.id) + "\"><h3>" + escape(f.title) + "</h3>\n";
      paragraphs(out, f.text, " class=\"caption\"");
      out += "<div class=\"pb-plot\" id=\"fig-" + escape(f.id) + "\"></div></figure>\n";
      client["figures"].push_back(f.client);
    }
    out += "</section>\n";
  }
  out += "</main>\n<script type=\"application/json\" id=\"pb-data\">";
  std::string data;
  append_json(data, client);
  out += script_safe(data);
  out += "</script>\n<script>\n";
  out += library;
  out += "\n</script>\n<script>\n";
  out += report_script();
  out += "</script>\n</body>\n</html>\n";
  return out;
}

void write_html(const nlohmann::json& document, const std::filesystem::path& file) {
  io::write_text_atomically(file, render_html(document));
}

}  // namespace piezobench::report
