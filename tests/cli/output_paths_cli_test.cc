// No writer destroys an input: every command that writes files compares its outputs with its
// inputs and with each other by device and inode, before any work, and exits 2 naming the
// option, whatever the spelling (the same path, ./X, d/../X, a symbolic or a hard link); the
// input is byte-identical afterwards. And the set of files `simulate` and `export` write is
// written as a set: Ctrl-C or a full disk leaves no temporary file and no incomplete set, and an
// output directory that cannot take files is found before the work.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_util.h"

namespace driftlab::cli_test {
namespace {

// A job of 2 runs over 10 s at 20 Hz: quick to run, a valid input for every result tool.
const char kTinyJob[] = R"({"name": "tiny", "rate_hz": 20,
  "motion": {"initial": {"lat_deg": 45, "lon_deg": 7}, "segments": [{"static": {"duration_s": 10}}]},
  "sensor": {"preset": "tactical"}, "monte_carlo": {"runs": 2, "epoch_interval_s": 1}})";

// The spellings of `path` a user could give for the same file, made in `dir`: itself, ./path
// relative to the working directory (the scratch directory), d/../name, a symbolic link and a
// hard link.
std::vector<std::string> Spellings(const fs::path& path, const Scratch& scratch) {
  fs::create_directories(scratch.dir() / "d");
  const fs::path symlink = scratch.dir() / ("symlink_to_" + path.filename().string());
  const fs::path hardlink = scratch.dir() / ("hardlink_to_" + path.filename().string());
  fs::remove(symlink);
  fs::remove(hardlink);
  fs::create_symlink(path, symlink);
  fs::create_hard_link(path, hardlink);
  return {path.string(), (path.parent_path() / "." / path.filename()).string(),
          (scratch.dir() / "d" / ".." / path.filename()).string(), symlink.string(),
          hardlink.string()};
}

// Refused before any work: exit 2, one line naming `option`, and `input` unchanged.
void ExpectRefused(const std::vector<std::string>& args, const std::string& option,
                   const fs::path& input, const Scratch& scratch) {
  const std::string before = ReadFile(input);
  const Result r = RunDriftlab(args, scratch);
  EXPECT_EQ(r.exit_status, 2) << r.out << r.err;
  EXPECT_EQ(r.err.rfind("error: " + option + ": ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("the same file as"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(input), before) << "the input changed";
}

// A result file of the tiny job (and its job file) in the scratch directory.
fs::path TinyResult(const Scratch& scratch, const std::string& name) {
  const fs::path job = Write(scratch.dir() / "tiny.json", kTinyJob);
  const fs::path result = scratch.dir() / name;
  const Result r = RunDriftlab({"run", job.string(), "--out", result.string(), "-q"}, scratch);
  EXPECT_EQ(r.exit_status, 0) << r.err;
  return result;
}

TEST(OutputPaths, RunRefusesAnOutputThatIsTheJobOrTheOtherOutput) {
  Scratch scratch;
  const fs::path job = Write(scratch.dir() / "tiny.json", kTinyJob);
  for (const std::string& same : Spellings(job, scratch)) {
    SCOPED_TRACE(same);
    ExpectRefused({"run", job.string(), "--out", same, "-q"}, "--out", job, scratch);
    ExpectRefused(
        {"run", job.string(), "--out", (scratch.dir() / "r.json").string(), "--report", same, "-q"},
        "--report", job, scratch);
  }
  // --out and --report naming one new file (two spellings): refused before the work.
  const fs::path result = scratch.dir() / "r.json";
  const Result r = RunDriftlab({"run", job.string(), "--out", result.string(), "--report",
                                (scratch.dir() / "d" / ".." / "r.json").string(), "-q"},
                               scratch);
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: --report: ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(result));
}

TEST(OutputPaths, RunRefusesAnOutputThatIsTheJobsMotionFile) {
  Scratch scratch;
  const fs::path profile = Write(
      scratch.dir() / "profile.csv",
      ReadFile(fs::path(DRIFTLAB_SOURCE_DIR) / "examples" / "motions" / "north_drive_profile.csv"));
  const fs::path job =
      Write(scratch.dir() / "profile_job.json",
            R"({"rate_hz": 10, "motion": {"truth_profile_file": {"path": "profile.csv"}},
                "monte_carlo": {"runs": 1}})");
  ExpectRefused({"run", job.string(), "--out", profile.string(), "-q"}, "--out", profile, scratch);
  // simulate writes truth.csv into its directory: a profile named truth.csv there is an input.
  fs::create_directories(scratch.dir() / "sim");
  const fs::path inside = Write(scratch.dir() / "sim" / "truth.csv", ReadFile(profile));
  const fs::path job2 = Write(scratch.dir() / "sim_job.json",
                              R"({"rate_hz": 10, "motion": {"truth_profile_file":
                                  {"path": "sim/truth.csv"}}})");
  ExpectRefused({"simulate", job2.string(), "--out", (scratch.dir() / "sim").string()},
                "--out truth.csv", inside, scratch);
}

