// The validation the job-file fuzz targets run on a parsed job (fuzz_targets.h).
#pragma once

#include "driftlab/v1/job.pb.h"

namespace driftlab::fuzz {

// What every entry does with a parsed job: ValidateJob (motion files relative to a directory that
// does not exist) with the default limits. SpecError (LimitError included) is the expected
// refusal and is caught.
void ValidateParsedJob(const v1::Job& job);

}  // namespace driftlab::fuzz
