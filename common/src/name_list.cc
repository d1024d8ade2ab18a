#include "ccsrm/common/name_list.h"

#include "ccsrm/common/error.h"

namespace ccsrm {

std::vector<std::string> SplitNameList(const std::string& text, const std::string& option) {
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

}  // namespace ccsrm
