#pragma once
// A partial result of a campaign (`run --units LIST` / `run --part K/N`, read back by `merge`):
// the typed results (results.hpp) of some of its units in OUT/part.json, with the campaign's hash
// so that parts of different campaigns are never mixed.
//
// results.json cannot be read back into the typed results: its numbers are scaled into the units
// its keys name and it holds no curves or FRFs. part.json is the typed results themselves, every
// field of UnitAnalysis under its C++ name, numbers in SI exactly as computed (shortest round-trip
// decimal; non-finite as "nan", "inf", "-inf"), so that the batch analyses, results.json,
// results.mat and report.html of `merge` are those of a single `run`. One exception: the state
// space `model` of a damped plant's vector fit is not carried (poles and residues are, which is
// what evaluate() uses). The fields are those of each struct's declaration (core/fields.hpp,
// beside the struct): a field declared there is written and read back with no change here.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/results.hpp"

namespace piezobench::campaign {

inline constexpr int kPartFormatVersion = 3;  // 2: FRFs carry std_H (issue 30); 3: the unit's FRF and k_resonance in frf_analysis, no copies of its analyses' numbers (issue 32)

// "fnv1a64:" and 16 hex digits: FNV-1a 64 of the file's bytes. InputError when it cannot be read.
std::string campaign_hash(const std::filesystem::path& file);

// The indices into campaign.units of part k of n (1 <= k <= n, else InputError naming "--part"):
// k-1, k-1+n, k-1+2n, ... (balanced: the parts differ by one unit at most; empty when k > units).
std::vector<std::size_t> part_indices(const Campaign& campaign, int k, int n);
// The indices of the units with these ids, in the campaign's order; InputError naming `option`
// and the id for an id the campaign does not have.
std::vector<std::size_t> unit_indices(const Campaign& campaign, const std::vector<int>& ids,
                                      const std::string& option = "--units");

// One unit's typed results as JSON, and back (InputError naming `source` and the field's path,
// e.g. "units[2].frf_analysis.welch.nfft", with what was expected and found).
nlohmann::json typed_unit_json(const UnitAnalysis& unit);
UnitAnalysis typed_unit_from_json(const nlohmann::json& j, const std::string& source, const std::string& path = "");

struct CampaignPart {
  std::filesystem::path file;          // the part.json read
  std::string generator;               // "piezobench VERSION"
  std::string campaign;                // the campaign file as given to `run`
  std::filesystem::path campaign_path; // its absolute path
  std::string campaign_hash;
  std::vector<int> campaign_units;     // every unit id of the campaign, in its order
  std::vector<UnitAnalysis> units;     // the part's, typed
};

// The part.json document of these units (analysed from `campaign`).
nlohmann::json part_json(const Campaign& campaign, const std::vector<UnitAnalysis>& units);
// Writes OUT/part.json atomically (OUT created if needed); returns its path. InputError when it
// cannot be written.
std::filesystem::path write_part(const Campaign& campaign, const std::vector<UnitAnalysis>& units,
                                 const std::filesystem::path& out_dir);
// Reads a part: a folder holding part.json, or the file. InputError (exit 3) naming the file for a
// folder that is not a part, a document of another format version or another piezobench version,
// and any field that is missing or of the wrong type.
CampaignPart read_part(const std::filesystem::path& path);

// The units of every part in the campaign's order. InputError naming the part (and the unit) when
// a part is of another campaign (hash, or the campaign file changed since), holds a unit the
// campaign does not have, or a unit another part also holds; naming the campaign and the unit when
// a unit is in none of the parts.
std::vector<UnitAnalysis> merge_parts(const Campaign& campaign, const std::vector<CampaignPart>& parts);

}  // namespace piezobench::campaign
