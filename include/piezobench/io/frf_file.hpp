#pragma once
// Frequency response functions (dsp::Frf) in files that other tools read: CSV, MATLAB .mat and
// Universal File Format dataset 58 (ASCII; binary 58b is read too), so modal-analysis tools can
// exchange FRFs with piezobench.
//
// Layouts
//  CSV   header `freq_Hz,re_NAME,im_NAME,coh_NAME,std_NAME` repeated per output (CLI.md; std_ is
//        dsp::Frf::std_H, in the units of H), values %.17g, so a round trip is exact. On read, coh_
//        and std_ columns are optional (each for every output or none), lines starting with '#' and
//        blank lines are ignored, the first column may also be `freq [Hz]` or `freq [kHz]`, and
//        the dialect (delimiter, decimal comma) is detected as for time series; the input name is
//        not stored (read back as "").
//  .mat  `freq_Hz` (column, Hz), per output `H_<name>` (complex column), `coh_<name>` (when the
//        coherence is known) and `std_<name>` (std_H, when known), `input` and `outputs` (char rows; outputs comma-separated, keeps the
//        order) and `provenance` (struct). Exact round trip. Names must be MATLAB identifiers.
//  .uff  (also .unv, .uf) one dataset 58 per output: function type 4 (FRF), ordinate type 6
//        (complex double, 4E20.12 i.e. 13 significant digits), abscissa in Hz (specific data
//        type 18), evenly spaced (record 7 holds min and increment, E13.5) when the grid is
//        uniform to 1e-9 relative, else unevenly spaced (E13.5 abscissa per point). So a round trip
//        keeps H to ~5e-13 relative and the frequencies to 6 significant digits (the format's).
//        Coherence, when known, follows as a dataset 58 of function type 6 (real double). The format
//        has no function type for a standard deviation: on read, std_H is recomputed from the
//        coherence and the Welch settings of ID line 5 (dsp::std_from_coherence), else unknown. Node and
//        direction: response node k+1 for output k, reference node `reference_node`, direction +Z
//        (3) for both. Channel names go in ID line 2 ("piezobench response: NAME"), ID line 4
//        ("piezobench reference: NAME") and the ordinate / denominator axis labels; ID line 5
//        holds the provenance ("welch: est=H1 win=hann-periodic nfft=.. ovl=.. dtr=.. avg=.. fs=..",
//        whole fields only, within 80 columns).
//        Reading accepts any mix of ASCII 58 and binary 58b datasets (byte order 1 little / 2 big
//        endian, IEEE floats, abscissa of uneven binary data as float32 or float64), skips other
//        datasets, and gathers every function-type-4 dataset (all must share the abscissa and the
//        reference); names come from the ID lines written above, else the axis labels, else the
//        entity name / node / direction ("1+Z").
//
// Every reader validates the FRF it returns and throws InputError naming the file and the field
// (column, variable, dataset and record); writers write a temporary file and rename it, so a
// failure never leaves a partial file.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "piezobench/dsp/frf.hpp"
#include "piezobench/io/timeseries.hpp"

namespace piezobench::io {

enum class FrfFormat { kCsv, kMat, kUff58 };
[[nodiscard]] std::string to_string(FrfFormat f);                       // "csv", "mat", "uff58"
[[nodiscard]] FrfFormat frf_format_from_string(const std::string& s);   // also "uff", "unv"
// From the extension: .csv, .mat, .uff/.unv/.uf (case-insensitive); InputError otherwise.
[[nodiscard]] FrfFormat frf_format_from_path(const std::filesystem::path& file);

struct FrfWriteOptions {
  MatVersion mat_version = MatVersion::kV5;  // .mat only
  int reference_node = 1000;                 // UFF: node number of the input (reference) DOF
  std::string date;                          // UFF ID line 3 (e.g. "21-NOV-25 10:48:00"); "" = NONE
  // Units of the measured channels H relates (unit table symbols, "" = not known): H of output i
  // is in output_units[i] / input_unit. Written as the CSV header's `re_NAME [m/V]`, the .mat
  // `units` struct (H_NAME = 'm/V') and UFF records 9 and 10. Empty vector: no units written.
  std::vector<std::string> output_units;
  std::string input_unit;

  void validate() const;  // InputError naming the field
};

// Writes `frf` (validated first) in the format of the file's extension.
void write_frf(const dsp::Frf& frf, const std::filesystem::path& file, const FrfWriteOptions& options = {});
void write_frf_csv(const dsp::Frf& frf, const std::filesystem::path& file, const FrfWriteOptions& options = {});
void write_frf_mat(const dsp::Frf& frf, const std::filesystem::path& file, const FrfWriteOptions& options = {});
void write_frf_uff58(const dsp::Frf& frf, const std::filesystem::path& file, const FrfWriteOptions& options = {});

struct FrfReadOptions {
  // CSV only: the delimiter (0 = detect; ',', ';', '\t' or ' ' for runs of blanks) and the decimal
  // separator (0 = detect; '.' or ','), as for time series (timeseries.hpp).
  char delimiter = 0;
  char decimal = 0;
  // Units replacing the file's (the command line's --units): an output's name -> that output's
  // unit, the input's name (or "input") -> the input's unit (H = output / input; the one not
  // given is taken as SI), or "H_NAME" -> the unit of that FRF itself ("um/V"). A file unit
  // replaced is a warning; a key that names no output or input is an InputError (field --units).
  std::map<std::string, std::string> unit_overrides;
};

// An FRF as read: H in SI units, with the unit each output's H was converted to.
struct FrfFile {
  dsp::Frf frf;
  std::vector<std::string> units;    // per output: the SI unit of H ("m/V"; "" = none stated: taken as SI)
  std::vector<std::string> warnings; // an output without a unit, a unit replaced by --units (one line each)
};

// Reads an FRF in the format of the file's extension, converting H to SI with the units the file
// states (Units in FRF files, docs/formats.md) or the overrides. provenance.source is the
// time-series file recorded in a .mat FRF, else the FRF file itself.
[[nodiscard]] FrfFile read_frf_file(const std::filesystem::path& file, const FrfReadOptions& options = {});
// read_frf_file's FRF (its warnings dropped).
[[nodiscard]] dsp::Frf read_frf(const std::filesystem::path& file, const FrfReadOptions& options = {});
// One format each (read_frf_file's FRF).
[[nodiscard]] dsp::Frf read_frf_csv(const std::filesystem::path& file, const FrfReadOptions& options = {});
[[nodiscard]] dsp::Frf read_frf_mat(const std::filesystem::path& file, const FrfReadOptions& options = {});
[[nodiscard]] dsp::Frf read_frf_uff58(const std::filesystem::path& file, const FrfReadOptions& options = {});

}  // namespace piezobench::io
