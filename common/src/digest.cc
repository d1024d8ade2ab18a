#include "ccsrm/common/digest.h"

#include <cstdio>

namespace ccsrm {

std::string Fnv1aDigest::Hex() const {
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value_));
  return text;
}

}  // namespace ccsrm
