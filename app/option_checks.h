#pragma once
// CLI11 validators for range-checked command-line values. They run while the
// command line is parsed, before any file is read, so an out-of-range value
// is refused with one line naming the option ("--order: filter_order must be
// in 1..8, found 0"); main() prints it and exits with status 2.
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace ccsrm::app {

// A finite number, whole text; throws InputError naming `option` otherwise.
double ParseNumber(const std::string& text, const std::string& option);

// A number in [min, max] (NaN refused); `unit` follows the bounds in the
// message ("deg", or "" for none).
CLI::Validator InRange(double min, double max, const std::string& unit = "");

// A number above `min` (NaN refused).
CLI::Validator Above(double min, const std::string& unit = "");

// A number of at least `min` (NaN refused).
CLI::Validator AtLeast(double min, const std::string& unit = "");

// A value given at all: "--config ''" is refused ("is empty: give a
// value"), never read as the option left out (the default).
CLI::Validator NotEmpty();

// A whole number in [0, 2^64 - 1], as a seed: "-1" and "1e30" are refused,
// not wrapped around.
CLI::Validator Unsigned64();

// For a value checked once parsing is done (e.g. one whose option another
// command registers): throws CLI::ValidationError naming `option` unless
// `value` is in [min, max] (NaN refused), with InRange's message.
void CheckInRange(const std::string& option, double value, double min, double max,
                  const std::string& unit = "");

// A value accepted when the options struct of the library that uses it is
// valid with that value in `field` (Options::IsValid(std::string*)): the
// range is written once, in IsValid, and its message names the field.
template <typename Options, typename Value>
CLI::Validator ValidIn(Value Options::*field, const Options& defaults = Options()) {
  return CLI::Validator(
      [field, defaults](std::string& text) {
        Value value{};
        // A value that does not convert is left to CLI11's own message.
        if (!CLI::detail::lexical_cast(text, value)) return std::string();
        Options options = defaults;
        options.*field = value;
        std::string error;
        return options.IsValid(&error) ? std::string() : error + ", found " + text;
      },
      "", "");
}

}  // namespace ccsrm::app