TEST(OutputPaths, ResultToolsRefuseToReplaceTheirInputs) {
  Scratch scratch;
  const fs::path a = TinyResult(scratch, "a.json");
  ASSERT_TRUE(fs::exists(a));
  for (const std::string& same : Spellings(a, scratch)) {
    SCOPED_TRACE(same);
    ExpectRefused({"report", a.string(), "--out", same}, "--out", a, scratch);
    ExpectRefused({"merge", a.string(), "--out", same}, "--out", a, scratch);
    ExpectRefused(
        {"merge", a.string(), "--out", (scratch.dir() / "m.json").string(), "--report", same},
        "--report", a, scratch);
    ExpectRefused({"gate", a.string(), "--baseline", a.string(), "--junit", same}, "--junit", a,
                  scratch);
  }
}

TEST(OutputPaths, CalibrationAndDatasheetToolsRefuseToReplaceTheirInputs) {
  Scratch scratch;
  const fs::path csv =
      Write(scratch.dir() / "gyro.csv", ReadFile(kCliData / "calib_seed003_gyro.csv"));
  const fs::path sheet =
      Write(scratch.dir() / "sheet.yaml", ReadFile(kCliData / "datasheet_tactical.yaml"));
  std::string rates = "gyro_x_rad_per_s\n";
  for (int k = 0; k < 64; ++k) rates += std::to_string(0.001 * ((k * 7) % 13) - 0.006) + "\n";
  const fs::path data = Write(scratch.dir() / "rates.csv", rates);
  for (const std::string& same : Spellings(csv, scratch)) {
    SCOPED_TRACE(same);
    ExpectRefused({"calibrate", "reference", csv.string(), "--input-unit", "deg/s", "--output-unit",
                   "V", "--out", same},
                  "--out", csv, scratch);
  }
  for (const std::string& same : Spellings(sheet, scratch)) {
    SCOPED_TRACE(same);
    ExpectRefused({"datasheet", sheet.string(), "--out", same}, "--out", sheet, scratch);
  }
  for (const std::string& same : Spellings(data, scratch)) {
    SCOPED_TRACE(same);
    ExpectRefused({"allan", data.string(), "--rate", "100", "--out", same}, "--out", data, scratch);
    ExpectRefused({"allan", data.string(), "--rate", "100", "--columns", "gyro_x_rad_per_s",
                   "--fit", "--fit-json", same},
                  "--fit-json", data, scratch);
  }
}

// ---- simulate / export: the set of files ------------------------------------------------------

// A job long enough that simulate runs for seconds (2 h at 100 Hz: 720 000 samples).
const char kLongJob[] = R"({"name": "long", "rate_hz": 100,
  "motion": {"initial": {"lat_deg": 45, "lon_deg": 7}, "segments": [{"static": {"duration_s": 7200}}]},
  "sensor": {"preset": "tactical"}})";

// Hidden temporary files or directories driftlab leaves in `dir` (none are allowed).
std::vector<std::string> Leftovers(const fs::path& dir) {
  std::vector<std::string> out;
  if (!fs::exists(dir)) return out;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(".")) out.push_back(name);
  }
  return out;
}

