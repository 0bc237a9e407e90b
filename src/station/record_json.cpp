// The station database's rows as JSON (record_json.hpp).
#include "piezobench/station/record_json.hpp"

namespace piezobench::station {

namespace {
nlohmann::json optional_json(const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json measurements_json(const std::vector<MeasurementRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& m : rows) {
    out.push_back({{"name", m.name}, {"unit", m.unit}, {"value", optional_json(m.value)}, {"min", optional_json(m.min)},
                   {"max", optional_json(m.max)}, {"verdict", m.verdict}, {"reason", m.reason}, {"stop_on_fail", m.stop_on_fail}});
  }
  return out;
}

nlohmann::json qualification_json(const QualificationRow& q, const std::vector<PhaseTryRow>& tries) {
  nlohmann::json t = nlohmann::json::array();
  for (const auto& r : tries) {
    nlohmann::json files = nlohmann::json::array();
    for (const auto& f : r.raw_files) files.push_back({{"path", f.path}, {"campaign_key", f.campaign_key}, {"sha256", f.sha256}, {"bytes", f.bytes}});
    t.push_back({{"phase", r.phase_name}, {"index", r.phase_index}, {"try", r.try_number}, {"status", r.status}, {"verdict", r.verdict},
                 {"reason", r.reason}, {"started", r.started}, {"finished", r.finished}, {"measurements", measurements_json(r.measurements)},
                 {"raw_files", files}});
  }
  return {{"id", q.id}, {"serial", q.serial}, {"batch", q.batch}, {"station", q.station}, {"station_sha256", q.station_sha256},
          {"operator", q.operator_name}, {"bench_file", q.bench_file}, {"bench_sha256", q.bench_sha256},
          {"software_version", q.software_version}, {"started", q.started}, {"finished", q.finished}, {"status", q.status},
          {"verdict", q.verdict}, {"deciding_phase", q.deciding_phase}, {"deciding_measurement", q.deciding_measurement},
          {"certificate_sha256", q.certificate_sha256}, {"phase_tries", t}};
}

nlohmann::json control_charts_json(const std::vector<ControlChart>& charts) {
  nlohmann::json out = nlohmann::json::array();
  for (const ControlChart& c : charts) {
    nlohmann::json points = nlohmann::json::array();
    for (const HistoryPoint& p : c.points) points.push_back({{"serial", p.serial}, {"batch", p.batch}, {"value", p.value}, {"verdict", p.verdict}});
    out.push_back({{"quantity", c.quantity}, {"unit", c.unit}, {"min", optional_json(c.min)}, {"max", optional_json(c.max)}, {"mean", c.mean},
                   {"sigma", c.sigma}, {"marginal", c.marginal}, {"failed", c.failed}, {"points", points}});
  }
  return out;
}

}  // namespace piezobench::station
