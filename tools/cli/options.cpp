// The one parser of every subcommand's arguments (options.hpp).
#include "cli/options.hpp"

#include <cmath>
#include <cstdlib>
#include <iostream>

namespace graspsim::cli {
namespace {

constexpr int kExitBadInput = 2;

std::string got(const std::string* value) { return value ? " (got '" + *value + "')" : std::string(); }

// The message for an option whose value is missing or refused.
std::string refused(const Option& option, const std::string* value, const std::string& why) {
  return why.empty() ? option.name + " needs " + option.needs + got(value) : why;
}

// Takes args[i] as `option` (and its value, moving i on): "" when taken, else the message.
std::string take_option(const Option& option, const std::vector<std::string>& args, std::size_t& i) {
  std::string why;
  if (option.needs.empty()) return option.take("", why) ? "" : refused(option, nullptr, why);
  const std::string* value = i + 1 < args.size() ? &args[++i] : nullptr;
  if (!value || (!option.dash_value && (value->empty() || value->front() == '-'))) return refused(option, value, why);
  return option.take(*value, why) ? "" : refused(option, value, why);
}

}  // namespace

int usage_error(const CommandLine& line, const std::string& message) {
  std::cerr << "graspsim " << line.name << ": " << message << "\n"
            << line.usage << "(graspsim " << line.name << " --help for more)\n";
  return kExitBadInput;
}

Parsed parse_command_line(const CommandLine& line, const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::cout << line.help;
      return Parsed::kHelp;
    }
    std::string why;
    if (a.size() > 1 && a.front() == '-') {
      const Option* option = nullptr;
      for (const Option& o : line.options)
        if (o.name == a) option = &o;
      why = option ? take_option(*option, args, i) : "unknown option '" + a + "'";
    } else {
      why = line.operand ? line.operand(a) : "takes no argument '" + a + "'";
    }
    if (!why.empty()) {
      usage_error(line, why);
      return Parsed::kError;
    }
  }
  return Parsed::kGo;
}

bool parse_number(const std::string& text, double& out) {
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return !text.empty() && end && *end == '\0' && std::isfinite(out);
}

Option flag(const std::string& name, bool& target) {
  return {name, "", [&target](const std::string&, std::string&) { return target = true; }};
}

Option text(const std::string& name, const std::string& needs, std::string& target) {
  return {name, needs, [&target](const std::string& v, std::string&) {
            target = v;
            return true;
          }};
}

Option texts(const std::string& name, const std::string& needs, std::vector<std::string>& target) {
  return {name, needs, [&target](const std::string& v, std::string&) {
            target.push_back(v);
            return true;
          }};
}

Option number(const std::string& name, const std::string& needs, double& target,
              const std::function<bool(double)>& allowed) {
  return {name, needs,
          [&target, allowed](const std::string& v, std::string&) { return parse_number(v, target) && allowed(target); },
          true};
}

Option count(const std::string& name, const std::string& needs, long long min, long long max, long long& target) {
  return {name, needs, [&target, min, max](const std::string& v, std::string&) {
            if (v.empty() || v.size() > 18 || v.find_first_not_of("0123456789") != std::string::npos) return false;
            target = std::strtoll(v.c_str(), nullptr, 10);
            return target >= min && target <= max;
          },
          true};
}

Option port(int& port, bool& given) {
  return {"--port", "a port number from 0 to 65535", [&port, &given](const std::string& v, std::string&) {
            if (v.empty() || v.size() > 5 || v.find_first_not_of("0123456789") != std::string::npos) return false;
            port = std::atoi(v.c_str());
            given = true;
            return port <= 65535;
          },
          true};
}

Option set_option(std::vector<std::string>& sets) {
  return {"--set", "NAME=VALUE", [&sets](const std::string& v, std::string&) {
            if (v.find('=') == std::string::npos || v.front() == '=') return false;
            sets.push_back(v);
            return true;
          }};
}

}  // namespace graspsim::cli
