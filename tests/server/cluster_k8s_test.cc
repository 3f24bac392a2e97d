// The Kubernetes backend without a cluster (cluster.h): the status logic against recorded batch/v1
// Job objects (tests/server/data/k8s, written from the Kubernetes API reference "Job v1 batch"),
// and the manifest generated from deploy/k8s/server-shard-job.yaml, parsed back with yaml-cpp.
// `kubectl apply --dry-run=client` is not run: it needs an API server for discovery and the
// OpenAPI schema, and there is none here.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>

#include "driftlab/server/cluster.h"

namespace driftlab::server {
namespace {

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

KubernetesJobStatus Fixture(const std::string& name) {
  return ParseKubernetesJob(
      ReadText(std::filesystem::path(DRIFTLAB_SOURCE_DIR) / "tests/server/data/k8s" / name), 4);
}

TEST(KubernetesIndexList, ParsesTheApiReferenceExample) {
  // The API reference's example: indexes 1, 3, 4, 5 and 7 are "1,3-5,7".
  EXPECT_EQ(ParseIndexList("1,3-5,7", 8, "f"), (std::set<uint32_t>{1, 3, 4, 5, 7}));
  EXPECT_TRUE(ParseIndexList("", 8, "f").empty());
  EXPECT_EQ(ParseIndexList("0-3", 4, "f"), (std::set<uint32_t>{0, 1, 2, 3}));
}

TEST(KubernetesIndexList, RejectsWhatTheFormatDoesNotAllow) {
  for (const char* bad : {"3,1", "1-", "-1", "a", "1,,2", "1,", "4", "2-1", " 1", "1-3,3"}) {
    EXPECT_THROW(ParseIndexList(bad, 4, "Job .status.completedIndexes"), ClusterError) << bad;
  }
  try {
    ParseIndexList("0,7", 4, "Job .status.completedIndexes");
    FAIL();
  } catch (const ClusterError& e) {
    EXPECT_NE(std::string(e.what()).find("Job .status.completedIndexes: \"0,7\""),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("0 to 3"), std::string::npos) << e.what();
  }
}

TEST(KubernetesJobStatus, NewJobWithoutStatusIsAllQueued) {
  const KubernetesJobStatus status = Fixture("job_created.json");
  EXPECT_FALSE(status.complete);
  EXPECT_FALSE(status.failed_job);
  const ClusterProgress p = KubernetesProgress(status, 4);
  EXPECT_EQ(p.done, 0u);
  EXPECT_EQ(p.running, 0u);
  EXPECT_EQ(p.queued, 4u);
}

TEST(KubernetesJobStatus, RunningJobCountsCompletedIndexesAndActivePods) {
  const KubernetesJobStatus status = Fixture("job_running.json");
  EXPECT_EQ(status.active, 2u);
  EXPECT_EQ(status.succeeded, 1u);
  EXPECT_EQ(status.failed, 1u);  // a failed pod of an index that is retried: not a failed Job
  EXPECT_FALSE(status.failed_job);
  const ClusterProgress p = KubernetesProgress(status, 4);
  EXPECT_EQ(p.done_shards, (std::vector<uint32_t>{1}));
  EXPECT_EQ(p.done, 1u);
  EXPECT_EQ(p.running, 2u);
  EXPECT_EQ(p.queued, 1u);  // 4 - 1 done - 2 active: the index waiting for its retry
  EXPECT_EQ(p.text, "k8s: 1/4 shards done, 2 running, 1 queued");
}

TEST(KubernetesJobStatus, CompleteJobHasEveryShardDone) {
  const KubernetesJobStatus status = Fixture("job_complete.json");
  EXPECT_TRUE(status.complete);
  EXPECT_FALSE(status.failed_job);
  const ClusterProgress p = KubernetesProgress(status, 4);
  EXPECT_EQ(p.done, 4u);
  EXPECT_EQ(p.done_shards, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(p.running + p.queued, 0u);
}

TEST(KubernetesJobStatus, FailedIndexFailsTheJobWithTheConditionsReason) {
  const KubernetesJobStatus status = Fixture("job_failed_index.json");
  EXPECT_TRUE(status.failed_job);
  EXPECT_FALSE(status.complete);
  EXPECT_EQ(status.failure, "FailedIndexes: Job has failed indexes");
  EXPECT_EQ(status.failed_indexes, (std::set<uint32_t>{1}));
  EXPECT_EQ(status.completed_indexes, (std::set<uint32_t>{0, 2, 3}));
}

TEST(KubernetesJobStatus, ConditionsWithStatusFalseAreIgnored) {
  // Suspended, with a "Complete" condition whose status is "False": neither done nor failed.
  const KubernetesJobStatus status = Fixture("job_suspended.json");
  EXPECT_FALSE(status.complete);
  EXPECT_FALSE(status.failed_job);
  EXPECT_EQ(KubernetesProgress(status, 4).queued, 4u);
}

TEST(KubernetesJobStatus, RejectsWhatIsNotAJob) {
  EXPECT_THROW(ParseKubernetesJob("not json", 4), ClusterError);
  EXPECT_THROW(ParseKubernetesJob(R"({"kind": "Pod"})", 4), ClusterError);
  EXPECT_THROW(ParseKubernetesJob(R"({"kind": "Job", "status": {"active": -1}})", 4), ClusterError);
  EXPECT_THROW(ParseKubernetesJob(R"({"kind": "Job", "status": {"completedIndexes": "9"}})", 4),
               ClusterError);
}

KubernetesJobParameters Parameters() {
  KubernetesJobParameters p;
  p.name = "driftlab-job-0123456789abcdef01234567";
  p.name_space = "driftlab";
  p.job_id = "job-0123456789abcdef01234567";
  p.image = "registry.example/driftlab:0.1";
  p.shards = 4;
  p.claim = "driftlab-shards";
  p.work_dir = "/shards/a \"quoted\" dir";  // JSON-escaped inside the template's quotes
  p.args = KubernetesShardArgs(p.work_dir + "/job-0123456789abcdef01234567/job.json", 4,
                               p.work_dir + "/job-0123456789abcdef01234567", {"--runs", "8"});
  return p;
}

TEST(KubernetesManifest, TemplateGivesAnIndexedJobWithTheShardCommand) {
  const std::string text =
      ReadText(std::filesystem::path(DRIFTLAB_SOURCE_DIR) / "deploy/k8s/server-shard-job.yaml");
  const KubernetesJobParameters p = Parameters();
  const YAML::Node job = YAML::Load(RenderKubernetesJob(text, p));
  EXPECT_EQ(job["apiVersion"].as<std::string>(), "batch/v1");
  EXPECT_EQ(job["kind"].as<std::string>(), "Job");
  EXPECT_EQ(job["metadata"]["name"].as<std::string>(), p.name);
  EXPECT_EQ(job["metadata"]["namespace"].as<std::string>(), "driftlab");
  EXPECT_EQ(job["metadata"]["labels"]["driftlab.io/job-id"].as<std::string>(), p.job_id);
  const YAML::Node spec = job["spec"];
  EXPECT_EQ(spec["completionMode"].as<std::string>(), "Indexed");
  EXPECT_EQ(spec["completions"].as<int>(), 4);
  EXPECT_EQ(spec["parallelism"].as<int>(), 4);
  EXPECT_EQ(spec["template"]["spec"]["restartPolicy"].as<std::string>(), "Never");
  const YAML::Node container = spec["template"]["spec"]["containers"][0];
  EXPECT_EQ(container["image"].as<std::string>(), p.image);
  EXPECT_EQ(container["command"][0].as<std::string>(), "/usr/local/bin/driftlab");
  std::vector<std::string> args;
  for (const YAML::Node& a : container["args"]) args.push_back(a.as<std::string>());
  const std::string dir = "/shards/a \"quoted\" dir/job-0123456789abcdef01234567";
  EXPECT_EQ(args, (std::vector<std::string>{
                      "run", dir + "/job.json", "--quiet", "--shard=$(JOB_COMPLETION_INDEX)/4",
                      "--out=" + dir + "/shard-$(JOB_COMPLETION_INDEX).json", "--runs", "8"}));
  EXPECT_EQ(container["volumeMounts"][0]["mountPath"].as<std::string>(), p.work_dir);
  EXPECT_EQ(container["volumeMounts"][0]["name"].as<std::string>(),
            spec["template"]["spec"]["volumes"][0]["name"].as<std::string>());
  EXPECT_EQ(spec["template"]["spec"]["volumes"][0]["persistentVolumeClaim"]["claimName"]
                .as<std::string>(),
            "driftlab-shards");
}

TEST(KubernetesManifest, UnknownPlaceholderIsNamed) {
  try {
    RenderKubernetesJob("name: ${NAME}\nimage: ${IMAGES}\n", Parameters());
    FAIL();
  } catch (const ClusterError& e) {
    EXPECT_NE(std::string(e.what()).find("${IMAGES}"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace driftlab::server
