#include "driftlab/calib/yaml_document.h"

#include <yaml-cpp/eventhandler.h>

#include <sstream>
#include <string>

namespace driftlab::calib {
namespace {

// Parser events are only counted per document, not built into nodes (aliases stay unexpanded).
class IgnoreEvents : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

}  // namespace

YamlDocuments LoadYamlDocuments(std::string_view text) {
  const std::string copy(text);
  YamlDocuments out;
  std::istringstream in(copy);
  YAML::Parser parser(in);
  IgnoreEvents events;
  while (out.count < 2 && parser.HandleNextDocument(events)) ++out.count;
  // YAML::Load reads the first document only (one HandleNextDocument), so it always returns.
  if (out.count > 0) out.first = YAML::Load(copy);
  return out;
}

}  // namespace driftlab::calib
