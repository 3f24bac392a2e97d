// Where a test finds the source tree, ../shared and the binaries it drives. Force-included into
// every test source (tests/CMakeLists.txt, driftlab_add_test_group), defined in test_paths.cc, the
// one test file compiled with absolute paths: the test sources' own compile commands hold none, so
// ccache reuses their objects across clones of the repository.
#pragma once

namespace driftlab_test_paths {
extern const char kSourceDir[];     // the repository's top directory
extern const char kSharedDir[];     // ../shared beside it (DESIGN.md, seeds)
extern const char kCliTestData[];   // tests/cli/data
extern const char kCliBinary[];     // <build>/driftlab
extern const char kServerBinary[];  // <build>/driftlab-server
}  // namespace driftlab_test_paths

#define DRIFTLAB_SOURCE_DIR (::driftlab_test_paths::kSourceDir)
#define DRIFTLAB_SHARED_DIR (::driftlab_test_paths::kSharedDir)
#define DRIFTLAB_CLI_TEST_DATA (::driftlab_test_paths::kCliTestData)
#define DRIFTLAB_CLI (::driftlab_test_paths::kCliBinary)
#define DRIFTLAB_SERVER_BINARY (::driftlab_test_paths::kServerBinary)
