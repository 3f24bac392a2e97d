// The translation steps of ValidateJob (job_validator.h), internal to driftlab_app: every caller
// outside goes through ValidateJob.
#pragma once

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/simulate.h"

namespace driftlab::app {

// ToSimulationSpec (translate.h), then the engine's checks that need the planned motion (a static
// segment entered at speed, a turn by radius at zero speed, the total duration; SEED000's static
// period at rest), by constructing the trajectory generator (plans, generates no samples).
SimulationSpec PlanSimulationSpec(const JobFile& file);

// The whole job into the engine's MonteCarloSpec with every field's range and cross-field rule,
// ending with the engine's ValidateMonteCarloSpec. Throws SpecError.
MonteCarloSpec TranslateMonteCarloJob(const JobFile& file, const MonteCarloOverrides& overrides);

}  // namespace driftlab::app
