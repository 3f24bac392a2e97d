// Job files from JSON text for the application-layer tests (header-only).
#pragma once

#include <string>

#include "driftlab/app/job_file.h"

namespace driftlab::testing {

// The job file of `json` (protobuf JSON mapping), relative paths resolved against ".".
inline app::JobFile File(const std::string& json) {
  return app::JobFile{app::ParseJobJson(json), "."};
}

}  // namespace driftlab::testing
