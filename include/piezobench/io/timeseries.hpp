#pragma once
// Sampled measurement records (time series) and the files they live in.
//
// Readers: MATLAB .mat (v5/v7 and v7.3, docs/formats.md) and CSV with a header row. Writers: .mat
// (v5 by default, v7.3 on request) and CSV. Every reader validates what it returns and throws
// InputError naming the file, the field or channel, what was expected and what was found: unknown
// channel (the message lists the available ones), lengths that differ, NaN/Inf (channel and sample
// index), an empty record, a non-numeric variable, a non-monotonic or non-uniform time vector `t`,
// a sample rate that contradicts `t`. Every writer writes a temporary file in the target's
// directory and renames it over the target only when complete, so a failed write leaves no file
// (and an existing target untouched).
//
// Units: every reader converts the samples to SI with the unit table of io/units.hpp (a CSV
// header's `[unit]` or `(unit)`, the .mat `units` struct, ReadOptions::units for files that say
// nothing) and records the SI symbol in TimeSeries::units; a unit the table does not know is an
// InputError naming the channel and listing the known ones. A channel without any unit is kept as
// it is (SI assumed).
//
// File layouts
//  .mat  one real double vector per channel (row or column; single and integer classes are
//        converted to double), optionally a time vector `t` or `time` (any case; in seconds, or in
//        the time unit its `units` field gives) and the sample rate as a scalar `fs`, `Fs`,
//        `sample_rate` or `sample_rate_Hz` (any case, Hz). Written files also hold `fs` (Hz, scalar),
//        `channels` (char row, the names comma-separated in order: v7.3 lists variables by name),
//        `units` (struct: one char field per channel that has a unit) and `settings` (struct: one
//        field per setting, a char row or a real scalar). Channels may instead be the fields of a
//        1x1 struct variable (ReadOptions::group), as in `data.u`, `data.de`.
//  .csv  the dialects labs write: delimiter ',', ';', tab or runs of blanks, decimal point or
//        comma, all detected from the header and the first data row unless ReadOptions forces
//        them; a UTF-8 byte order mark, blank lines and lines starting with '#' are ignored; the
//        first other line is the header. A header cell is a channel name optionally followed by
//        its unit in square brackets or parentheses, e.g. `de [um]`, `Vs (mV)`. A column named `t`
//        or `time` (any case) is the time vector, in any time unit (`Time [ms]`). A comment before
//        the header such as `# sample_rate_Hz: 10000`, `# fs = 10 kHz` or `# Fs: 2000` gives the
//        rate of a file without a time column (the writer adds the first form then).
#include <Eigen/Dense>
#include <filesystem>
#include <optional>
#include <map>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace piezobench::io {

using Setting = std::variant<double, std::string>;

struct TimeSeries {
  std::vector<std::string> names;    // channel names, unique, not "t"
  Eigen::MatrixXd data;              // samples x channels; column j is channel names[j] (SI units)
  double sample_rate = 0.0;          // Hz, > 0
  Eigen::VectorXd t;                 // s, same length as data.rows(); empty when the file has none
  std::vector<std::string> units;    // per channel, SI symbol ("" = unknown); empty or names.size() entries
  std::map<std::string, Setting> settings;  // how the record was made (experiment, seed, ...)
  std::string source;                // file it was read from ("" when built in memory)
  // What the reader accepted but the user should know, one line each, naming the file: a channel
  // without a unit (taken as SI), a unit replaced by ReadOptions::unit_overrides, an --fs that
  // disagrees with the time vector. Commands print them on stderr and in --json ("warnings").
  std::vector<std::string> warnings;

  [[nodiscard]] Eigen::Index samples() const { return data.rows(); }
  [[nodiscard]] Eigen::Index channels() const { return data.cols(); }
  // Column index of a channel; throws InputError (source, field "channel") listing the names.
  [[nodiscard]] Eigen::Index index(const std::string& name) const;
  // The samples of one channel (see index()).
  [[nodiscard]] Eigen::Ref<const Eigen::VectorXd> channel(const std::string& name) const;
  // Unit of a channel ("" when unknown).
  [[nodiscard]] std::string unit(const std::string& name) const;
  // Throws InputError naming `source` for: no channel or no sample, duplicate or empty names,
  // sizes that differ, NaN/Inf (channel and sample index), sample_rate <= 0 or not finite, a `t`
  // that is not strictly increasing.
  void validate() const;
};

struct ReadOptions {
  // Sample rate in Hz; 0 = take it from the time vector `t` (or, for files written by piezobench,
  // the scalar `fs`). When given, it overrides the time vector and the file's fs; a disagreement
  // is a warning that shows both rates.
  double fs = 0.0;
  // Channels to read, in this order; empty = every numeric vector in the file except `t`.
  std::vector<std::string> channels;
  // .mat only: name of a 1x1 struct variable whose fields are the channels ("" = top level; if
  // the top level holds no vector but exactly one struct does, that struct is used).
  std::string group;
  // Jitter tolerance of a time vector: the largest accepted deviation of a stamp from the
  // least-squares line through the stamps, beyond the precision the file stores them with (printed
  // decimals, float32, double round-off; capped at a quarter period), as a fraction of the sample
  // period. 1 % accepts random jitter of 0.1 % RMS (its largest deviation in 10^7 stamps is
  // ~0.55 %) and refuses a dropped or doubled sample (half a period at least). Beyond it the reader
  // refuses the file with the measured figure, unless `fs` is given (then a warning).
  double time_tolerance = 0.01;
  // CSV only: the delimiter (0 = detect; ',', ';', '\t' or ' ' for runs of blanks) and the decimal
  // separator (0 = detect; '.' or ',').
  char delimiter = 0;
  char decimal = 0;
  // Units of channels whose file gives none (e.g. from a campaign file): channel -> unit symbol.
  // A file that gives another unit for such a channel is an InputError.
  std::map<std::string, std::string> units;
  // Units that replace the file's (the command line's --units de=um,Vs=mV): channel -> unit
  // symbol. A file that gives another unit is overridden with a warning; a channel the file does
  // not have is an InputError (field "--units").
  std::map<std::string, std::string> unit_overrides;

