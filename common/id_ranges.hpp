#pragma once
#include <string>
#include <vector>

namespace ddswarm {

/// Parses "3-5,7" into {3,4,5,7} (in the order given); every id must be in
/// [0, max_exclusive) and appear once. Throws std::invalid_argument
/// "--ids TEXT: why".
std::vector<int> parse_id_ranges(const std::string& text, int max_exclusive);

}  // namespace ddswarm
