// The command line of the tools in tools/, parsed by CLI11 (libcli11-dev) with one convention:
// --help (-h) prints the help CLI11 makes from the options' descriptions on stdout and exits 0,
// whatever else the line holds; a usage error (an unknown option, a missing or bad value, a
// required option left out, options that do not go together) prints "TOOL: what is wrong" and the
// help on stderr and exits 2 (kUsageError). As with the hand-written loops before CLI11, an option
// takes one value each time it is given (an option that is a list gathers them), an option given
// twice otherwise takes its last value, and whole numbers are read in base 10 (CLI11 alone takes 010
// for octal 8 and refuses 08, as frame numbers are often written). parseCommandLine finds the
// whole-number options by the type name CLI11 gives them (INT, UINT): leave it to them, and check
// their limits after parsing (a check added to them would see the number before it is read in base 10).
#pragma once

#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

namespace viper_tools {

/// The exit status of a usage error.
constexpr int kUsageError = 2;

/// Prints "TOOL: problem" and the help on stderr; returns kUsageError. For what only the whole
/// command line tells (options that go together), after parseCommandLine.
inline int usageError(const CLI::App& app, const std::string& problem) {
  std::cerr << app.get_name() << ": " << problem << "\n" << app.help();
  return kUsageError;
}

/// A T built from `args` (a reader of the file the command line names); nullptr after "TOOL: what
/// went wrong" on stderr when its constructor throws (the tools then exit 2).
template <typename T, typename... Args>
std::unique_ptr<T> openOrReport(const CLI::App& app, Args&&... args) {
  try {
    return std::make_unique<T>(std::forward<Args>(args)...);
  } catch (const std::exception& e) {
    std::cerr << app.get_name() << ": " << e.what() << "\n";
    return nullptr;
  }
}

/// CLI11's help with each option's description wrapped at 70 columns (its own line breaks kept).
class HelpFormatter : public CLI::Formatter {
 public:
  HelpFormatter() { label("Usage", "usage"); }
  std::string make_option_desc(const CLI::Option* option) const override {
    std::string out, line;
    std::istringstream words(option->get_description());
    for (std::string paragraph; std::getline(words, paragraph);) {
      std::istringstream in(paragraph);
      line.clear();
      for (std::string word; in >> word;) {
        if (!line.empty() && line.size() + 1 + word.size() > 70) out += line + "\n", line.clear();
        line += (line.empty() ? "" : " ") + word;
      }
      out += line + "\n";
    }
    return out.empty() ? out : out.substr(0, out.size() - 1);
  }
};

/// Whole numbers written in base 10 ([+-]digits), their leading zeros dropped for CLI11.
inline const CLI::Validator kDecimal(
    [](std::string& value) -> std::string {
      const size_t digits = !value.empty() && (value[0] == '-' || value[0] == '+') ? 1 : 0;
      if (digits == value.size() || value.find_first_not_of("0123456789", digits) != std::string::npos)
        return "'" + value + "' is not a whole number";
      const size_t first = value.find_first_not_of('0', digits);
      value = value.substr(0, digits) + (first == std::string::npos ? "0" : value.substr(first));
      return "";
    },
    "", "DECIMAL");

/// Parses argv into `app`'s options (all added by now). Returns the exit status when the tool is
/// done (0 after --help, kUsageError after a usage error, each printed); std::nullopt when it goes on.
inline std::optional<int> parseCommandLine(CLI::App& app, int argc, char** argv) {
  app.formatter(std::make_shared<HelpFormatter>());
  // --help as soon as it is read: before the values' checks (an environment variable's included).
  app.get_help_ptr()->trigger_on_parse()->each([](const std::string&) { throw CLI::CallForHelp(); });
  for (CLI::Option* option : app.get_options()) {
    option->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);  // a list (vector) keeps every value
    if (!option->get_positional()) option->allow_extra_args(false);  // one value each time it is given
    const std::string type = option->get_type_name();  // CLI11 names integers' INT or UINT
    if (type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0) option->transform(kDecimal);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) return usageError(app, e.what());
    std::cout << app.help();
    return 0;
  }
  return std::nullopt;
}

}  // namespace viper_tools
