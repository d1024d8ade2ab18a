#include "option_checks.h"

#include <cmath>
#include <functional>
#include <sstream>

#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"

namespace ccsrm::app {

double ParseNumber(const std::string& text, const std::string& option) {
  double value = 0.0;
  const std::string problem = ParseNumberText(text, &value);
  if (!problem.empty()) ThrowInputError(option, "", "'" + text + "' " + problem);
  return value;
}

namespace {

// A bound as a user would write it: "60", "0.001".
std::string Number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string WithUnit(const std::string& rule, const std::string& unit) {
  return unit.empty() ? rule : rule + " " + unit;
}

// Refuses a number `accept` does not allow with "must be <rule>, found
// <text>"; a value that does not convert is left to CLI11's own message.
CLI::Validator NumberCheck(std::function<bool(double)> accept, const std::string& rule) {
  return CLI::Validator(
      [accept, rule](std::string& text) {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value)) return std::string();
        return accept(value) ? std::string() : "must be " + rule + ", found " + text;
      },
      rule, "");
}

std::string RangeRule(double min, double max, const std::string& unit) {
  return WithUnit("in [" + Number(min) + ", " + Number(max) + "]", unit);
}

}  // namespace

CLI::Validator NotEmpty() {
  return CLI::Validator(
      [](std::string& text) { return text.empty() ? std::string("is empty: give a value") : ""; },
      "", "");
}

CLI::Validator Unsigned64() {
  return CLI::Validator(
      [](std::string& text) {
        const bool digits = !text.empty() && text.size() <= 20 &&
                            text.find_first_not_of("0123456789") == std::string::npos;
        // 2^64 - 1 has 20 digits; a longer or larger text does not fit.
        if (digits && (text.size() < 20 || text <= "18446744073709551615")) return std::string();
        return "must be a whole number in [0, 18446744073709551615], found " + text;
      },
      "", "");
}

CLI::Validator InRange(double min, double max, const std::string& unit) {
  return NumberCheck([min, max](double v) { return v >= min && v <= max; },
                     RangeRule(min, max, unit));
}

void CheckInRange(const std::string& option, double value, double min, double max,
                  const std::string& unit) {
  if (!(value >= min && value <= max)) {
    throw CLI::ValidationError(option,
                               "must be " + RangeRule(min, max, unit) + ", found " + Number(value));
  }
}

CLI::Validator Above(double min, const std::string& unit) {
  return NumberCheck([min](double v) { return v > min; }, WithUnit("> " + Number(min), unit));
}

CLI::Validator AtLeast(double min, const std::string& unit) {
  return NumberCheck([min](double v) { return v >= min; }, WithUnit(">= " + Number(min), unit));
}

}  // namespace ccsrm::app
