#pragma once
// Output files that are either complete or absent: the text is written to a temporary file in the
// target's directory and renamed over the target, so a failure never leaves half a file.
#include <filesystem>
#include <string>

namespace piezobench::io {

// Writes `text` to `target` atomically; InputError (source = target) when it cannot.
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

}  // namespace piezobench::io
