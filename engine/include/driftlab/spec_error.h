// Error raised for invalid input (job fields, files): names the field path, the value and the
// allowed range (DESIGN.md invariant 7). Field paths use the proto field names of the job schema,
// e.g. "motion.segments[2].turn.duration_s", so the CLI and the server report the same path.
//
// A message is always one line of bounded length, whatever the input: the parts that
// echo input (field path, value, message) pass through MessageText, which escapes control bytes and
// invalid UTF-8 as \xNN (a newline as \n) and cuts a long text, saying how long it was. So a
// hostile value can neither inject lines into a log nor blow up a gRPC status past its metadata
// limit.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace driftlab {

// Longest echo of one input value, field path or free-form message [bytes, before escaping].
inline constexpr size_t kMaxMessageValueBytes = 200;
inline constexpr size_t kMaxMessageFieldBytes = 200;
inline constexpr size_t kMaxMessageTextBytes = 1500;

// `text` as one printable line of at most about max_bytes bytes: bytes below 0x20 and 0x7F as
// \n, \r, \t or \xNN; a byte that is not part of well-formed UTF-8 as \xNN; when longer than
// max_bytes, the first max_bytes bytes (cut at a character boundary) and " ... (N bytes)".
std::string MessageText(std::string_view text, size_t max_bytes);

// A number as SpecError messages show it: the shortest text that parses back to the same double
// (std::to_chars), laid out as fmt's "{}" lays it out: fixed notation for decimal exponents
// -4 <= e < 16, scientific otherwise ("0.51", "100000", "1e+16", "1.5e-07", "nan", "-inf").
std::string ValueText(double value);

// "field[i]": the path of element i of a repeated field.
std::string IndexedField(const std::string& field, size_t i);

class SpecError : public std::runtime_error {
 public:
  // message: "<field>: <value> is not allowed; allowed: <range>".
  SpecError(const std::string& field, const std::string& value, const std::string& allowed)
      : std::runtime_error(
            MessageText(field, kMaxMessageFieldBytes) + ": " +
            (value.empty() ? std::string("missing") : MessageText(value, kMaxMessageValueBytes)) +
            " is not allowed; allowed: " + MessageText(allowed, kMaxMessageTextBytes)),
        field_(MessageText(field, kMaxMessageFieldBytes)) {}
  // Free-form message for errors that are not a single value out of range (e.g. a bad file line).
  SpecError(const std::string& field, const std::string& message, int)
      : std::runtime_error(MessageText(field, kMaxMessageFieldBytes) + ": " +
                           MessageText(message, kMaxMessageTextBytes)),
        field_(MessageText(field, kMaxMessageFieldBytes)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

// A valid input that exceeds a resource limit (memory, size): reported like a SpecError (exit 2 in
// the CLI) but as RESOURCE_EXHAUSTED by the server, and the message names the limit and how to
// raise it.
class LimitError : public SpecError {
 public:
  using SpecError::SpecError;
};

}  // namespace driftlab
