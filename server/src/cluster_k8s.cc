// The Kubernetes backend (cluster.h): one Indexed Job per driftlab job, created with
// `kubectl create -f -` from the template; status from `kubectl get job NAME -o json`.
#include <fmt/format.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "driftlab/server/cluster.h"
#include "driftlab/slurm/shard_array.h"
#include "driftlab/spec_error.h"

namespace driftlab::server {
namespace {

namespace fs = std::filesystem;
using google::protobuf::Struct;
using google::protobuf::Value;

std::string JsonEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
        } else {
          out += c;
        }
    }
  }
  return out;
}

const Value* Field(const Struct& s, const std::string& name) {
  const auto it = s.fields().find(name);
  return it == s.fields().end() ? nullptr : &it->second;
}

uint32_t Count(const Struct& status, const std::string& name) {
  const Value* v = Field(status, name);
  if (v == nullptr) return 0;
  if (v->kind_case() != Value::kNumberValue || !(v->number_value() >= 0) ||
      v->number_value() > 1e9 || std::floor(v->number_value()) != v->number_value()) {
    throw ClusterError(fmt::format("Job .status.{}: not a count", name));
  }
  return static_cast<uint32_t>(v->number_value());
}

std::string Text(const Struct& s, const std::string& name) {
  const Value* v = Field(s, name);
  return v != nullptr && v->kind_case() == Value::kStringValue ? v->string_value() : "";
}

class KubernetesRun : public ClusterRun {
 public:
  KubernetesRun(const ClusterOptions& options, const std::string& job_id,
                const v1::SubmitJobRequest& request, uint32_t shards)
      : options_(options),
        request_(request),
        job_id_(job_id),
        name_("driftlab-" + job_id),
        dir_(options.work_dir / job_id) {
    shards_ = shards;
  }

  void Submit() override {
    std::string manifest;
    try {
      fs::create_directories(dir_);
      for (uint32_t i = 0; i < shards_; ++i) fs::remove(dir_ / fmt::format("shard-{}.json", i));
      const std::vector<std::string> extra = WriteClusterJobFile(dir_, request_);
      std::ifstream in(options_.k8s_template);
      if (!in) throw ClusterError("cannot read " + options_.k8s_template.string());
      std::stringstream text;
      text << in.rdbuf();
      KubernetesJobParameters p;
      p.name = name_;
      p.name_space = options_.k8s_namespace;
      p.job_id = job_id_;
      p.image = options_.k8s_image;
      p.shards = shards_;
      p.claim = options_.k8s_claim;
      p.work_dir = options_.work_dir.string();
      p.args = KubernetesShardArgs((dir_ / "job.json").string(), shards_, dir_.string(), extra);
      manifest = RenderKubernetesJob(text.str(), p);
    } catch (const ClusterError&) {
      throw;
    } catch (const std::exception& e) {
      throw ClusterError(fmt::format("{}: {}", dir_.string(), e.what()));
    }
    const slurm::CommandOutput r = slurm::RunCommand({"kubectl", "create", "-f", "-"}, manifest);
    if (r.status != 0) {
      throw ClusterError(
          fmt::format("kubectl create failed (status {}): {}", r.status, MessageText(r.text, 500)));
    }
  }

  void Attach(const std::string& handle) override {
    std::istringstream words(handle);
    std::string kind;
    words >> kind >> name_;
  }

  std::string Handle() const override { return "k8s " + name_; }

  std::optional<ClusterProgress> Poll(std::vector<std::string>*, std::string* warning) override {
    const slurm::CommandOutput r = slurm::RunCommand(
        {"kubectl", "get", "job", name_, "--namespace", options_.k8s_namespace, "-o", "json"});
    if (r.status != 0) {
      if (r.text.find("NotFound") != std::string::npos) {
        throw ClusterError(fmt::format("the Kubernetes Job {} no longer exists", name_));
      }
      *warning =
          fmt::format("kubectl get job failed (status {}): {}", r.status, MessageText(r.text, 300));
      return std::nullopt;
    }
    const KubernetesJobStatus status = ParseKubernetesJob(r.text, shards_);
    if (status.failed_job) {
      throw ClusterError(fmt::format("the Kubernetes Job {} failed ({}; failed indexes: {})", name_,
                                     status.failure, fmt::join(status.failed_indexes, ",")));
    }
    return KubernetesProgress(status, shards_);
  }

  bool Cancel() override {
    return slurm::RunCommand({"kubectl", "delete", "job", name_, "--namespace",
                              options_.k8s_namespace, "--wait=false"})
               .status == 0;
  }

  v1::JobResult Merge(const std::string& engine_version) override {
    return slurm::MergeShardResults(dir_, shards_, engine_version);
  }

 private:
  ClusterOptions options_;
  v1::SubmitJobRequest request_;
  std::string job_id_;
  std::string name_;
  fs::path dir_;
};

}  // namespace

std::unique_ptr<ClusterRun> MakeKubernetesRun(const ClusterOptions& options,
                                              const std::string& job_id,
                                              const v1::SubmitJobRequest& request,
                                              uint32_t shards) {
  return std::make_unique<KubernetesRun>(options, job_id, request, shards);
}

