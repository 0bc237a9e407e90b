#pragma once
// A JSON document (e.g. results.json) as a MATLAB .mat file of nested structs, so that
// `r = load('results.mat')` gives r.units(3).stiffness_N_per_um.k1 in MATLAB or Octave.
//
// Mapping (JSON -> MATLAB):
//   object                      -> 1x1 struct (field names made MATLAB identifiers, see below)
//   number                      -> double scalar
//   true / false                -> logical scalar
//   null                        -> [] (0x0 double)
//   "nan", "inf", "-inf"        -> NaN, Inf, -Inf (io::to_json writes non-finite numbers so)
//   other string                -> char row
//   [] (empty array)            -> [] (0x0 double)
//   array of numbers            -> 1xN double row (null and the strings above as NaN / +-Inf)
//   array of booleans           -> 1xN logical row
//   array of equal-length arrays of numbers -> N x M double matrix (e.g. [re, im] pairs -> N x 2)
//   array of objects                        -> 1xN struct array with the union of their keys
//                                              (a key an element lacks is [] there)
//   anything else (strings, mixed, ragged)  -> 1xN cell array, element by element
// Field names: characters other than letters, digits and '_' become '_', a name not starting with a
// letter gets the prefix "x", names are cut to 63 characters and made unique with "_2", "_3", ...
// The top-level object's keys become the file's variables (or one struct variable, see options).
#include <filesystem>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "piezobench/io/timeseries.hpp"

namespace piezobench::io {

struct MatStructOptions {
  MatVersion version = MatVersion::kV5;
  bool compress = true;  // zlib for v5 (v7.3 is never compressed here)
  // "" = one variable per top-level key; otherwise the whole document as this one struct variable
  // (a MATLAB identifier).
  std::string variable;
  void validate() const;  // InputError (source "mat options") naming the field
};

// The identifier a JSON key becomes (see above).
std::string matlab_field_name(const std::string& key);

// Writes `document` (a JSON object) atomically to `file` (no partial file on failure). InputError
// (source = file) when the document is not an object or the file cannot be written.
void write_json_as_mat(const nlohmann::json& document, const std::filesystem::path& file,
                       const MatStructOptions& options = {});

}  // namespace piezobench::io
