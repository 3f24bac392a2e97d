// The libFuzzer targets as plain functions: each takes one input (the bytes libFuzzer
// generates, or a file of fuzz/corpus/ or fuzz/regressions/) and feeds it through one reader of
// hostile input the way the CLI or the server does. A refusal (SpecError, LimitError) is the
// expected answer to a bad input and is caught; anything else escaping (another exception, a
// sanitizer report, a crash, a hang) is a bug.
//
// The same functions run in two builds: the fuzz build (fuzz/CMakeLists.txt, clang with
// -fsanitize=fuzzer), where fuzz/libfuzzer_main.cc makes each one a libFuzzer executable, and the
// normal build, where tests/fuzz/fuzz_regression_test.cc replays every saved input through them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace driftlab::fuzz {

using FuzzFunction = void (*)(const uint8_t* data, size_t size);

// Job files: ParseJobJson / ParseJobYaml, then ValidateJob, the validation of every entry
// (`validate`, `run`, `simulate`, `export`, the server), with its memory estimate.
void FuzzJobJson(const uint8_t* data, size_t size);
void FuzzJobYaml(const uint8_t* data, size_t size);
// The units parser: ParseUnit, ParseQuantity against every dimension, FromSi, FormatQuantity.
void FuzzUnits(const uint8_t* data, size_t size);
// Recording CSV (calibrate, allan, noise fit): ReadNumericCsv (both overloads), then
// SelectRateColumns (units from the column names' suffixes).
void FuzzRecordingCsv(const uint8_t* data, size_t size);
// Raw IMU CSV of the calibration library: ReadRawImuCsv with and without a time column, then
// ValidateRecording.
void FuzzRawImuCsv(const uint8_t* data, size_t size);
// gnss-ins-sim motion-definition importer, then the trajectory generator's planning of it.
void FuzzGnssInsSimMotion(const uint8_t* data, size_t size);
// Groves-layout truth-profile importer (the motion CSV), then TruthProfileMotion and planning.
void FuzzTruthProfile(const uint8_t* data, size_t size);
// Datasheet summaries: ParseDatasheetText, DatasheetToModel.
void FuzzDatasheet(const uint8_t* data, size_t size);
// Result files: two results separated by a NUL byte; each parsed and validated
// (ParseJobResultJson), rendered (RenderHtmlReport), gated (RunGate, default rules) and the pair
// merged (MergeJobResults).
void FuzzResultMerge(const uint8_t* data, size_t size);
// The server's Submit: a binary SubmitJobRequest parsed as gRPC does, then ValidateSubmitRequest.
void FuzzSubmitRequest(const uint8_t* data, size_t size);

struct FuzzTarget {
  std::string_view name;  // the folder under fuzz/corpus/ and fuzz/regressions/
  FuzzFunction function;
};

// Every target, in the order fuzz/ci.sh runs them.
const std::vector<FuzzTarget>& FuzzTargets();

}  // namespace driftlab::fuzz
