// HTML report of an error budget (`driftlab budget --report`): per component group (horizontal
// position, vertical position, attitude) the sources' contributions stacked against time, a table
// of the top sources at each checkpoint with their shares in %, and the Monte-Carlo check's
// intervals. Self-contained like the Monte-Carlo report (html_report.h).
#pragma once

#include <string>

#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

std::string RenderBudgetReport(const v1::ErrorBudget& budget);

}  // namespace driftlab::app