// Starts the driftlab binary with `args` (stdout and stderr to files in the scratch directory).
pid_t Spawn(const std::vector<std::string>& args, const Scratch& scratch) {
  std::vector<std::string> argv_strings = {DRIFTLAB_CLI};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, (scratch.dir() / "spawn.out").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, (scratch.dir() / "spawn.err").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

// Size of the files under `dir` whose names start with '.' (the work in progress).
uintmax_t TemporaryBytes(const fs::path& dir) {
  uintmax_t bytes = 0;
  std::error_code error;
  for (auto it = fs::recursive_directory_iterator(dir, error);
       !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
    if (it->is_regular_file(error)) bytes += it->file_size(error);
  }
  return bytes;
}

// `command` on the long job, interrupted by `signal_number` once it has written data: exit 130,
// nothing left in the output directory (which it created, so it is gone too).
void ExpectInterruptLeavesNothing(const std::string& command, int signal_number) {
  Scratch scratch;
  const fs::path job = Write(scratch.dir() / "long.json", kLongJob);
  const fs::path out = scratch.dir() / "out";
  const pid_t pid = Spawn({command, job.string(), "--out", out.string()}, scratch);
  ASSERT_GT(pid, 0);
  // Wait (bounded, polling every 10 ms) until the command has written a megabyte of data.
  bool writing = false;
  for (int i = 0; i < 6000 && !writing; ++i) {
    writing = fs::exists(out) && TemporaryBytes(out) > (1u << 20);
    if (!writing) std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polling interval
  }
  ASSERT_TRUE(writing) << ReadFile(scratch.dir() / "spawn.err");
  kill(pid, signal_number);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 130) << ReadFile(scratch.dir() / "spawn.err");
  EXPECT_FALSE(fs::exists(out)) << "left: " << (fs::exists(out) ? Leftovers(out).size() : 0);
}

TEST(OutputSets, SimulateInterruptedBySigintLeavesNoFiles) {
  ExpectInterruptLeavesNothing("simulate", SIGINT);
}

TEST(OutputSets, ExportInterruptedBySigtermLeavesNoFiles) {
  ExpectInterruptLeavesNothing("export", SIGTERM);
}

TEST(OutputSets, AnOutputDirectoryThatTakesNoFilesIsFoundBeforeTheWork) {
  // /proc takes no new files, even for root: refused at once, with the option named, instead of
  // after two hours of simulated data.
  Scratch scratch;
  const fs::path job = Write(scratch.dir() / "long.json", kLongJob);
  for (const char* command : {"simulate", "export"}) {
    const Result r =
        RunDriftlab({command, job.string(), "--out", "/proc/driftlab-test/out"}, scratch);
    EXPECT_EQ(r.exit_status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("error: --out: ", 0), 0u) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  const Result run = RunDriftlab(
      {"run", job.string(), "--out", "/proc/driftlab-test/result.json", "--runs", "1000"}, scratch);
  EXPECT_EQ(run.exit_status, 2) << run.err;
  EXPECT_EQ(run.err.rfind("error: --out: ", 0), 0u) << run.err;
}

TEST(OutputSets, AFullDiskLeavesTheOlderSetUntouched) {
  // An older set of simulate's files, then a run that cannot write more than 200 kB per file
  // (RLIMIT_FSIZE through the shell's ulimit, SIGXFSZ ignored: writes fail with EFBIG as on a full
  // disk): exit 1, the older files byte-identical, no temporary file left.
  Scratch scratch;
  const fs::path job = Write(scratch.dir() / "job.json",
                             R"({"name": "short", "rate_hz": 100, "motion": {"initial":
                                 {"lat_deg": 45, "lon_deg": 7}, "segments": [{"static":
                                 {"duration_s": 600}}]}, "sensor": {"preset": "tactical"}})");
  const fs::path out = scratch.dir() / "out";
  fs::create_directories(out);
  std::vector<std::string> names = {"truth.csv", "imu.csv", "nav.csv", "errors.csv",
                                    "imu_ideal.csv"};
  for (const std::string& name : names) Write(out / name, "older " + name + "\n");
  const std::string command = "ulimit -f 200; trap '' XFSZ; exec '" + std::string(DRIFTLAB_CLI) +
                              "' simulate '" + job.string() + "' --out '" + out.string() + "' > '" +
                              (scratch.dir() / "o.txt").string() + "' 2> '" +
                              (scratch.dir() / "e.txt").string() + "'";
  const int status = std::system(("/bin/sh -c \"" + command + "\"").c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1) << ReadFile(scratch.dir() / "e.txt");
  EXPECT_NE(ReadFile(scratch.dir() / "e.txt").find("cannot write"), std::string::npos)
      << ReadFile(scratch.dir() / "e.txt");
  for (const std::string& name : names) {
    EXPECT_EQ(ReadFile(out / name), "older " + name + "\n") << name;
  }
  EXPECT_TRUE(Leftovers(out).empty()) << Leftovers(out).front();
}

}  // namespace
}  // namespace driftlab::cli_test