  // Throws InputError (source "ReadOptions") naming the bad field.
  void validate() const;
};

// Spellings of ReadOptions::delimiter / decimal for command lines: "auto" (0), ",", ";", "tab",
// "space" (blanks); "auto", ".", ",". InputError (field --delimiter / --decimal) otherwise.
[[nodiscard]] char csv_delimiter_from_string(const std::string& s);
[[nodiscard]] char csv_decimal_from_string(const std::string& s);

enum class MatVersion { kV5, kV73 };
[[nodiscard]] std::string to_string(MatVersion v);        // "v5", "v7.3"
[[nodiscard]] MatVersion mat_version_from_string(const std::string& s);  // also "7.3", "-v7.3", "v7"

struct MatWriteOptions {
  MatVersion version = MatVersion::kV5;  // v5 (MATLAB -v7 compatible) unless v7.3 is asked for
  bool compress = false;                 // zlib compression of v5 variables (ignored for v7.3)
};

// Reads a time series; the format comes from the extension (.mat, .csv, or .uff/.unv/.uf for UFF58
// time histories; case-insensitive).
[[nodiscard]] TimeSeries read_timeseries(const std::filesystem::path& file, const ReadOptions& options = {});
[[nodiscard]] TimeSeries read_timeseries_mat(const std::filesystem::path& file, const ReadOptions& options = {});
[[nodiscard]] TimeSeries read_timeseries_csv(const std::filesystem::path& file, const ReadOptions& options = {});
// UFF dataset 58 time histories (function type 1, as Testlab and Simcenter export; ASCII or binary
// 58b, one record per channel): docs/formats.md, "UFF58 time histories".
[[nodiscard]] TimeSeries read_timeseries_uff58(const std::filesystem::path& file, const ReadOptions& options = {});

// Readings of one value per element (an LCR meter's capacitances), which read_timeseries refuses in
// a .mat file (a record has 2 samples or more): the variables `channels` of a .mat file, each a
// real double scalar or vector, all of one length n, as a TimeSeries of n samples at 1 Hz without
// a time vector (no unit conversion: the values as stored). std::nullopt when the file is not a
// .mat file (by its extension), lacks one of the channels or one is not such a vector (the
// caller's own reader then has the message to show); InputError when the file cannot be read or
// a value is NaN/Inf. MAT v7.3 files are read by an isolated child, as read_timeseries does.
[[nodiscard]] std::optional<TimeSeries> read_mat_readings(const std::filesystem::path& file,
                                                          const std::vector<std::string>& channels);

// A record read for one pass over its samples (what `piezobench frf` needs): the same checks and
// results as read_timeseries, but the channels of a v5 MAT file stored as uncompressed doubles in
// SI units are used in place from a read-only mapping of the file (no copy into fresh memory);
// anything else is read by read_timeseries and kept in `storage`. The time vector, when the file
// has one, is checked and gives the sample rate; the view does not keep it, nor the settings.
// FiniteCheck::kCaller leaves NaN/Inf in the mapped channels to the caller, which must check them
// on its own pass (dsp::estimate_frf does, through its sums, and names the channel and sample):
// one pass over the record less. A record read into memory is checked as it arrives in any case.
enum class FiniteCheck { kReader, kCaller };
struct TimeSeriesView {
  std::vector<std::string> names;                // as TimeSeries::names
  std::vector<const double*> columns;            // columns[j]: samples() values of channel names[j]
  Eigen::Index samples = 0;
  double sample_rate = 0.0;                      // Hz
  std::vector<std::string> units;                // as TimeSeries::units
  std::string source;
  std::vector<std::string> warnings;             // as TimeSeries::warnings
  std::shared_ptr<const void> storage;           // owns what `columns` point to
  bool mapped = false;                           // true when the columns point into the file's mapping

  [[nodiscard]] Eigen::Index index(const std::string& name) const;  // as TimeSeries::index
  [[nodiscard]] Eigen::Map<const Eigen::VectorXd> channel(const std::string& name) const;
  [[nodiscard]] std::string unit(const std::string& name) const;
};
[[nodiscard]] TimeSeriesView read_timeseries_view(const std::filesystem::path& file, const ReadOptions& options = {},
                                                  FiniteCheck finite = FiniteCheck::kReader);

// Writes `ts` (validated first) as .mat or CSV (format from the extension). Channel names must be
// MATLAB identifiers (letter, then letters, digits, '_'; at most 63 characters) other than the
// reserved fs, units, settings, channels for .mat.
// Throws InputError (source = file) when the data are invalid or the file cannot be written.
void write_timeseries(const TimeSeries& ts, const std::filesystem::path& file, const MatWriteOptions& options = {});
void write_timeseries_mat(const TimeSeries& ts, const std::filesystem::path& file, const MatWriteOptions& options = {});
// CSV: header `t [s],name [unit],...` (t only when present, units only when known), %.17g values.
void write_timeseries_csv(const TimeSeries& ts, const std::filesystem::path& file);

}  // namespace piezobench::io
