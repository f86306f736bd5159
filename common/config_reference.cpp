#include "common/config_reference.hpp"

#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace ddswarm {
namespace {

std::string trim(std::string s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  const auto b = s.find_last_not_of(" \t");
  return s.substr(a, b - a + 1);
}

/// A table cell as text: backticks and escaped bars gone.
std::string plain(std::string s) {
  std::string out;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (s[k] == '`') continue;
    if (s[k] == '\\' && k + 1 < s.size() && s[k + 1] == '|') continue;
    out += s[k];
  }
  return trim(out);
}

/// The cells of a markdown table row ("| a | b \| c |"), an escaped bar kept in its cell.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (std::size_t k = 1; k < line.size(); ++k) {
    if (line[k] == '|' && line[k - 1] != '\\') {
      out.push_back(trim(cur));
      cur.clear();
    } else {
      cur += line[k];
    }
  }
  return out;
}

bool number(const std::string& s, double* v) {
  try {
    std::size_t used = 0;
    *v = std::stod(s, &used);
    return used == s.size();
  } catch (const std::exception&) {
    return false;
  }
}

bool scalar_type(const std::string& t) {
  return t == "real" || t == "bool" || t == "integer" || t == "int";
}

}  // namespace

std::vector<std::string> reference_mismatches(const std::string& markdown,
                                              const std::string& heading,
                                              const std::vector<FieldRow>& rows) {
  std::istringstream in(markdown);
  std::string line;
  bool found = false;
  while (std::getline(in, line))
    if (line.rfind("#", 0) == 0 && line.find(heading) != std::string::npos) {
      found = true;
      break;
    }
  if (!found) return {"no heading containing '" + heading + "'"};
  // key -> cells (key, type, default, unit, range, meaning)
  std::map<std::string, std::vector<std::string>> table;
  bool in_table = false;
  while (std::getline(in, line)) {
    if (line.rfind("|", 0) != 0) {
      if (in_table) break;
      if (line.rfind("#", 0) == 0) break;  // the next section: no table here
      continue;
    }
    in_table = true;
    auto c = cells(line);
    if (c.size() < 5 || c[0] == "key" || c[0].rfind("---", 0) == 0) continue;
    table[plain(c[0])] = c;
  }
  std::vector<std::string> out;
  if (table.empty()) return {"no table after '" + heading + "'"};
  std::map<std::string, bool> listed;
  for (const auto& r : rows) {
    listed[r.key] = true;
    auto it = table.find(r.key);
    if (it == table.end()) {
      out.push_back(heading + ": no row for " + r.key);
      continue;
    }
    const auto& c = it->second;
    const std::string def = plain(c[2]), unit = plain(c[3]), range = plain(c[4]);
    double a = 0, b = 0;
    // A placeholder the doc explains ("<source>/config/x.xml") stands for
    // the start of the code's default.
    const auto close = def.find('>');
    const bool placeholder = def.rfind("<", 0) == 0 && close != std::string::npos;
    const bool same_default =
        placeholder ? r.default_text.size() >= def.size() - close - 1 &&
                          r.default_text.compare(r.default_text.size() - (def.size() - close - 1),
                                                 std::string::npos, def.substr(close + 1)) == 0
        : number(def, &a) && number(r.default_text, &b)
            ? a == b
            : (def == "\"\"" ? "" : def) == r.default_text;
    if (!same_default)
      out.push_back(heading + ": " + r.key + ": the doc's default is '" + def + "', the code's '" +
                    r.default_text + "'");
    if (unit != r.unit)
      out.push_back(heading + ": " + r.key + ": the doc's unit is '" + unit + "', the code's '" +
                    r.unit + "'");
    if (range.rfind(r.bounds, 0) != 0)
      out.push_back(heading + ": " + r.key + ": the doc's range '" + range +
                    "' does not begin with the code's '" + r.bounds + "'");
    if (r.type.find(" | ") != std::string::npos) {
      std::istringstream names(r.type);
      std::string name, row = c[1] + " " + c[4];
      while (names >> name)
        if (name != "|" && row.find("`" + name + "`") == std::string::npos)
          out.push_back(heading + ": " + r.key + ": the doc does not name the choice '" + name +
                        "'");
    }
  }
  for (const auto& [key, c] : table)
    if (!listed.count(key) && scalar_type(plain(c[1])))
      out.push_back(heading + ": the doc has a row for " + key + ", which the code does not list");
  return out;
}

std::string configuration_reference() {
  const std::string path = std::string(DDSWARM_SOURCE_DIR) + "/docs/configuration.md";
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot be read");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace ddswarm
