// Definitions that many test files use, defined once: the files of a test executable compile
// together in unity batches (cmake/DriftlabUnity.cmake), where a name defined at namespace scope
// in two files is a redefinition. Force-included into every test source after test_paths.h
// (tests/CMakeLists.txt).
#pragma once

#include <cmath>
#include <filesystem>

// One degree in radians.
inline constexpr double kDeg = M_PI / 180.0;
// tests/cli/data: job files, recordings, datasheets and results the tests read.
inline const std::filesystem::path kCliData{DRIFTLAB_CLI_TEST_DATA};
// tests/data: motion files and other engine test inputs.
inline const std::filesystem::path kTestData =
    std::filesystem::path(DRIFTLAB_SOURCE_DIR) / "tests" / "data";
// examples/: the job files a new user runs.
inline const std::filesystem::path kExamples =
    std::filesystem::path(DRIFTLAB_SOURCE_DIR) / "examples";
