// Error raised for invalid input (job fields, files): names the field path, the value and the
// allowed range (DESIGN.md invariant 7). Field paths use the proto field names of the job schema,
// e.g. "motion.segments[2].turn.duration_s", so the CLI and the server report the same path.
#pragma once

#include <stdexcept>
#include <string>

namespace driftlab {

class SpecError : public std::runtime_error {
 public:
  // message: "<field>: <value> is out of range; allowed <range>" or similar, composed by caller.
  SpecError(std::string field, std::string value, std::string allowed)
      : std::runtime_error(field + ": " + (value.empty() ? "missing" : value) +
                           " is not allowed; allowed: " + allowed),
        field_(std::move(field)) {}
  // Free-form message for errors that are not a single value out of range (e.g. a bad file line).
  SpecError(std::string field, std::string message, int)
      : std::runtime_error(field + ": " + message), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

}  // namespace driftlab
