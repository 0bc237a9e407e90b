#include "piezobench/station/certificate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "piezobench/station/measurements.hpp"

namespace piezobench::station {

namespace {

std::string escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string number(const std::optional<double>& v) { return v ? fmt::format("{:.6g}", *v) : std::string(); }

constexpr const char* kStyle =
    "<style>body{font-family:sans-serif;margin:2em;max-width:60em}table{border-collapse:collapse;margin:0.5em 0}"
    "td,th{border:1px solid #bbb;padding:2px 6px;font-size:90%;text-align:left}.pass{color:#176317}.marginal{color:#a66300}"
    ".fail{color:#b00020;font-weight:bold}code{font-size:85%}@media print{body{margin:0}}</style>";

// A horizontal gauge: the limits as a band, the value as a mark.
std::string gauge(const MeasurementRow& m) {
  if (!m.value || (!m.min && !m.max)) return "";
  const double lo_limit = m.min.value_or(m.max.value_or(0.0)), hi_limit = m.max.value_or(m.min.value_or(0.0));
  double lo = std::min({lo_limit, hi_limit, *m.value}), hi = std::max({lo_limit, hi_limit, *m.value});
  const double pad = 0.15 * std::max(hi - lo, std::abs(hi) * 0.05 + 1e-300);
  lo -= pad;
  hi += pad;
  const auto x = [&](double v) { return 10.0 + 280.0 * (v - lo) / (hi - lo); };
  const double a = m.min ? x(*m.min) : 10.0, b = m.max ? x(*m.max) : 290.0;
  return fmt::format(
      "<svg width=\"300\" height=\"22\" viewBox=\"0 0 300 22\"><rect x=\"10\" y=\"8\" width=\"280\" height=\"6\" fill=\"#f3d0d0\"/>"
      "<rect x=\"{:.1f}\" y=\"8\" width=\"{:.1f}\" height=\"6\" fill=\"#cfe8cf\"/><line x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"2\" y2=\"20\" "
      "stroke=\"#222\" stroke-width=\"2\"/></svg>",
      a, std::max(0.0, b - a), x(*m.value), x(*m.value));
}

std::string phase_table(const std::vector<PhaseTryRow>& tries) {
  std::string h = "<table><tr><th>phase</th><th>try</th><th>status</th><th>verdict</th><th>measurement</th><th>value</th><th>unit</th>"
                  "<th>min</th><th>max</th><th>verdict</th><th></th><th>reason</th></tr>\n";
  for (const PhaseTryRow& t : tries) {
    const std::size_t rows = std::max<std::size_t>(1, t.measurements.size());
    for (std::size_t i = 0; i < rows; ++i) {
      h += "<tr>";
      if (i == 0) {
        h += fmt::format("<td rowspan=\"{0}\">{1}</td><td rowspan=\"{0}\">{2}</td><td rowspan=\"{0}\">{3}</td><td rowspan=\"{0}\" class=\"{4}\">{4}</td>",
                         rows, escape(t.phase_name), t.try_number, escape(t.status), escape(t.verdict));
      }
      if (i < t.measurements.size()) {
        const MeasurementRow& m = t.measurements[i];
        h += fmt::format("<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{}\">{}</td><td>{}</td><td>{}</td>", escape(m.name),
                         number(m.value), escape(m.unit), number(m.min), number(m.max), escape(m.verdict), escape(m.verdict), gauge(m),
                         escape(m.reason.empty() && i == 0 ? t.reason : m.reason));
      } else {
        h += fmt::format("<td colspan=\"7\"></td><td>{}</td>", escape(t.reason));
      }
      h += "</tr>\n";
    }
  }
  return h + "</table>\n";
}

std::string provenance(const QualificationRow& q, const std::vector<PhaseTryRow>& tries) {
  std::string h = fmt::format(
      "<h2>Provenance</h2><table><tr><th>software</th><td>{}</td></tr><tr><th>station</th><td>{} <code>sha256 {}</code></td></tr>"
      "<tr><th>bench file</th><td>{} <code>sha256 {}</code></td></tr><tr><th>operator</th><td>{}</td></tr>"
      "<tr><th>started, finished (UTC)</th><td>{} .. {}</td></tr></table>\n<h3>Raw files</h3><table><tr><th>phase</th><th>try</th><th>file</th>"
      "<th>bytes</th><th>sha256</th></tr>\n",
      escape(q.software_version), escape(q.station), escape(q.station_sha256), escape(q.bench_file), escape(q.bench_sha256),
      escape(q.operator_name), escape(q.started), escape(q.finished));
  for (const PhaseTryRow& t : tries) {
    for (const RawFileRow& f : t.raw_files) {
      h += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td><code>{}</code></td></tr>\n", escape(t.phase_name), t.try_number,
                       escape(f.path), f.bytes, escape(f.sha256));
    }
  }
  return h + "</table>\n";
}

}  // namespace

