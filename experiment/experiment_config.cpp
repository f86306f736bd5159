#include "experiment/experiment_config.hpp"

#include <algorithm>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "common/config_error.hpp"
#include "common/scenario_overrides.hpp"

namespace ddswarm::gs {
namespace {

namespace fs = std::filesystem;

}  // namespace

void ExperimentConfig::validate() const {
  if (name.empty()) throw FieldError("experiment.name", "\"\"", "must not be empty");
  if (scenario.empty())
    throw FieldError("experiment.scenario", "\"\"", "must name a scenario file");
  FieldChecker check("experiment");
  fields(*this, check);
  if (mode != "lockstep" && mode != "realtime")
    throw FieldError("experiment.mode", mode, "must be lockstep or realtime");
  if (sets.empty()) throw FieldError("experiment.sets", "[]", "must list at least one set");
  std::set<std::string> names;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const std::string field = "experiment.sets[" + std::to_string(i) + "]";
    const ExperimentSet& s = sets[i];
    if (s.name.empty()) throw FieldError(field + ".name", "\"\"", "must not be empty");
    if (!names.insert(s.name).second)
      throw FieldError(field + ".name", s.name, "another set has this name");
    for (const auto& [key, value] : s.overrides) {
      if (split_key_path(key).empty())
        throw FieldError(field + ".set." + key, key, "must be a dotted key path like agent.x");
      // The map is sorted: keys extending "key." start at lower_bound("key.").
      auto next = s.overrides.lower_bound(key + ".");
      if (next != s.overrides.end() && next->first.compare(0, key.size() + 1, key + ".") == 0)
        throw FieldError(field + ".set." + next->first, next->first,
                         "conflicts with " + key + " (set one or the other)");
    }
  }
}

std::uint64_t ExperimentConfig::seed(int set_index, int run_index) const {
  return base_seed + static_cast<std::uint64_t>(set_index) * 1000u +
         static_cast<std::uint64_t>(run_index);
}

void load(YamlSection s, ExperimentConfig& c, const std::string& base_dir) {
  FieldLoader fields(s);
  ExperimentConfig::fields(c, fields);
  c.sets.clear();
  for (YamlSection set : s.children("sets")) {
    ExperimentSet e;
    set.get("name", e.name);
    YamlSection overrides = set.child("set");
    const YAML::Node& n = overrides.node();
    if (n && n.IsMap()) {
      for (auto it = n.begin(); it != n.end(); ++it) {
        const std::string key = it->first.Scalar();
        if (!e.overrides.emplace(key, YAML::Clone(it->second)).second)
          overrides.fail(it->first, key, YAML::Dump(it->second), "set twice");
        e.lines[key] = it->first.Mark().line + 1;
      }
    }
    set.finish();
    c.sets.push_back(std::move(e));
  }
  s.finish();
  if (!c.scenario.empty()) {
    const fs::path p(c.scenario);
    c.scenario_path =
        p.is_absolute() ? p.string() : (fs::path(base_dir) / p).lexically_normal().string();
  }
}

namespace {

ExperimentConfig from_document(const YamlDocument& doc) {
  YamlSection root(doc.root(), doc.file(), "");
  ExperimentConfig c;
  c.file = doc.file();
  doc.guard([&] {
    if (!root.has("experiment")) throw ConfigError(doc.file() + ":1: no `experiment:` section");
    load(root.child("experiment"), c, fs::path(doc.file()).parent_path().string());
    root.finish();
    c.validate();
  });
  return c;
}

}  // namespace

ExperimentConfig parse_experiment(const std::string& text, const std::string& file) {
  return from_document(YamlDocument::parse(text, file));
}

ExperimentConfig load_experiment_file(const std::string& path) {
  return from_document(YamlDocument::load_file(path));
}

void override_every_set(ExperimentConfig& c, const std::map<std::string, YAML::Node>& overrides) {
  for (auto& set : c.sets) {
    for (const auto& kv : overrides) {
      // The command line wins over the set's value for the key and for
      // anything under or above it (validate() rejects a key and its child).
      // (kv, not a structured binding: clang 14, the fuzz build, cannot capture one.)
      const std::string& key = kv.first;
      const auto replaced = [&](const auto& o) {
        return o.first == key || o.first.starts_with(key + ".") || key.starts_with(o.first + ".");
      };
      std::erase_if(set.overrides, replaced);
      std::erase_if(set.lines, replaced);
      set.overrides[key] = YAML::Clone(kv.second);
    }
  }
  c.validate();
}

std::vector<OverrideOrigin> override_origins(const ExperimentConfig& c, std::size_t set_index) {
  const ExperimentSet& set = c.sets.at(set_index);
  std::vector<OverrideOrigin> out;
  for (const auto& [key, value] : set.overrides) {
    if (const auto it = set.lines.find(key); it != set.lines.end()) {
      out.push_back({key, c.file + ":" + std::to_string(it->second) + ": set '" + set.name + "'"});
    } else {
      std::string text = value.IsScalar() ? value.Scalar() : YAML::Dump(value);
      std::replace(text.begin(), text.end(), '\n', ' ');
      out.push_back({key, "--set " + key + "=" + text, true});
    }
  }
  return out;
}

YAML::Node scenario_for_set(const ExperimentConfig& c, std::size_t set_index) {
  const YamlDocument doc = YamlDocument::load_file(c.scenario_path);
  try {
    return apply_overrides(doc.root(), c.sets.at(set_index).overrides);
  } catch (const OverrideError& e) {
    for (const auto& o : override_origins(c, set_index))
      if (o.key == e.key()) throw ConfigError(o.where + ": " + e.key() + ": " + e.reason());
    throw;
  }
}

}  // namespace ddswarm::gs
