// `driftlab help [TOPIC] [--man]` and `driftlab completion bash`: the offline reference and the
// shell completion, both generated from the command line itself (the CLI11 app that main.cc
// builds from every registered command), so they always say what `--help` says.
//   help             the text of `driftlab --help`
//   help COMMAND     the text of `driftlab COMMAND --help`
//   help --man       a man page (roff, section 1): every command's --help text, exit statuses
//   completion bash  a bash completion script: commands, each command's options, the values of
//                    options with a fixed set ({a,b,c} in --help), files elsewhere
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"

namespace driftlab::cli {
namespace {

// The registered commands in the order of --help (main.cc sorts them by name).
std::vector<const CLI::App*> Commands(const CLI::App& app) {
  std::vector<const CLI::App*> commands;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    commands.push_back(sub);
  }
  return commands;
}

// The overview as `driftlab --help` prints it. App::help() would describe the subcommand given on
// this command line (`help` itself), hence the formatter directly.
std::string Overview(const CLI::App& app, const std::string& name) {
  return app.get_formatter()->make_help(&app, name, CLI::AppFormatMode::Normal);
}

std::string JoinNames(const std::vector<const CLI::App*>& commands) {
  std::string names;
  for (const CLI::App* c : commands) names += (names.empty() ? "" : ", ") + c->get_name();
  return names;
}

// ---- man page ----------------------------------------------------------------------------

// Text as roff: backslashes escaped, hyphens as \- (so that options can be searched and copied),
// lines that would start a request (. or ') protected with \&.
std::string Roff(const std::string& text) {
  std::string out;
  bool line_start = true;
  for (char c : text) {
    if (line_start && (c == '.' || c == '\'')) out += "\\&";
    if (c == '\\') {
      out += "\\e";
    } else if (c == '-') {
      out += "\\-";
    } else {
      out += c;
    }
    line_start = c == '\n';
  }
  return out;
}

std::string ManPage(const CLI::App& app, const std::string& name) {
  std::string page =
      fmt::format(".TH DRIFTLAB 1 \"\" \"driftlab {}\" \"User Commands\"\n", DRIFTLAB_VERSION);
  page += ".SH NAME\n" + Roff(name) + " \\- " + Roff(app.get_description()) + "\n";
  page += ".SH SYNOPSIS\n.B " + Roff(name) + "\n\\fICOMMAND\\fR [\\fIOPTIONS\\fR] [\\fIARGS\\fR]\n";
  page += ".SH DESCRIPTION\n.nf\n" + Roff(Overview(app, name)) + ".fi\n";
  page += ".SH COMMANDS\n";
  for (const CLI::App* command : Commands(app)) {
    page += ".SS " + Roff(name + " " + command->get_name()) + "\n.nf\n" +
            Roff(command->help(name)) + ".fi\n";
  }
  page +=
      ".SH EXIT STATUS\n.TP\n0\nsuccess\n.TP\n1\nI/O or internal error; for \\fBgate\\fR, a "
      "regression\n.TP\n2\nbad input: job file, data file or command line (the message names "
      "the field, the value and the allowed range)\n";
  page +=
      ".SH ENVIRONMENT\n.TP\nDRIFTLAB_TOKEN\nbearer token of the commands that take "
      "\\-\\-server, when \\-\\-token is not given\n";
  page +=
      ".SH SEE ALSO\n\\fBdriftlab help\\fR \\fICOMMAND\\fR, docs/getting-started.md of the "
      "driftlab sources\n";
  return page;
}

// ---- bash completion -----------------------------------------------------------------------

// The values of an option with a fixed set, from its type text as --help prints it
// ("TEXT:{accel,gyro,imu,reference}"); empty when it has none.
std::vector<std::string> Choices(const CLI::Option* option) {
  const std::string type = option->get_type_name();
  const size_t open = type.find(":{");
  const size_t close = type.find('}', open);
  std::vector<std::string> choices;
  if (open == std::string::npos || close == std::string::npos) return choices;
  std::string list = type.substr(open + 2, close - open - 2);
  size_t start = 0;
  while (start <= list.size()) {
    size_t comma = list.find(',', start);
    if (comma == std::string::npos) comma = list.size();
    std::string item = list.substr(start, comma - start);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    if (!item.empty()) choices.push_back(item);
    start = comma + 1;
  }
  return choices;
}

// Words that bash may print unquoted inside a case pattern or a word list.
bool ShellSafe(const std::string& word) {
  return !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ||
           c == '/' || c == '+' || c == ':';
  });
}

std::string Words(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) {
    if (ShellSafe(w)) out += (out.empty() ? "" : " ") + w;
  }
  return out;
}

