#pragma once
// The finite-difference schemes of the derivative check and the fits.

namespace ccsrm::identify {

// How a derivative is formed from the base run f(p) and two trial runs.
// All three are second-order accurate, so steps of either kind compare.
enum class DifferenceScheme {
  kCentral,   // trials p - h, p + h:   (f(p+h) - f(p-h)) / 2h
  kForward,   // trials p + h, p + 2h:  (-3 f(p) + 4 f(p+h) - f(p+2h)) / 2h
  kBackward,  // trials p - h, p - 2h:  (3 f(p) - 4 f(p-h) + f(p-2h)) / 2h
};
const char* SchemeName(DifferenceScheme scheme);  // "central", "forward", "backward"

}  // namespace ccsrm::identify
