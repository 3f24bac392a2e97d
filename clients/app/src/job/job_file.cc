#include "driftlab/app/job_file.h"

#include <fmt/format.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "driftlab/app/json_syntax.h"
#include "driftlab/app/schema_check.h"
#include "driftlab/calib/yaml_document.h"
#include "driftlab/input_files.h"
#include "driftlab/spec_error.h"

namespace driftlab::app {
namespace {

using google::protobuf::Value;
namespace util = google::protobuf::util;

// protobuf's JSON errors read "reason\n<up to 20 characters either side of the error>\n   ^" (the
// caret under the error). Split into those parts; `context` is empty for other errors.
struct JsonErrorParts {
  std::string reason;
  std::string context;
  size_t caret = 0;  // offset of the error inside `context`
};

JsonErrorParts SplitJsonError(const util::Status& status) {
  const std::string message = status.message().ToString();
  JsonErrorParts parts;
  const size_t first = message.find('\n');
  const size_t last = message.rfind('\n');
  parts.reason = message.substr(0, first);
  if (first == std::string::npos || last == first) return parts;
  const std::string caret_line = message.substr(last + 1);
  if (caret_line.empty() || caret_line.back() != '^') return parts;
  parts.context = message.substr(first + 1, last - first - 1);
  parts.caret = caret_line.size() - 1;
  return parts;
}

// A job error is one line: "reason near `context`", with the context's line breaks as spaces.
std::string StatusText(const util::Status& status) {
  JsonErrorParts parts = SplitJsonError(status);
  if (parts.context.empty()) return parts.reason;
  std::replace(parts.context.begin(), parts.context.end(), '\n', ' ');
  return fmt::format("{} near `{}`", parts.reason, parts.context);
}

// " at line N" for a JSON syntax error whose quoted context occurs once in the input.
std::string LineOf(const util::Status& status, std::string_view text) {
  const JsonErrorParts parts = SplitJsonError(status);
  if (parts.context.empty()) return "";
  const size_t at = text.find(parts.context);
  if (at == std::string_view::npos || text.find(parts.context, at + 1) != std::string_view::npos) {
    return "";
  }
  const size_t offset = std::min(at + parts.caret, text.size());
  return fmt::format(" at line {}", 1 + std::count(text.begin(), text.begin() + offset, '\n'));
}

// Length of the run of decimal digits starting at text[i].
size_t Digits(std::string_view text, size_t i) {
  size_t n = 0;
  while (i + n < text.size() && text[i + n] >= '0' && text[i + n] <= '9') ++n;
  return n;
}

// The YAML 1.2 core schema's int and float patterns, [-+]? [0-9]+ and
// [-+]? ( \. [0-9]+ | [0-9]+ ( \. [0-9]* )? ) ( [eE] [-+]? [0-9]+ )?.
bool IsYamlInt(std::string_view text) {
  const size_t sign = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
  const size_t digits = Digits(text, sign);
  return digits > 0 && sign + digits == text.size();
}

bool IsYamlFloat(std::string_view text) {
  size_t i = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
  const size_t integer_digits = Digits(text, i);
  i += integer_digits;
  size_t fraction_digits = 0;
  if (i < text.size() && text[i] == '.') {
    fraction_digits = Digits(text, i + 1);
    i += 1 + fraction_digits;
  }
  if (integer_digits == 0 && fraction_digits == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '-' || text[i] == '+')) ++i;
    const size_t exponent_digits = Digits(text, i);
    if (exponent_digits == 0) return false;
    i += exponent_digits;
  }
  return i == text.size();
}

// YAML 1.2 core schema resolution of a plain (unquoted, untagged) scalar.
// https://yaml.org/spec/1.2.2/#1032-tag-resolution
void ResolvePlainScalar(const std::string& text, Value* out) {
  const std::string_view unsigned_text = !text.empty() && (text[0] == '-' || text[0] == '+')
                                             ? std::string_view(text).substr(1)
                                             : std::string_view(text);
  if (text == "true" || text == "True" || text == "TRUE") {
    out->set_bool_value(true);
  } else if (text == "false" || text == "False" || text == "FALSE") {
    out->set_bool_value(false);
  } else if (IsYamlInt(text) && text.size() > 15) {
    out->set_string_value(text);  // beyond 2^53: keep every digit (the JSON mapping takes strings)
  } else if (IsYamlInt(text) || IsYamlFloat(text)) {
    out->set_number_value(std::strtod(text.c_str(), nullptr));
  } else if (unsigned_text == ".inf" || unsigned_text == ".Inf" || unsigned_text == ".INF") {
    out->set_string_value(text[0] == '-' ? "-Infinity" : "Infinity");
  } else if (text == ".nan" || text == ".NaN" || text == ".NAN") {
    out->set_string_value("NaN");
  } else {
    out->set_string_value(text);
  }
}

// The conversion walks the YAML tree with aliases expanded; `budget` bounds the nodes it makes, so
// an alias bomb (a few hundred bytes of anchors referring to anchors, expanding to billions of
// nodes) is refused after kMaxYamlNodes, and `depth` bounds the nesting, which also stops a
// self-referencing alias (&a [*a], a cycle) instead of recursing until the stack overflows.
struct YamlWalk {
  size_t nodes = 0;
  std::string_view source;
  std::string_view text;  // the document, to check that quoted scalars are closed
};

