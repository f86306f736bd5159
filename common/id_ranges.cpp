#include "common/id_ranges.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace ddswarm {

std::vector<int> parse_id_ranges(const std::string& text, int max_exclusive) {
  std::vector<int> ids;
  std::stringstream ss(text);
  std::string part;
  auto bad = [&](const std::string& why) {
    throw std::invalid_argument("--ids " + text + ": " + why);
  };
  while (std::getline(ss, part, ',')) {
    if (part.empty()) bad("empty range");
    auto dash = part.find('-');
    try {
      std::size_t used = 0;
      int a = std::stoi(part.substr(0, dash), &used);
      if (used != (dash == std::string::npos ? part.size() : dash)) bad("not a number: " + part);
      int b = a;
      if (dash != std::string::npos) {
        b = std::stoi(part.substr(dash + 1), &used);
        if (used != part.size() - dash - 1) bad("not a number: " + part);
      }
      if (a > b) bad("range " + part + " runs backwards");
      if (a < 0 || b >= max_exclusive)
        bad("ids must be in [0, " + std::to_string(max_exclusive - 1) + "]");
      for (int i = a; i <= b; ++i) ids.push_back(i);
    } catch (const std::invalid_argument& e) {
      if (std::string(e.what()).rfind("--ids", 0) == 0) throw;
      bad("not a number: " + part);
    } catch (const std::out_of_range&) {
      bad("number too large: " + part);
    }
  }
  if (ids.empty()) bad("no ids");
  std::vector<int> sorted = ids;
  std::sort(sorted.begin(), sorted.end());
  if (auto d = std::adjacent_find(sorted.begin(), sorted.end()); d != sorted.end())
    bad("id " + std::to_string(*d) + " given twice");
  return ids;
}

}  // namespace ddswarm
