#include "piezobench/campaign/part.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <utility>

#include "piezobench/core/error.hpp"
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/version.hpp"
#include "part_codec.hpp"

namespace piezobench::campaign {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kFormat = "piezobench campaign part";

using part_codec::decode, part_codec::encode, part_codec::PartReader, part_codec::Where;

std::string generator() { return std::string("piezobench ") + kVersion; }

std::string units_text(const std::vector<int>& ids) {
  std::string s;
  for (const int id : ids) s += (s.empty() ? "" : ", ") + std::to_string(id);
  return s;
}

}  // namespace

// ------------------------------------------------------------------------------------ public

std::string campaign_hash(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "campaign", "a readable campaign file", "cannot be opened");
  std::uint64_t h = 14695981039346656037ULL;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 1099511628211ULL;
    }
  }
  return fmt::format("fnv1a64:{:016x}", h);
}

std::vector<std::size_t> part_indices(const Campaign& c, int k, int n) {
  if (n < 1 || k < 1 || k > n) throw InputError("", "--part", "K/N with 1 <= K <= N", fmt::format("{}/{}", k, n));
  std::vector<std::size_t> out;
  for (std::size_t i = static_cast<std::size_t>(k - 1); i < c.units.size(); i += static_cast<std::size_t>(n)) out.push_back(i);
  return out;
}

std::vector<std::size_t> unit_indices(const Campaign& c, const std::vector<int>& ids, const std::string& option) {
  std::vector<int> all;
  for (const auto& u : c.units) all.push_back(u.id);
  for (const int id : ids) {
    if (std::find(all.begin(), all.end(), id) == all.end()) {
      throw InputError(c.file.string(), option, "unit ids of the campaign (" + units_text(all) + ")", std::to_string(id));
    }
  }
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < c.units.size(); ++i) {
    if (std::find(ids.begin(), ids.end(), c.units[i].id) != ids.end()) out.push_back(i);
  }
  return out;
}

json typed_unit_json(const UnitAnalysis& unit) { return encode(unit); }

UnitAnalysis typed_unit_from_json(const json& j, const std::string& source, const std::string& path) {
  UnitAnalysis u;
  decode(j, u, Where{source, path});
  return u;
}

json part_json(const Campaign& c, const std::vector<UnitAnalysis>& units) {
  json ids = json::array();
  for (const auto& u : c.units) ids.push_back(u.id);
  json list = json::array();
  for (const auto& u : units) list.push_back(typed_unit_json(u));
  return {{"format", kFormat},
          {"format_version", kPartFormatVersion},
          {"generator", generator()},
          {"campaign", c.file.string()},
          {"campaign_path", fs::absolute(c.file).lexically_normal().string()},
          {"campaign_hash", campaign_hash(c.file)},
          {"campaign_units", ids},
          {"units", list}};
}

fs::path write_part(const Campaign& c, const std::vector<UnitAnalysis>& units, const fs::path& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir)) {
    throw InputError(out_dir.string(), "--out", "a folder that can be created", ec ? ec.message() : "not a folder");
  }
  const fs::path file = out_dir / "part.json";
  io::write_text_atomically(file, part_json(c, units).dump() + "\n");
  return file;
}

CampaignPart read_part(const fs::path& path) {
  const fs::path file = fs::is_directory(path) ? path / "part.json" : path;
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    throw InputError(path.string(), "part.json", "a partial result of `piezobench run --part K/N` or `--units LIST`",
                     fs::exists(path) ? "no part.json in it" : "no such file or folder");
  }
  std::ostringstream text;
  text << in.rdbuf();
  json doc;
  try {
    doc = json::parse(text.str());
  } catch (const json::exception& e) {
    throw InputError(name, "", "a JSON document (part.json)", e.what());
  }
  const Where top{name, ""};
  if (!doc.is_object() || !doc.contains("format") || doc["format"] != kFormat) {
    throw InputError(name, "format", fmt::format("\"{}\" (a part.json of `piezobench run --part/--units`)", kFormat),
                     doc.is_object() && doc.contains("format") ? doc["format"].dump() : "no format key");
  }
  int version = 0;
  PartReader r{doc, top};
  r("format_version", version);
  if (version != kPartFormatVersion) throw InputError(name, "format_version", std::to_string(kPartFormatVersion), std::to_string(version));
  CampaignPart p;
  p.file = file;
  r("generator", p.generator);
  if (p.generator != generator()) {
    throw InputError(name, "generator", generator() + " (parts are merged by the program that wrote them)", p.generator);
  }
  std::string campaign_path;
  r("campaign", p.campaign);
  r("campaign_path", campaign_path);
  p.campaign_path = campaign_path;
  r("campaign_hash", p.campaign_hash);
  r("campaign_units", p.campaign_units);
  r("units", p.units);
  return p;
}

std::vector<UnitAnalysis> merge_parts(const Campaign& c, const std::vector<CampaignPart>& parts) {
  const std::string campaign_file = c.file.string();
  const std::string hash = campaign_hash(c.file);
  std::map<int, std::pair<const UnitAnalysis*, const CampaignPart*>> found;
  for (const CampaignPart& p : parts) {
    const std::string name = p.file.string();
    if (p.campaign_hash != hash) {
      throw InputError(name, "campaign_hash",
                       fmt::format("{} (campaign {} as it is now)", hash, campaign_file),
                       fmt::format("{} (campaign {}): a part of another campaign, or of this file before it changed", p.campaign_hash, p.campaign));
    }
    for (std::size_t i = 0; i < p.units.size(); ++i) {
      const UnitAnalysis& u = p.units[i];
      const bool known = std::any_of(c.units.begin(), c.units.end(), [&](const UnitSpec& s) { return s.id == u.id; });
      if (!known) throw InputError(name, fmt::format("units[{}].id", i), "a unit of campaign " + campaign_file, std::to_string(u.id));
      const auto [it, inserted] = found.emplace(u.id, std::pair{&u, &p});
      if (!inserted) {
        throw InputError(name, fmt::format("units[{}].id", i), "a unit no other part holds",
                         fmt::format("unit {} ({}), also in {}", u.id, u.name, it->second.second->file.string()));
      }
    }
  }
  std::vector<UnitAnalysis> out;
  std::vector<int> missing;
  for (const UnitSpec& s : c.units) {
    const auto it = found.find(s.id);
    if (it == found.end()) {
      missing.push_back(s.id);
    } else {
      out.push_back(*it->second.first);
    }
  }
  if (!missing.empty()) {
    throw InputError(campaign_file, "units", fmt::format("every unit of the campaign in one of the {} parts", parts.size()),
                     fmt::format("unit{} {} in none of them", missing.size() > 1 ? "s" : "", units_text(missing)));
  }
  return out;
}

}  // namespace piezobench::campaign
