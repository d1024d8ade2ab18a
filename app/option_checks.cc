#include "option_checks.h"

#include <cmath>
#include <functional>
#include <sstream>

#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"

namespace ccsrm::app {

std::vector<std::string> SplitList(const std::string& text, const std::string& option) {
  // An empty list is refused rather than read as "the default": `--free ''`
  // would otherwise fit every parameter.
  if (text.find_first_not_of(" \t") == std::string::npos) {
    ThrowInputError(option, "", "is empty: give at least one name");
  }
  std::vector<std::string> items;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = text.find(',', begin);
    std::string item = text.substr(begin, end == std::string::npos ? end : end - begin);
    const std::size_t first = item.find_first_not_of(" \t");
    const std::size_t last = item.find_last_not_of(" \t");
    item = first == std::string::npos ? "" : item.substr(first, last - first + 1);
    if (item.empty()) ThrowInputError(option, "", "empty item in '" + text + "'");
    items.push_back(item);
    if (end == std::string::npos) return items;
    begin = end + 1;
  }
}

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
