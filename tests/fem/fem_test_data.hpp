#pragma once
// What several fem tests share: the folder of the external Ansys APA95ML export, and the issue's
// accuracy of a reduced model against ccx on the full mesh.
#include <filesystem>

namespace piezobench::fem::test_data {

inline const std::filesystem::path kAnsysDir = std::filesystem::path(PIEZOBENCH_SHARED_DATA_DIR) / "apa95ml-ansys";
inline constexpr double kAgainstCcx = 2e-3;  // 0.2 %

}  // namespace piezobench::fem::test_data
