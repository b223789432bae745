// The command line of every graspsim subcommand, parsed one way: each subcommand is a table of
// its options (name, what its value must be, what to do with it) with its usage and help, and
// parse_command_line reads any of them the same way, so every subcommand answers its own
// --help and shows its own usage with an error in its arguments.
//
// Our own rather than CLI11 (Debian's libcli11-dev): what a user reads is this tool's, and is
// tested and quoted in the READMEs: each subcommand's hand-written help, and messages that say
// what a value must be ("--out needs a file name (got '--quiet')", "--record physics:0: EVERY
// must be ..."); CLI11 words errors and lays out help its own way, would be one more package
// to install, and its headers are thousands of lines to parse in each file that includes them
// (a 2-core machine builds this suite twice). What is needed here is small: options with or
// without a value, operands, --help.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace graspsim::cli {

// One option. A flag (`needs` "") takes no value; any other takes the next argument as its
// value, which may not start with '-' unless `dash_value` (a number: "--duration -1" is then
// the option's own error, "--out --quiet" the parser's: a missing file name).
struct Option {
  std::string name;    // "--out"
  std::string needs;   // what the value must be: "a file name", "FINGER=SPEC"; "" for a flag
  // Takes the value ("" for a flag): true when taken. False with `why` empty makes the parser say
  // "NAME needs NEEDS (got 'VALUE')"; with `why` set, `why` is the message.
  std::function<bool(const std::string& value, std::string& why)> take;
  bool dash_value = false;
};

// A subcommand's arguments: its options, and what it does with each operand (an argument that
// is not an option: a scenario, a trace).
struct CommandLine {
  std::string name;    // "compare": messages start "graspsim compare: "
  std::string usage;   // "usage: graspsim compare A.h5 B.h5 [...]", shown with any argument error
  std::string help;    // its --help
  std::vector<Option> options;
  // Takes an operand: "" when taken, else why not ("one scenario at a time (got 'a' and 'b')").
  std::function<std::string(const std::string& operand)> operand;
};

enum class Parsed {
  kGo,      // every argument taken: run the command
  kHelp,    // -h or --help: the help was printed; exit 0
  kError,   // an argument was refused: the message and the usage were printed; exit 2
};

// Reads `args` (what follows the subcommand's name) against `line`, in order.
Parsed parse_command_line(const CommandLine& line, const std::vector<std::string>& args);

// Prints "graspsim NAME: MESSAGE", then the usage and where the help is, on stderr; returns 2.
// For an argument error found after parsing (two traces needed, options that exclude each other).
int usage_error(const CommandLine& line, const std::string& message);

// The options several subcommands share, each defined once.
Option flag(const std::string& name, bool& target);
// A value that is not empty and does not start with '-' (a file, a folder, NAME=VALUE).
Option text(const std::string& name, const std::string& needs, std::string& target);
// The same, every occurrence kept in order (--set, --device).
Option texts(const std::string& name, const std::string& needs, std::vector<std::string>& target);
// A finite number (strtod, nothing after it) that `allowed` accepts; "-1" reaches `allowed`.
Option number(const std::string& name, const std::string& needs, double& target,
              const std::function<bool(double)>& allowed);
// A whole number from `min` to `max` (decimal digits only).
Option count(const std::string& name, const std::string& needs, long long min, long long max, long long& target);
// --port N: the port a page is served on, 0 to 65535 (0: any free one); `given` is set.
Option port(int& port, bool& given);

// "--set NAME=VALUE": NAME=VALUE with a NAME (the scenario's own errors say the rest).
Option set_option(std::vector<std::string>& sets);

// A finite number, all of `text` (strtod).
bool parse_number(const std::string& text, double& out);

}  // namespace graspsim::cli