void YamlToValue(const YAML::Node& node, const std::string& path, Value* out, YamlWalk* walk,
                 int depth) {
  const std::string where = path.empty() ? std::string(walk->source) : path;
  if (depth > kMaxYamlDepth) {
    throw SpecError(where,
                    fmt::format("nested deeper than {} levels (or an alias that refers to "
                                "itself); allowed: at most {} levels",
                                kMaxYamlDepth, kMaxYamlDepth),
                    0);
  }
  if (++walk->nodes > kMaxYamlNodes) {
    throw SpecError(std::string(walk->source),
                    fmt::format("more than {} values once aliases are expanded; allowed: at most "
                                "{} values",
                                kMaxYamlNodes, kMaxYamlNodes),
                    0);
  }
  // Tags: none ("?"), the quoted-scalar "!", and the core schema's own; anything else
  // (application tags such as !!python/object or !custom) is refused rather than ignored.
  const std::string& tag = node.Tag();
  if (!tag.empty() && tag != "?" && tag != "!" && !tag.starts_with("tag:yaml.org,2002:")) {
    throw SpecError(where,
                    fmt::format("line {}: the tag '{}' is not allowed; allowed: plain YAML "
                                "values (no tags)",
                                node.Mark().line + 1, tag),
                    0);
  }
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      auto* fields = out->mutable_struct_value()->mutable_fields();
      for (const auto& entry : node) {
        if (!entry.first.IsScalar()) {
          throw SpecError(path.empty() ? std::string("job") : path,
                          fmt::format("line {}: a key must be a plain name; allowed: field names",
                                      entry.first.Mark().line + 1),
                          0);
        }
        const std::string key = entry.first.Scalar();
        const std::string child = path.empty() ? key : path + "." + key;
        if (fields->count(key) != 0) {
          throw SpecError(
              child,
              fmt::format("line {}: given twice; allowed: once", entry.first.Mark().line + 1), 0);
        }
        YamlToValue(entry.second, child, &(*fields)[key], walk, depth + 1);
      }
      return;
    }
    case YAML::NodeType::Sequence: {
      auto* values = out->mutable_list_value();
      int i = 0;
      for (const auto& element : node) {
        YamlToValue(element, fmt::format("{}[{}]", path, i++), values->add_values(), walk,
                    depth + 1);
      }
      return;
    }
    case YAML::NodeType::Scalar:
      // "!" is yaml-cpp's tag for quoted scalars; an explicit !!str also means string.
      if (node.Tag() == "!" && node.Mark().pos >= 0 &&
          !YamlQuotedScalarIsClosed(walk->text, static_cast<size_t>(node.Mark().pos))) {
        throw SpecError(where,
                        fmt::format("line {}: a quote that is never closed; allowed: a closed "
                                    "'single' or \"double\" quoted value",
                                    node.Mark().line + 1),
                        0);
      }
      if (node.Tag() == "!" || node.Tag() == "tag:yaml.org,2002:str") {
        out->set_string_value(node.Scalar());
      } else {
        ResolvePlainScalar(node.Scalar(), out);
      }
      return;
    default:
      out->set_null_value(google::protobuf::NULL_VALUE);
      return;
  }
}

Value YamlTextToValue(std::string_view yaml_text, std::string_view source) {
  calib::YamlDocuments documents;
  try {
    documents = calib::LoadYamlDocuments(yaml_text);
  } catch (const YAML::Exception& e) {
    throw SpecError(std::string(source),
                    fmt::format("invalid YAML at line {}, column {}: {}", e.mark.line + 1,
                                e.mark.column + 1, e.msg),
                    0);
  }
  if (documents.count > 1) {
    throw SpecError(std::string(source),
                    "more than one YAML document (a --- separator, or a ',' outside [ ] and { }); "
                    "allowed: one document",
                    0);
  }
  Value value;
  YamlWalk walk{0, source, yaml_text};
  YamlToValue(documents.first, "", &value, &walk, 0);
  return value;
}

v1::Job ValueToJob(const Value& value, std::string_view source) {
  CheckJsonAgainstDescriptor(value, *v1::Job::descriptor());
  std::string json;
  util::Status status = util::MessageToJsonString(value, &json);
  if (!status.ok()) throw SpecError(std::string(source), StatusText(status), 0);
  v1::Job job;
  status = util::JsonStringToMessage(json, &job);
  // The descriptor check accepts what the JSON parser accepts; a failure here is reported as is.
  if (!status.ok()) throw SpecError(std::string(source), StatusText(status), 0);
  return job;
}

}  // namespace

v1::Job ParseJobJson(std::string_view json_text, std::string_view source) {
  CheckJsonSyntax(json_text, source);
  Value value;
  util::Status status = util::JsonStringToMessage(json_text, &value);
  if (!status.ok()) {
    throw SpecError(std::string(source),
                    "invalid JSON" + LineOf(status, json_text) + ": " + StatusText(status), 0);
  }
  return ValueToJob(value, source);
}

v1::Job ParseJobYaml(std::string_view yaml_text, std::string_view source) {
  return ValueToJob(YamlTextToValue(yaml_text, source), source);
}

std::string YamlToJson(std::string_view yaml_text, std::string_view source) {
  std::string json;
  util::Status status = util::MessageToJsonString(YamlTextToValue(yaml_text, source), &json);
  if (!status.ok()) throw SpecError(std::string(source), StatusText(status), 0);
  return json;
}

JobFile LoadJobFile(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string extension = path.extension().string();
  const bool is_json = extension == ".json";
  const bool is_yaml = extension == ".yaml" || extension == ".yml";
  if (!is_json && !is_yaml) {
    throw SpecError(name,
                    fmt::format("file extension \"{}\" is not allowed; allowed: .json, "
                                ".yaml, .yml",
                                extension),
                    0);
  }
  const std::string text = ReadInputFile(path, kMaxJobFileBytes, name);
  JobFile file;
  file.job = is_json ? ParseJobJson(text, name) : ParseJobYaml(text, name);
  file.base_dir = std::filesystem::absolute(path).parent_path();
  return file;
}

}  // namespace driftlab::app
