// The paths of test_paths.h, from the build's definitions (tests/CMakeLists.txt).
#include "test_paths.h"

namespace driftlab_test_paths {
extern const char kSourceDir[] = DRIFTLAB_TEST_SOURCE_DIR;
extern const char kSharedDir[] = DRIFTLAB_TEST_SHARED_DIR;
extern const char kCliTestData[] = DRIFTLAB_TEST_CLI_TEST_DATA;
extern const char kCliBinary[] = DRIFTLAB_TEST_CLI_BINARY;
extern const char kServerBinary[] = DRIFTLAB_TEST_SERVER_BINARY;
}  // namespace driftlab_test_paths
