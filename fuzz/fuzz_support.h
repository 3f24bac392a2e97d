// Helpers shared by the fuzz targets (fuzz_targets.h); header-only, so a target links only the
// libraries of the reader it fuzzes.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace driftlab::fuzz {

// The input as text (any bytes, NUL included).
inline std::string_view AsText(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Writes the input to this process's scratch file (in the system's temporary directory, one per
// process and `suffix`, rewritten on every call) and returns its path, for the readers that take
// a path, as the CLI calls them.
inline std::string WriteScratchFile(const uint8_t* data, size_t size, std::string_view suffix) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("driftlab-fuzz-" + std::to_string(::getpid()) + std::string(suffix)))
                               .string();
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) throw std::runtime_error("fuzz: cannot create " + path);
  const bool ok = std::fwrite(data, 1, size, file) == size;
  if (std::fclose(file) != 0 || !ok) throw std::runtime_error("fuzz: cannot write " + path);
  return path;
}

}  // namespace driftlab::fuzz
