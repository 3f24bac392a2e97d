// Hostile input: one test per kind of hostile input, run against the `driftlab` binary as a user
// (or an attacker) would. None may crash driftlab (SIGSEGV, abort: exit status >= 128), hang it,
// exhaust its memory, replace a file that is not driftlab's, or be accepted silently: each is
// refused with exit status 2 and a one-line message that names the field and the limit, or (for
// valid but extreme data) handled.
// No timing is asserted: a regression to super-linear work or a hang shows as the test's ctest
// timeout.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "support/cli_runner.h"
#include "support/report_html.h"

namespace {

namespace fs = std::filesystem;
using driftlab::testing::ReadFile;
using driftlab::testing::Result;
using driftlab::testing::RunDriftlab;
using driftlab::testing::Scratch;

fs::path Write(const Scratch& scratch, const std::string& name, const std::string& content) {
  const fs::path path = scratch.dir() / name;
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

int Lines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

// Refused as bad input: exit status 2 (not a signal), one line on stderr holding `fragment`.
void ExpectRefused(const Result& r, const std::string& fragment) {
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << "wanted '" << fragment << "' in: " << r.err;
}

// A small static CSV for `allan` with one rate column.
fs::path SmallCsv(const Scratch& scratch, const std::string& header) {
  std::string text = header + "\n";
  for (int k = 0; k < 64; ++k) text += std::to_string(0.001 * ((k * 7) % 13) - 0.006) + "\n";
  return Write(scratch, "rates.csv", text);
}

TEST(HostileInput, DeepParenthesesInAUnitAreRefusedNotAStackOverflow) {
  Scratch scratch;
  const fs::path csv = SmallCsv(scratch, "gyro_x");
  // 20 KB of '(': longer than a unit text may be (units.h kMaxUnitTextBytes = 128).
  ExpectRefused(RunDriftlab({"allan", csv.string(), "--rate", "100", "--unit",
                             std::string(20000, '(') + "deg/s"},
                            scratch),
                "a unit text of at most 128 bytes");
  // Short but nested 10 deep: over kMaxUnitNesting = 8.
  ExpectRefused(RunDriftlab({"allan", csv.string(), "--rate", "100", "--unit",
                             std::string(10, '(') + "deg/s" + std::string(10, ')')},
                            scratch),
                "nested deeper than 8 levels");
  // The same in a datasheet figure and in a CSV column name (the noise fit's unit suffix).
  const fs::path sheet =
      Write(scratch, "sheet.yaml", "gyro:\n  arw: \"0.1 " + std::string(20000, '(') + "deg\"\n");
  const Result datasheet = RunDriftlab({"datasheet", sheet.string()}, scratch);
  EXPECT_EQ(datasheet.exit_status, 2) << datasheet.err;
  EXPECT_EQ(Lines(datasheet.err), 1) << datasheet.err;
  const fs::path header = SmallCsv(scratch, "gyro_x_" + std::string(20000, '('));
  ExpectRefused(RunDriftlab({"allan", header.string(), "--rate", "100"}, scratch),
                "a column name of at most 256 bytes");
}

TEST(HostileInput, LongColumnNameIsRefusedBeforeTheUnitSuffixSearch) {
  // A 160 KB header: refused before a unit-suffix search over the whole name.
  Scratch scratch;
  std::string name = "gyro";
  while (name.size() < 160000) name += "_x";
  const fs::path csv = SmallCsv(scratch, name);
  ExpectRefused(RunDriftlab({"allan", csv.string(), "--rate", "100"}, scratch),
                "a column name of at most 256 bytes");
}

TEST(HostileInput, YamlSelfReferenceAndAliasBombAreRefused) {
  Scratch scratch;
  // A node that contains itself: the YAML -> JSON conversion must not recurse without end.
  for (const std::string& text :
       {std::string("name: x\nmotion: &m {initial: *m}\n"), std::string("name: &n [*n]\n")}) {
    const fs::path job = Write(scratch, "self.yaml", text);
    const Result r = RunDriftlab({"validate", job.string()}, scratch);
    EXPECT_EQ(r.exit_status, 2) << text << "\n" << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
  }
  // "Billion laughs": 9 levels of 9 aliases each, 9^9 = 387 420 489 nodes from ~340 bytes.
  std::string bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x]\n";
  for (int level = 1; level <= 8; ++level) {
    const std::string prev = "*a" + std::to_string(level - 1);
    bomb += "a" + std::to_string(level) + ": &a" + std::to_string(level) + " [" + prev;
    for (int k = 1; k < 9; ++k) bomb += ", " + prev;
    bomb += "]\n";
  }
  const fs::path job = Write(scratch, "bomb.yaml", bomb);
  ExpectRefused(RunDriftlab({"validate", job.string()}, scratch), "1000000");
}

TEST(HostileInput, YamlMultipleDocumentsAndTagsAreRefused) {
  Scratch scratch;
  const fs::path two = Write(scratch, "two.yaml", "name: a\n---\nname: b\n");
  EXPECT_EQ(RunDriftlab({"validate", two.string()}, scratch).exit_status, 2);
  const fs::path tag = Write(scratch, "tag.yaml", "name: !!binary aGVsbG8=\n");
  EXPECT_EQ(RunDriftlab({"validate", tag.string()}, scratch).exit_status, 2);
}

TEST(HostileInput, DeeplyNestedJsonIsRefusedAtTheDepthLimit) {
  // 40 000 levels: refused before protobuf's JSON parser (super-linear in the depth) sees them.
  Scratch scratch;
  const fs::path job =
      Write(scratch, "deep.json", std::string(40000, '[') + std::string(40000, ']'));
  ExpectRefused(RunDriftlab({"validate", job.string()}, scratch), "64");
}

TEST(HostileInput, NonJsonSyntaxIsRefused) {
  Scratch scratch;
  const std::string base = ReadFile(kCliData / "mc_small.json");
  // A trailing comma before the final '}'.
  const size_t last = base.rfind('}');
  const fs::path comma = Write(scratch, "comma.json", base.substr(0, last) + ",}\n");
  EXPECT_EQ(RunDriftlab({"validate", comma.string()}, scratch).exit_status, 2);
  std::string quoted = base;
  quoted.replace(quoted.find("\"mc_small\""), 10, "'mc_small'");
  const fs::path single = Write(scratch, "single.json", quoted);
  EXPECT_EQ(RunDriftlab({"validate", single.string()}, scratch).exit_status, 2);
}

TEST(HostileInput, TooManySegmentsAreRefusedBeforeTheWork) {
  // A job of more segments than allowed is refused by its size, before it is validated. Repeated
  // fields hold at most 100 000 entries (schema_check.h kMaxJobRepeatedFieldSize).
  Scratch scratch;
  std::string job = R"({"name": "many", "motion": {"initial": {"lat_deg": 1}, "segments": [)";
  for (int k = 0; k < 100001; ++k)
    job += (k ? "," : "") + std::string(R"({"static":{"duration_s":1}})");
  job += R"(]}, "rate_hz": 10, "sensor": {"preset": "tactical"}})";
  const fs::path path = Write(scratch, "many.json", job);
  ExpectRefused(RunDriftlab({"validate", path.string()}, scratch), "100000");
}

TEST(HostileInput, OutputNeverReplacesASymlinkOrAFifo) {
  Scratch scratch;
  const fs::path target = Write(scratch, "precious.txt", "keep me\n");
  const fs::path link = scratch.dir() / "link.json";
  fs::create_symlink(target, link);
  const fs::path sheet = kCliData / "datasheet_tactical.yaml";
  ExpectRefused(RunDriftlab({"datasheet", sheet.string(), "--out", link.string()}, scratch),
                "symbolic link");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(ReadFile(target), "keep me\n");
  // Opening a FIFO for writing would block until a reader comes: refused before that.
  const fs::path fifo = scratch.dir() / "fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(RunDriftlab({"datasheet", sheet.string(), "--out", fifo.string()}, scratch).exit_status,
            2);
  EXPECT_TRUE(fs::is_fifo(fifo));
  // A missing directory: the system's reason, never "Success". A short path, so that the message
  // (its echoed paths cut at kMaxMessageValueBytes) keeps the reason after them.
  const Result missing = RunDriftlab(
      {"datasheet", sheet.string(), "--out", "/nonexistent-driftlab-test-dir/such.json"}, scratch);
  EXPECT_NE(missing.exit_status, 0);
  EXPECT_EQ(missing.err.find("Success"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("No such file or directory"), std::string::npos) << missing.err;
}

TEST(HostileInput, InputsThatAreNotRegularFilesOrAreEmptyAreRefused) {
  // /dev/zero as a CSV or datasheet (an endless read), an empty file or a directory as a
  // datasheet (an empty model): all refused.
  Scratch scratch;
  EXPECT_EQ(RunDriftlab({"datasheet", "/dev/zero"}, scratch).exit_status, 2);
  EXPECT_EQ(RunDriftlab({"allan", "/dev/zero", "--rate", "100"}, scratch).exit_status, 2);
  EXPECT_EQ(RunDriftlab({"validate", "/dev/zero"}, scratch).exit_status, 2);
  EXPECT_EQ(RunDriftlab({"datasheet", scratch.dir().string()}, scratch).exit_status, 2);
  const fs::path empty = Write(scratch, "empty.yaml", "");
  const Result r = RunDriftlab({"datasheet", empty.string()}, scratch);
  EXPECT_EQ(r.exit_status, 2) << r.out;
  EXPECT_TRUE(r.out.empty()) << r.out;
  // A motion file that is a device.
  const fs::path motion =
      Write(scratch, "motion_dev.json",
            R"({"name": "dev", "motion": {"truth_profile_file": {"path": )"
            R"("/dev/zero"}}, "rate_hz": 10, "sensor": {"preset": "tactical"}})");
  ExpectRefused(RunDriftlab({"validate", motion.string()}, scratch), "/dev/zero");
}

TEST(HostileInput, UnsignedOptionsAreParsedStrictlyOnOneLine) {
  // --seed -1, 2^64 and 40 digits must not wrap to 2^64 - 1, nor --runs "" pass: all refused.
  Scratch scratch;
  const std::string job = (kCliData / "mc_small.json").string();
  const std::string out = (scratch.dir() / "r.json").string();
  for (const std::vector<std::string>& extra : {std::vector<std::string>{"--seed", "-1"},
                                                {"--seed", "18446744073709551616"},
                                                {"--seed", std::string(40, '9')},
                                                {"--runs", ""},
                                                {"--runs", "-1"}}) {
    std::vector<std::string> args = {"run", job, "--out", out};
    args.insert(args.end(), extra.begin(), extra.end());
    const Result r = RunDriftlab(args, scratch);
    EXPECT_EQ(r.exit_status, 2) << extra[0] << " '" << extra[1] << "': " << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(extra[0]), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(HostileInput, TokensWithControlOrNonAsciiBytesAreRefusedBeforeGrpc) {
  // A token with a CR, a newline or a non-ASCII byte (gRPC aborts on such metadata) is refused. The
  // server address is never contacted: the token is checked first (port 1 would refuse anyway).
  Scratch scratch;
  const std::string job = (kCliData / "mc_small.json").string();
  for (const std::string& token : {std::string("ab\rcd"), std::string("ab\ncd"),
                                   std::string("t\xc3\xb6ken"), std::string("a b")}) {
    const Result r = RunDriftlab({"run", job, "--out", (scratch.dir() / "r.json").string(),
                                  "--server", "127.0.0.1:1", "--token", token},
                                 scratch);
    EXPECT_EQ(r.exit_status, 2) << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("token"), std::string::npos) << r.err;
  }
}

// `path` with every "mean": value of an epoch component replaced, alternately, by +v and -v.
std::string WithExtremeMeans(const std::string& json, const std::string& v) {
  const std::regex mean(R"re("mean": [-0-9.eE+]+)re");
  std::string out;
  auto begin = std::sregex_iterator(json.begin(), json.end(), mean);
  size_t copied = 0;
  int k = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it, ++k) {
    out += json.substr(copied, it->position() - copied);
    out += std::string("\"mean\": ") + (k % 2 ? "-" : "") + v;
    copied = it->position() + it->length();
  }
  return out + json.substr(copied);
}

TEST(HostileInput, ReportRefusesMeansItsPerRunValuesDoNotGive) {
  // A structurally valid result whose epoch means were edited to +-1e308: `report` checks the
  // statistics against the per-run values before rendering (result_check.h), refuses with exit 2
  // naming the field, and writes nothing. (The renderer itself with such values:
  // tests/report/result_report_test.cc, HtmlReport.ExtremeValuesRenderWithoutNonFinite.)
  Scratch scratch;
  const std::string text = WithExtremeMeans(ReadFile(kCliData / "gate_baseline.json"), "1e308");
  ASSERT_NE(text.find("\"mean\": -1e308"), std::string::npos);
  const fs::path result = Write(scratch, "extreme.json", text);
  const fs::path html = scratch.dir() / "extreme.html";
  const Result r = RunDriftlab({"report", result.string(), "--out", html.string()}, scratch);
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find("extreme.json: epochs[5].components[0].mean: -1e+308 is not allowed"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(html));
}

TEST(HostileInput, MergeRefusesCountsThatWouldOverflow) {
  // `merge` of hand-edited huge counts: refused rather than summed past the signed range
  // (undefined behaviour, a negative count).
  Scratch scratch;
  const std::string job = (kCliData / "mc_small.json").string();
  std::vector<std::string> shards;
  for (const char* shard : {"0/2", "1/2"}) {
    const std::string out = (scratch.dir() / (std::string("s") + shard[0] + ".json")).string();
    ASSERT_EQ(RunDriftlab({"run", job, "--runs", "4", "--shard", shard, "--out", out}, scratch)
                  .exit_status,
              0);
    std::string text = ReadFile(out);
    const std::regex samples(R"re("samples": "[0-9]+")re");
    ASSERT_TRUE(std::regex_search(text, samples));
    text = std::regex_replace(text, samples, R"("samples": "18446744073709551615")");
    std::ofstream(out) << text;
    shards.push_back(out);
  }
  const fs::path merged = scratch.dir() / "merged.json";
  ExpectRefused(RunDriftlab({"merge", shards[0], shards[1], "--out", merged.string()}, scratch),
                "timings.samples");
  EXPECT_FALSE(fs::exists(merged));
}

}  // namespace