std::string certificate_html(const QualificationRow& q, const std::vector<PhaseTryRow>& tries) {
  std::string h = fmt::format("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Certificate {}</title>{}</head><body>\n",
                              escape(q.serial), kStyle);
  h += fmt::format("<h1>Qualification certificate: {}</h1>\n<p>Batch {}, qualification {} ({}), station {}.</p>\n", escape(q.serial),
                   escape(q.batch.empty() ? "-" : q.batch), q.id, escape(q.status), escape(q.station));
  h += fmt::format("<p style=\"font-size:140%\">Verdict: <span class=\"{0}\">{0}</span>{1}</p>\n", escape(q.verdict.empty() ? "none" : q.verdict),
                   q.deciding_phase.empty() ? std::string()
                                            : fmt::format(", decided by phase <b>{}</b>, {}", escape(q.deciding_phase), escape(q.deciding_measurement)));
  if (!q.reasons.empty()) {
    h += "<ul>";
    std::size_t start = 0;
    while (start <= q.reasons.size()) {
      const std::size_t end = std::min(q.reasons.find('\n', start), q.reasons.size());
      h += "<li>" + escape(q.reasons.substr(start, end - start)) + "</li>";
      start = end + 1;
    }
    h += "</ul>\n";
  }
  h += "<h2>Phases</h2>\n" + phase_table(tries) + provenance(q, tries);
  return h + "<p>Margin: a measurement is marginal when a limit lies within its uncertainty (docs/station.md).</p></body></html>\n";
}

const std::vector<std::string>& control_chart_quantities() {
  static const std::vector<std::string> q = {"stroke_um",       "k1_N_per_um",      "k_resonance_N_per_um", "capacitance_sensor_uF",
                                             "capacitance_actuator_uF", "resonance_Hz", "antiresonance_Hz", "hysteresis_relative_width"};
  return q;
}

std::vector<ControlChart> control_charts(const RecordStore& store, const std::string& batch, const std::vector<std::string>& quantities) {
  std::vector<ControlChart> out;
  for (const std::string& name : quantities) {
    ControlChart c;
    c.quantity = name;
    const MeasurementKind* kind = find_measurement(name);
    c.unit = kind ? kind->unit : "";
    c.points = store.history(name, batch);
    if (c.points.empty()) continue;
    double sum = 0.0;
    for (const HistoryPoint& p : c.points) sum += p.value;
    c.mean = sum / static_cast<double>(c.points.size());
    double ss = 0.0;
    for (const HistoryPoint& p : c.points) ss += (p.value - c.mean) * (p.value - c.mean);
    c.sigma = c.points.size() > 1 ? std::sqrt(ss / static_cast<double>(c.points.size() - 1)) : 0.0;
    c.min = c.points.back().min;
    c.max = c.points.back().max;
    for (const HistoryPoint& p : c.points) {
      c.marginal += p.verdict == "marginal" ? 1 : 0;
      c.failed += p.verdict == "fail" ? 1 : 0;
    }
    out.push_back(std::move(c));
  }
  return out;
}

