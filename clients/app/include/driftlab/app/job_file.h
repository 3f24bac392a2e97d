// Job files: reading a driftlab.v1.Job from its protobuf JSON mapping or from YAML.
//
// The schema drives everything (DESIGN.md invariant 6): the text is parsed into a generic tree
// (google.protobuf.Value), checked against the Job descriptor by reflection so that unknown
// fields, wrong types and bad enum names are reported with their field path, and only then
// handed to protobuf's own JSON parser. YAML is converted generically to the same tree. Every
// error is a driftlab::SpecError whose message is one line:
//   "motion.segments[2].spin: unknown field; allowed: static, accelerate, ..."
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "driftlab/v1/job.pb.h"

namespace driftlab::app {

// Limits of a YAML document, checked while it is converted: nesting depth, and the
// number of values once aliases are expanded (an "alias bomb" of a few hundred bytes would
// otherwise expand to billions). JSON input is checked by CheckJsonSyntax (json_syntax.h); a job
// file is at most kMaxJobFileBytes (input_files.h). A YAML text holds one document; tags other
// than YAML's own are refused.
inline constexpr int kMaxYamlDepth = 64;
inline constexpr size_t kMaxYamlNodes = 1000000;

// A job as loaded from a file: relative file paths inside it resolve against base_dir.
struct JobFile {
  v1::Job job;
  std::filesystem::path base_dir;
};

// Parses a job from JSON (the protobuf JSON mapping). `source` names the text in errors that are
// not about one field (syntax errors). Throws SpecError.
v1::Job ParseJobJson(std::string_view json_text, std::string_view source = "job");

// Parses a job from YAML: the document is converted to the JSON tree (plain scalars that look
// like numbers become numbers, true/false booleans, null/~ null, .nan/.inf the JSON strings
// "NaN"/"Infinity" that protobuf accepts for double fields; quoted scalars stay strings).
v1::Job ParseJobYaml(std::string_view yaml_text, std::string_view source = "job");

// Converts a YAML document to JSON text by the rules above (used by ParseJobYaml; exposed for
// tools and tests). Throws SpecError on YAML syntax errors.
std::string YamlToJson(std::string_view yaml_text, std::string_view source = "job");

// Reads a job file; the format follows the extension: .json, or .yaml / .yml. Throws SpecError
// (file-level errors carry the file name as their field).
JobFile LoadJobFile(const std::filesystem::path& path);

}  // namespace driftlab::app
