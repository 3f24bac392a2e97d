// One validator for every entry, through the `driftlab` binary: each job that an earlier driftlab
// validated and then failed on (or ran wrongly, or reported under a field the schema does not
// have) is refused by `validate`, `run`, `simulate` and `export` alike, with exit status 2, the
// same one-line message naming the field, and nothing written.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/bad_jobs.h"
#include "support/cli_runner.h"

namespace {

namespace fs = std::filesystem;
// driftlab::testing::BadJob, by another name: cli_test.cc has a BadJob of its own (unity builds).
using EntryBadJob = driftlab::testing::BadJob;
using driftlab::testing::Result;
using driftlab::testing::RunDriftlab;
using driftlab::testing::Scratch;

fs::path WriteScratchFile(const Scratch& scratch, const std::string& name,
                          const std::string& content) {
  const fs::path path = scratch.dir() / name;
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

int MessageLines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

// Every entry refuses `bad` before any work with the same message; no output appears.
void ExpectRefusedEverywhere(const EntryBadJob& bad) {
  SCOPED_TRACE(bad.name);
  Scratch scratch;
  const fs::path job = WriteScratchFile(scratch, "job.json", bad.json);
  const Result validate = RunDriftlab({"validate", job.string()}, scratch);
  ASSERT_EQ(validate.exit_status, 2) << validate.out << validate.err;
  ASSERT_EQ(MessageLines(validate.err), 1) << validate.err;
  EXPECT_EQ(validate.err.rfind("error: " + bad.field + ": ", 0), 0u) << validate.err;
  EXPECT_NE(validate.err.find(bad.value), std::string::npos) << validate.err;

  const fs::path result = scratch.dir() / "out" / "result.json";
  const fs::path report = scratch.dir() / "out" / "report.html";
  const Result run = RunDriftlab(
      {"run", job.string(), "--out", result.string(), "--report", report.string(), "-q"}, scratch);
  EXPECT_EQ(run.exit_status, 2) << run.err;
  EXPECT_EQ(run.err, validate.err);

  const fs::path dir = scratch.dir() / "sim";
  const Result simulate = RunDriftlab({"simulate", job.string(), "--out", dir.string()}, scratch);
  EXPECT_EQ(simulate.exit_status, 2) << simulate.err;
  EXPECT_EQ(simulate.err, validate.err);

  const fs::path export_dir = scratch.dir() / "export";
  const Result exported =
      RunDriftlab({"export", job.string(), "--out", export_dir.string()}, scratch);
  EXPECT_EQ(exported.exit_status, 2) << exported.err;
  EXPECT_EQ(exported.err, validate.err);

  // Nothing written: neither the files nor their directories.
  EXPECT_FALSE(fs::exists(scratch.dir() / "out"));
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_FALSE(fs::exists(export_dir));
}

TEST(JobValidationCli, JobsThatValidatedThenFailedAreRefusedByEveryEntry) {
  for (const EntryBadJob& bad : driftlab::testing::ValidatedThenFailedJobs()) {
    ExpectRefusedEverywhere(bad);
  }
}

TEST(JobValidationCli, MessagesNameFieldsOfTheJobSchema) {
  for (const EntryBadJob& bad : driftlab::testing::WrongFieldNameJobs())
    ExpectRefusedEverywhere(bad);
}

TEST(JobValidationCli, ImportedMotionErrorsNameTheFileField) {
  // A truth profile of two samples 0.01 s apart: shorter than one 20 Hz interval. The engine once
  // named "motion.segments", a field this job does not have.
  Scratch scratch;
  WriteScratchFile(scratch, "short.csv", "0,45,7,200,0,0,0,0,0,0\n0.01,45,7,200,0,0,0,0,0,0\n");
  const EntryBadJob bad{"TruthProfileTooShort",
                        R"({"rate_hz": 20, "motion": {"truth_profile_file": {"path": ")" +
                            (scratch.dir() / "short.csv").string() + R"("}}})",
                        "motion.truth_profile_file.path", "short.csv"};
  ExpectRefusedEverywhere(bad);
}

TEST(JobValidationCli, AllanFitOnTooFewSamplesNamesTheData) {
  // Three samples give the Allan deviation at one averaging time; the fit was refused naming
  // noise_fit.flicker_tau_min_s, an option the user never gave.
  Scratch scratch;
  const fs::path data =
      WriteScratchFile(scratch, "three.csv", "gyro_x_rad_per_s\n0.001\n-0.002\n0.0005\n");
  const Result r =
      RunDriftlab({"allan", data.string(), "--rate", "100", "--columns", "gyro_x_rad_per_s",
                   "--fit", "--out", (scratch.dir() / "m.json").string()},
                  scratch);
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: " + data.string() +
                            ": column 'gyro_x_rad_per_s': 3 samples is not "
                            "allowed; allowed: at least 5 samples for a fit",
                        0),
            0u)
      << r.err;
  EXPECT_EQ(r.err.find("flicker_tau"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(scratch.dir() / "m.json"));
}

}  // namespace
