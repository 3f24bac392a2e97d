// Reading the one document of a YAML text (datasheets, job files) with yaml-cpp, bounded.
//
// yaml-cpp 0.7's YAML::LoadAll never returns on some short texts: a ',' at the top level of a
// document (outside [ ] and { }) is never consumed, and every further call of
// Parser::HandleNextDocument yields another empty document, so LoadAll loops, its vector of
// documents growing until memory runs out (input "," alone does it). driftlab accepts one document
// per text, so it never needs more than two: this reader counts documents up to two and loads only
// the first.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string_view>

namespace driftlab::calib {

struct YamlDocuments {
  YAML::Node first;  // the first document; a null node when there is none
  int count = 0;     // 0, 1, or 2 meaning "more than one" (a --- separator or a stray ',')
};

// Throws YAML::Exception for a syntax error in the first two documents, as YAML::Load does.
YamlDocuments LoadYamlDocuments(std::string_view text);

}  // namespace driftlab::calib
