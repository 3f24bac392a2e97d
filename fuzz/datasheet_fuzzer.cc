// Fuzz target: datasheet summaries (fuzz_targets.h), as `datasheet` and the server's
// ConvertDatasheet read them: ParseDatasheetText, then DatasheetToModel.
#include "driftlab/calib/datasheet.h"
#include "driftlab/spec_error.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"

namespace driftlab::fuzz {

void FuzzDatasheet(const uint8_t* data, size_t size) {
  try {
    calib::DatasheetToModel(calib::ParseDatasheetText(AsText(data, size), "fuzz.yaml"));
  } catch (const SpecError&) {
  }
}

}  // namespace driftlab::fuzz