std::set<uint32_t> ParseIndexList(const std::string& text, uint32_t completions,
                                  const std::string& field) {
  std::set<uint32_t> out;
  if (text.empty()) return out;
  const auto bad = [&] {
    return ClusterError(
        fmt::format("{}: \"{}\" is not an index list like \"1,3-5,7\" of indexes "
                    "0 to {}",
                    field, MessageText(text, 200), completions - 1));
  };
  std::istringstream items(text);
  std::string item;
  int64_t last = -1;
  while (std::getline(items, item, ',')) {
    unsigned first = 0, end = 0;
    int used = 0;
    if (std::sscanf(item.c_str(), "%u-%u%n", &first, &end, &used) == 2 &&
        used == static_cast<int>(item.size())) {
      if (end <= first) throw bad();
    } else if (std::sscanf(item.c_str(), "%u%n", &first, &used) == 1 &&
               used == static_cast<int>(item.size())) {
      end = first;
    } else {
      throw bad();
    }
    if (static_cast<int64_t>(first) <= last || end >= completions || item[0] == '+' ||
        item[0] == '-' || item[0] == ' ') {
      throw bad();
    }
    for (uint32_t i = first; i <= end; ++i) out.insert(i);
    last = end;
  }
  if (text.back() == ',') throw bad();
  return out;
}

KubernetesJobStatus ParseKubernetesJob(const std::string& json, uint32_t completions) {
  Struct job;
  google::protobuf::util::JsonParseOptions options;
  if (!google::protobuf::util::JsonStringToMessage(json, &job, options).ok() ||
      Text(job, "kind") != "Job") {
    throw ClusterError("kubectl did not print a Job object: " + MessageText(json, 200));
  }
  KubernetesJobStatus out;
  const Value* status_value = Field(job, "status");
  if (status_value == nullptr) return out;  // not yet observed by the Job controller
  if (status_value->kind_case() != Value::kStructValue)
    throw ClusterError("Job .status: not an object");
  const Struct& status = status_value->struct_value();
  out.active = Count(status, "active");
  out.succeeded = Count(status, "succeeded");
  out.failed = Count(status, "failed");
  out.completed_indexes =
      ParseIndexList(Text(status, "completedIndexes"), completions, "Job .status.completedIndexes");
  out.failed_indexes =
      ParseIndexList(Text(status, "failedIndexes"), completions, "Job .status.failedIndexes");
  const Value* conditions = Field(status, "conditions");
  if (conditions != nullptr && conditions->kind_case() == Value::kListValue) {
    for (const Value& c : conditions->list_value().values()) {
      if (c.kind_case() != Value::kStructValue) continue;
      const Struct& condition = c.struct_value();
      if (Text(condition, "status") != "True") continue;
      const std::string type = Text(condition, "type");
      if (type == "Complete" || type == "SuccessCriteriaMet") out.complete = true;
      if (type == "Failed" || type == "FailureTarget") {
        out.failed_job = true;
        out.failure =
            MessageText(Text(condition, "reason") + ": " + Text(condition, "message"), 300);
      }
    }
  }
  return out;
}

ClusterProgress KubernetesProgress(const KubernetesJobStatus& status, uint32_t completions) {
  ClusterProgress p;
  p.total = completions;
  p.done_shards.assign(status.completed_indexes.begin(), status.completed_indexes.end());
  p.done = static_cast<uint32_t>(p.done_shards.size());
  // A Complete Job has every index done; before completedIndexes is written, count succeeded.
  if (status.complete) {
    p.done = completions;
    p.done_shards.clear();
    for (uint32_t i = 0; i < completions; ++i) p.done_shards.push_back(i);
  }
  p.running = std::min(status.active, completions - p.done);
  const uint32_t failed_for_good = static_cast<uint32_t>(status.failed_indexes.size());
  const uint32_t accounted = p.done + p.running + failed_for_good;
  p.queued = accounted < completions ? completions - accounted : 0;
  p.text = fmt::format("k8s: {}/{} shards done, {} running, {} queued", p.done, completions,
                       p.running, p.queued);
  return p;
}

std::string RenderKubernetesJob(const std::string& template_text,
                                const KubernetesJobParameters& parameters) {
  std::string args = "[";
  for (size_t i = 0; i < parameters.args.size(); ++i) {
    args += (i ? ", \"" : "\"") + JsonEscape(parameters.args[i]) + "\"";
  }
  args += "]";
  const std::map<std::string, std::string> values = {
      {"NAME", JsonEscape(parameters.name)},
      {"NAMESPACE", JsonEscape(parameters.name_space)},
      {"JOB_ID", JsonEscape(parameters.job_id)},
      {"IMAGE", JsonEscape(parameters.image)},
      {"SHARDS", std::to_string(parameters.shards)},
      {"CLAIM", JsonEscape(parameters.claim)},
      {"WORK_DIR", JsonEscape(parameters.work_dir)},
      {"ARGS", args}};
  std::string out;
  size_t at = 0;
  while (true) {
    const size_t open = template_text.find("${", at);
    if (open == std::string::npos) break;
    const size_t close = template_text.find('}', open);
    if (close == std::string::npos) {
      throw ClusterError("Kubernetes Job template: \"${\" without \"}\"");
    }
    const std::string key = template_text.substr(open + 2, close - open - 2);
    const auto it = values.find(key);
    if (it == values.end()) {
      throw ClusterError(fmt::format(
          "Kubernetes Job template: unknown placeholder ${{{}}} (known: NAME, NAMESPACE, JOB_ID, "
          "IMAGE, SHARDS, CLAIM, WORK_DIR, ARGS)",
          MessageText(key, 100)));
    }
    out += template_text.substr(at, open - at) + it->second;
    at = close + 1;
  }
  return out + template_text.substr(at);
}

std::vector<std::string> KubernetesShardArgs(const std::string& job_file, uint32_t shards,
                                             const std::string& work_dir,
                                             const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"run", job_file, "--quiet",
                                   fmt::format("--shard=$(JOB_COMPLETION_INDEX)/{}", shards),
                                   "--out=" + work_dir + "/shard-$(JOB_COMPLETION_INDEX).json"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

}  // namespace driftlab::server