std::string BashCompletion(const CLI::App& app) {
  std::vector<std::string> command_names;
  for (const CLI::App* c : Commands(app)) command_names.push_back(c->get_name());
  std::string cases;
  for (const CLI::App* command : Commands(app)) {
    std::vector<std::string> flags;
    std::vector<std::string> valued;    // options that take a value
    std::vector<std::string> to_files;  // ... a file name or other free text
    std::vector<std::string> positionals;
    std::string choice_cases;
    for (const CLI::Option* option : command->get_options()) {
      const std::vector<std::string> choices = Choices(option);
      if (option->get_positional()) {
        // What each positional argument completes to: its fixed values, command names for
        // `help`, else file names.
        std::string words = choices.empty() ? "files" : Words(choices);
        if (command->get_name() == "help") words = Words(command_names);
        positionals.push_back(words);
        continue;
      }
      std::vector<std::string> names;
      for (const std::string& l : option->get_lnames()) names.push_back("--" + l);
      for (const std::string& s : option->get_snames()) names.push_back("-" + s);
      flags.insert(flags.end(), names.begin(), names.end());
      if (option->get_expected_max() == 0) continue;  // a flag: no value follows
      std::string pattern;
      for (const std::string& n : names) {
        if (!ShellSafe(n)) continue;
        pattern += (pattern.empty() ? "" : "|") + n;
        valued.push_back(n);
      }
      if (pattern.empty()) continue;
      if (!choices.empty()) {
        choice_cases += fmt::format("        {}) words=\"{}\" ;;\n", pattern, Words(choices));
      } else {
        to_files.push_back(pattern);
      }
    }
    std::string positional_words;
    for (const std::string& p : positionals) positional_words += " \"" + p + "\"";
    std::string file_case;
    for (const std::string& v : to_files) file_case += (file_case.empty() ? "" : "|") + v;
    cases +=
        fmt::format("    {})\n      options=\"{}\"\n      valued=\"{}\"\n      positionals=({})\n",
                    command->get_name(), Words(flags), Words(valued), positional_words);
    cases += "      case \"$prev\" in\n" + choice_cases;
    if (!file_case.empty()) cases += "        " + file_case + ") words=files ;;\n";
    cases += "      esac\n      ;;\n";
  }
  return fmt::format(
      R"(# bash completion of driftlab {version}, generated by `driftlab completion bash` from the
# command line that --help describes. Load it in this shell:   source <(driftlab completion bash)
# or for every shell:  driftlab completion bash > ~/.local/share/bash-completion/completions/driftlab
_driftlab() {{
  local cur="${{COMP_WORDS[COMP_CWORD]}}"
  local prev=""
  if ((COMP_CWORD > 0)); then prev="${{COMP_WORDS[COMP_CWORD - 1]}}"; fi
  local commands="{commands}"
  local command="" at=0 i
  for ((i = 1; i < COMP_CWORD; i++)); do
    case "${{COMP_WORDS[i]}}" in
      -*) ;;
      *) command="${{COMP_WORDS[i]}}"; at=$i; break ;;
    esac
  done
  if [[ -z $command ]]; then
    COMPREPLY=($(compgen -W "$commands --help --version" -- "$cur"))
    return
  fi
  local options="" valued="" words=""
  local -a positionals=()
  case "$command" in
{cases}    *) return ;;
  esac
  if [[ -z $words && $cur == -* ]]; then
    COMPREPLY=($(compgen -W "$options" -- "$cur"))
    return
  fi
  if [[ -z $words ]]; then
    # The how-manieth positional argument this is: words after the command that are neither
    # options nor an option's value.
    local n=0 skip=0 w
    for ((i = at + 1; i < COMP_CWORD; i++)); do
      w="${{COMP_WORDS[i]}}"
      if ((skip)); then skip=0; continue; fi
      case " $valued " in *" $w "*) skip=1; continue ;; esac
      [[ $w == -* ]] && continue
      n=$((n + 1))
    done
    if ((${{#positionals[@]}} == 0)); then
      words=files
    elif ((n < ${{#positionals[@]}})); then
      words="${{positionals[n]}}"
    else
      words="${{positionals[-1]}}"
    fi
  fi
  if [[ $words == files ]]; then
    compopt -o filenames 2> /dev/null
    COMPREPLY=($(compgen -f -- "$cur"))
  else
    COMPREPLY=($(compgen -W "$words" -- "$cur"))
  fi
}}
complete -F _driftlab driftlab
)",
      fmt::arg("version", DRIFTLAB_VERSION), fmt::arg("commands", Words(command_names)),
      fmt::arg("cases", cases));
}

// ---- commands ------------------------------------------------------------------------------

struct HelpOptions {
  std::string topic;
  bool man = false;
};

int RunHelp(const CLI::App& app, const HelpOptions& options) {
  const std::string name = app.get_name().empty() ? "driftlab" : app.get_name();
  if (options.man) {
    if (!options.topic.empty()) {
      std::fprintf(stderr, "error: help --man: the man page covers every command; give no TOPIC\n");
      return kExitBadJob;
    }
    fmt::print("{}", ManPage(app, "driftlab"));
    return kExitOk;
  }
  if (options.topic.empty()) {
    fmt::print("{}", Overview(app, name));
    return kExitOk;
  }
  for (const CLI::App* command : Commands(app)) {
    if (command->get_name() == options.topic) {
      fmt::print("{}", command->help(name));
      return kExitOk;
    }
  }
  std::fprintf(stderr, "error: help: no topic '%s'; topics: %s\n", options.topic.c_str(),
               JoinNames(Commands(app)).c_str());
  return kExitBadJob;
}

const RegisterCommand kHelp("help", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<HelpOptions>();
  CLI::App* command = app.add_subcommand(
      "help",
      "The help of a command (the text of COMMAND --help), or every command's as a man page");
  command->add_option("topic", options->topic, "A command (default: the overview)");
  command->add_flag(
      "--man", options->man,
      "Print the man page (roff): driftlab help --man > driftlab.1; man ./driftlab.1");
  return [&app, options] { return RunHelp(app, *options); };
});

const RegisterCommand kCompletion("completion", [](CLI::App& app) -> std::function<int()> {
  auto shell = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "completion", "Print the shell completion script: source <(driftlab completion bash)");
  command->add_option("shell", *shell, "The shell")->required()->check(CLI::IsMember({"bash"}));
  return [&app, shell] {
    fmt::print("{}", BashCompletion(app));
    return kExitOk;
  };
});

}  // namespace
}  // namespace driftlab::cli
