// `driftlab help` and `driftlab completion bash`, run as child processes: the help topics print
// the same text as --help, the man page holds every command's --help text, and the completion
// script, loaded into bash, completes commands, options and fixed option values.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_runner.h"

namespace {

using driftlab::testing::Result;
using driftlab::testing::RunDriftlab;
using driftlab::testing::RunProgram;
using driftlab::testing::Scratch;

// The command names as the overview lists them (the lines under "Subcommands:").
std::vector<std::string> CommandNames(const std::string& overview) {
  std::vector<std::string> names;
  std::istringstream in(overview.substr(overview.find("Subcommands:")));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string name;
    // A command's line starts with two blanks and its name; a description's continuation lines
    // start with more.
    if (line.size() > 2 && line.rfind("  ", 0) == 0 && line[2] != ' ' && words >> name) {
      names.push_back(name);
    }
  }
  return names;
}

TEST(HelpCli, HelpTopicIsTheTextOfDashDashHelp) {
  Scratch scratch;
  const Result overview = RunDriftlab({"--help"}, scratch);
  ASSERT_EQ(overview.exit_status, 0) << overview.err;
  const Result help = RunDriftlab({"help"}, scratch);
  ASSERT_EQ(help.exit_status, 0) << help.err;
  EXPECT_EQ(help.out, overview.out);
  const std::vector<std::string> names = CommandNames(overview.out);
  ASSERT_GE(names.size(), 15u) << overview.out;
  for (const std::string& name : names) {
    const Result direct = RunDriftlab({name, "--help"}, scratch);
    const Result topic = RunDriftlab({"help", name}, scratch);
    ASSERT_EQ(direct.exit_status, 0) << name << ": " << direct.err;
    ASSERT_EQ(topic.exit_status, 0) << name << ": " << topic.err;
    EXPECT_EQ(topic.out, direct.out) << name;
  }
}

TEST(HelpCli, UnknownTopicIsBadInputNamingTheTopics) {
  Scratch scratch;
  const Result r = RunDriftlab({"help", "frobnicate"}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("no topic 'frobnicate'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("run"), std::string::npos) << r.err;
}

// The man page's text of a command, roff escapes undone (\- to -, \e to \, \& removed).
std::string Unroff(const std::string& roff) {
  std::string out;
  for (size_t i = 0; i < roff.size(); ++i) {
    if (roff[i] == '\\' && i + 1 < roff.size()) {
      const char next = roff[i + 1];
      if (next == '-') {
        out += '-';
      } else if (next == 'e') {
        out += '\\';
      } else if (next != '&') {
        out += roff.substr(i, 2);
      }
      ++i;
    } else {
      out += roff[i];
    }
  }
  return out;
}

TEST(HelpCli, ManPageHoldsEveryCommandsHelpText) {
  Scratch scratch;
  const Result man = RunDriftlab({"help", "--man"}, scratch);
  ASSERT_EQ(man.exit_status, 0) << man.err;
  EXPECT_EQ(man.out.rfind(".TH DRIFTLAB 1 ", 0), 0u) << man.out.substr(0, 200);
  for (const char* section : {".SH NAME", ".SH SYNOPSIS", ".SH COMMANDS", ".SH EXIT STATUS"}) {
    EXPECT_NE(man.out.find(section), std::string::npos) << section;
  }
  // No line may start a roff request by accident: every line is a request we wrote, or text.
  std::istringstream lines(man.out);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || (line[0] != '.' && line[0] != '\'')) continue;
    const std::string request = line.substr(0, 3);
    EXPECT_TRUE(request == ".TH" || request == ".SH" || request == ".SS" || request == ".nf" ||
                request == ".fi" || request == ".TP" || request == ".B ")
        << line;
  }
  const std::string text = Unroff(man.out);
  for (const std::string& name : CommandNames(RunDriftlab({"--help"}, scratch).out)) {
    const Result help = RunDriftlab({name, "--help"}, scratch);
    // The page is made with the program name "driftlab"; --help prints the path it was run as.
    std::string expected = help.out;
    const std::string path = DRIFTLAB_CLI;
    for (size_t at = expected.find(path); at != std::string::npos;
         at = expected.find(path, at + 1)) {
      expected.replace(at, path.size(), "driftlab");
    }
    EXPECT_NE(text.find(".SS driftlab " + name + "\n.nf\n" + expected + ".fi\n"), std::string::npos)
        << name;
  }
  const Result with_topic = RunDriftlab({"help", "run", "--man"}, scratch);
  EXPECT_EQ(with_topic.exit_status, 2);
}

// COMPREPLY of the completion function for the words typed so far (the last one being
// completed), one per line, sorted.
std::vector<std::string> Complete(const Scratch& scratch, const std::string& script,
                                  const std::vector<std::string>& words) {
  std::string array;
  for (const std::string& w : words) array += " '" + w + "'";
  const std::string driver = scratch.dir() / "driver.sh";
  std::ofstream(driver) << "source " << script << "\nCOMP_WORDS=(" << array
                        << ")\nCOMP_CWORD=" << words.size() - 1
                        << "\n_driftlab\nprintf '%s\\n' \"${COMPREPLY[@]}\"\n";
  const Result r = RunProgram({"/bin/bash", driver}, scratch);
  EXPECT_EQ(r.exit_status, 0) << r.err;
  std::vector<std::string> out;
  std::istringstream lines(r.out);
  std::string line;
  while (std::getline(lines, line)) {
    if (!line.empty()) out.push_back(line);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(CompletionCli, BashCompletesCommandsOptionsAndValues) {
  Scratch scratch;
  const Result r = RunDriftlab({"completion", "bash"}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string script = (scratch.dir() / "driftlab.bash").string();
  std::ofstream(script) << r.out;
  using V = std::vector<std::string>;
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "ru"}), V({"run"}));
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "re"}), V({"report", "result"}));
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "run", "--rep"}), V({"--report"}));
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "run", "-q", "--th"}), V({"--threads"}));
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "calibrate", "--loss", ""}),
            V({"cauchy", "huber", "none"}));
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "help", "val"}), V({"validate"}));
  // calibrate KIND DATA.csv: the kinds first, then files (an option's value not counted).
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "calibrate", "--loss", "huber", "re"}),
            V({"reference"}));
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "completion", ""}), V({"bash"}));
  // File names after an option that takes a file, and for positional arguments.
  std::ofstream(scratch.dir() / "probe_job.json") << "{}";
  const std::string prefix = (scratch.dir() / "probe_j").string();
  const V file = {(scratch.dir() / "probe_job.json").string()};
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "run", prefix}), file);
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "run", "x.json", "--out", prefix}), file);
  EXPECT_EQ(Complete(scratch, script, {"driftlab", "calibrate", "gyro", prefix}), file);
  // Every option that `run --help` lists is offered after `run -`.
  const V offered = Complete(scratch, script, {"driftlab", "run", "-"});
  for (const char* option :
       {"--out", "-o", "--report", "--runs", "--seed", "--shard", "--quiet", "--help"}) {
    EXPECT_TRUE(std::binary_search(offered.begin(), offered.end(), option)) << option;
  }
  EXPECT_EQ(RunDriftlab({"completion", "zsh"}, scratch).exit_status, 2);
}

}  // namespace
