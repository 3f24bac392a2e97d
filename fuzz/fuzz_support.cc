#include "fuzz_support.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "driftlab/jobspec/job_file.h"
#include "driftlab/jobspec/monte_carlo_job.h"
#include "driftlab/jobspec/translate.h"
#include "driftlab/spec_error.h"

namespace driftlab::fuzz {

std::string WriteScratchFile(const uint8_t* data, size_t size, std::string_view suffix) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("driftlab-fuzz-" + std::to_string(::getpid()) + std::string(suffix)))
                               .string();
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) throw std::runtime_error("fuzz: cannot create " + path);
  const bool ok = std::fwrite(data, 1, size, file) == size;
  if (std::fclose(file) != 0 || !ok) throw std::runtime_error("fuzz: cannot write " + path);
  return path;
}

void ValidateParsedJob(const v1::Job& job) {
  const jobspec::JobFile file{job, "/nonexistent/driftlab-fuzz"};
  try {
    jobspec::ValidateJob(file);
  } catch (const SpecError&) {
    return;
  }
  try {
    jobspec::ToMonteCarloSpec(file, jobspec::MonteCarloOverrides{});
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
