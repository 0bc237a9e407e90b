#pragma once
// Private to the campaign module: the APA300ML super element shipped in the binary
// (data/superelement/apa300ml: K, M, DOF list and the bench description apa300ml.toml).
#include <filesystem>
#include <string_view>
#include <vector>

namespace piezobench::campaign::detail {

struct EmbeddedFile {
  std::string_view name;  // file name, e.g. "apa300ml_K.mtx"
  std::string_view text;
};
[[nodiscard]] std::vector<EmbeddedFile> apa300ml_superelement_files();

// Writes the files into `dir` (created); returns the path of apa300ml.toml. InputError when they
// cannot be written.
std::filesystem::path write_apa300ml_superelement(const std::filesystem::path& dir);

}  // namespace piezobench::campaign::detail
