// Helpers shared by the fuzz targets (fuzz_targets.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "driftlab/v1/job.pb.h"

namespace driftlab::fuzz {

// The input as text (any bytes, NUL included).
inline std::string_view AsText(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Writes the input to this process's scratch file (in the system's temporary directory, one per
// process and `suffix`, rewritten on every call) and returns its path, for the readers that take
// a path, as the CLI calls them.
std::string WriteScratchFile(const uint8_t* data, size_t size, std::string_view suffix);

// What `validate` and `run` do with a parsed job: ValidateJob (motion files relative to a
// directory that does not exist), then ToMonteCarloSpec with the default limits. SpecError
// (LimitError included) is the expected refusal and is caught.
void ValidateParsedJob(const v1::Job& job);

}  // namespace driftlab::fuzz
