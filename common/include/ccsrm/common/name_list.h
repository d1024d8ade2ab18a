#pragma once
// Comma-separated lists of names, as options take them (--free mu,T_p).
#include <string>
#include <vector>

namespace ccsrm {

// "a, b,c" -> {"a", "b", "c"} (blanks around each name dropped). Throws
// InputError naming `option` for an empty list ("is empty: give at least
// one name") or an empty item. The commands and the Python module read
// their lists with it.
std::vector<std::string> SplitNameList(const std::string& text, const std::string& option);

}  // namespace ccsrm
