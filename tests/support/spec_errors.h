// The message of the SpecError an input check throws, for tests of bad input (header-only; the test
// links the library that defines SpecError's MessageText, driftlab_engine).
#pragma once

#include <string>

#include "driftlab/spec_error.h"

namespace driftlab::testing {

// The SpecError message of f(), or "" when f returns normally.
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const SpecError& e) {
    return e.what();
  }
  return "";
}

}  // namespace driftlab::testing