namespace {

std::string chart_svg(const ControlChart& c) {
  constexpr double w = 640, h = 220, l = 60, r = 20, t = 15, b = 30;
  std::vector<double> ys = {c.mean - 3 * c.sigma, c.mean + 3 * c.sigma};
  for (const HistoryPoint& p : c.points) ys.push_back(p.value);
  if (c.min) ys.push_back(*c.min);
  if (c.max) ys.push_back(*c.max);
  double lo = *std::min_element(ys.begin(), ys.end()), hi = *std::max_element(ys.begin(), ys.end());
  const double pad = 0.05 * std::max(hi - lo, std::abs(hi) * 1e-6 + 1e-300);
  lo -= pad;
  hi += pad;
  const auto y = [&](double v) { return t + (h - t - b) * (hi - v) / (hi - lo); };
  const auto x = [&](std::size_t i) { return l + (w - l - r) * (c.points.size() > 1 ? static_cast<double>(i) / static_cast<double>(c.points.size() - 1) : 0.5); };
  std::string s = fmt::format("<svg width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#888\"/>",
                              w, h, w, h, l, t, w - l - r, h - t - b);
  const auto hline = [&](double v, const char* color, const char* dash, const std::string& label) {
    s += fmt::format("<line x1=\"{}\" x2=\"{}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" stroke-dasharray=\"{}\"/><text x=\"2\" y=\"{:.1f}\" font-size=\"10\">{}</text>",
                     l, w - r, y(v), y(v), color, dash, y(v) + 3, label);
  };
  if (c.min) hline(*c.min, "#b00020", "", fmt::format("min {:.4g}", *c.min));
  if (c.max) hline(*c.max, "#b00020", "", fmt::format("max {:.4g}", *c.max));
  hline(c.mean, "#555", "4 2", fmt::format("mean {:.4g}", c.mean));
  hline(c.mean - 3 * c.sigma, "#1f5fbf", "2 2", "-3 sigma");
  hline(c.mean + 3 * c.sigma, "#1f5fbf", "2 2", "+3 sigma");
  std::string path;
  for (std::size_t i = 0; i < c.points.size(); ++i) path += fmt::format("{}{:.1f},{:.1f}", i ? " L" : "M", x(i), y(c.points[i].value));
  s += "<path d=\"" + path + "\" fill=\"none\" stroke=\"#999\"/>";
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    const std::string& v = c.points[i].verdict;
    s += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3\" fill=\"{}\"><title>{} ({}): {:.6g} {}, {}</title></circle>", x(i),
                     y(c.points[i].value), v == "fail" ? "#b00020" : v == "marginal" ? "#e08a00" : "#176317", escape(c.points[i].serial),
                     escape(c.points[i].batch), c.points[i].value, escape(c.unit), escape(v));
  }
  return s + "</svg>";
}

}  // namespace

std::string control_charts_html(const std::vector<ControlChart>& charts, const std::string& title) {
  std::string h = fmt::format("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>{}</head><body><h1>{}</h1>\n",
                              escape(title), kStyle, escape(title));
  for (const ControlChart& c : charts) {
    h += fmt::format("<h2>{} ({})</h2><p>{} units, mean {:.6g}, sigma {:.4g}, mean +- 3 sigma [{:.6g}, {:.6g}]; limits [{}, {}]; {} marginal, {} failed</p>\n",
                     escape(c.quantity), escape(c.unit), c.points.size(), c.mean, c.sigma, c.mean - 3 * c.sigma, c.mean + 3 * c.sigma,
                     number(c.min), number(c.max), c.marginal, c.failed);
    h += chart_svg(c) + "\n";
  }
  return h + "</body></html>\n";
}

}  // namespace piezobench::station
