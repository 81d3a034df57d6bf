// Registry: the one table shape every swappable strategy is listed in (STYLE.md section 3):
// name -> factory -> description, plus optional properties the strategy declares (a schedule
// needs cost estimates, a render method belongs to a family, a scene has a size range).
// A registry feeds --help (describe), validation (find, problem) and reports (names). Used by
// schedulers, ray-tracer partitions, integrators, sort points, compositors, render methods
// and scene generators.
//
// Registries are plain objects assembled explicitly (a function returning a static table, or
// a caller that copies one and add()s entries from a library further down the link order),
// never by static-initialisation self-registration: a static library's object file that
// nothing references is dropped by the linker, and its registration with it.
#pragma once

#include <algorithm>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/util/error.h"

namespace pr {

// The properties of an entry that declares none.
struct NoProperties {};

template <class Factory, class Properties = NoProperties>
struct RegistryEntry {
  std::string name;         // lower case, as on the command line and in run records
  std::string description;  // one line for --help
  Factory make;
  Properties properties{};
};

template <class Factory, class Properties = NoProperties>
class Registry {
 public:
  using Entry = RegistryEntry<Factory, Properties>;

  // what: the noun of the error message ("schedule", "ray-tracing method", ...).
  explicit Registry(std::string what, std::vector<Entry> entries = {}) : what_(std::move(what)) {
    for (Entry& e : entries) add(std::move(e));
  }

  // Appends an entry; a duplicate or empty name is a programming error.
  void add(Entry entry) {
    PR_CHECK(!entry.name.empty(), "registry of " + what_ + ": empty name");
    PR_CHECK(tryFind(entry.name) == nullptr, "registry of " + what_ + ": duplicate name '" + entry.name + "'");
    entries_.push_back(std::move(entry));
  }

  const std::string& what() const { return what_; }
  size_t size() const { return entries_.size(); }
  const Entry& operator[](size_t i) const { return entries_[i]; }
  auto begin() const { return entries_.begin(); }
  auto end() const { return entries_.end(); }

  const Entry* tryFind(std::string_view name) const {
    for (const Entry& e : entries_)
      if (e.name == name) return &e;
    return nullptr;
  }
  bool contains(std::string_view name) const { return tryFind(name) != nullptr; }

  // The entry called name; throws pr::InputError "unknown <what> 'name' (expected one of: a, b)".
  const Entry& find(std::string_view name) const {
    if (const Entry* e = tryFind(name)) return *e;
    throw InputError(problem(name));
  }

  // "" when name is registered, otherwise find()'s error message (for CLI validators).
  std::string problem(std::string_view name) const {
    if (contains(name)) return {};
    return "unknown " + what_ + " '" + std::string(name) + "' (expected one of: " + joinedNames() + ")";
  }

  std::vector<std::string_view> names() const {
    std::vector<std::string_view> out;
    out.reserve(entries_.size());
    for (const Entry& e : entries_) out.emplace_back(e.name);
    return out;
  }

  // "a, b, c" (or with another separator, e.g. " | " for an option's help).
  std::string joinedNames(std::string_view separator = ", ") const {
    std::string out;
    for (const Entry& e : entries_) {
      if (!out.empty()) out += separator;
      out += e.name;
    }
    return out;
  }

  // One "  name   description" line per entry, names padded to a common column, for --help.
  std::string describe() const {
    size_t width = 0;
    for (const Entry& e : entries_) width = std::max(width, e.name.size());
    width = std::max<size_t>(width + 2, 15);
    std::string text;
    for (const Entry& e : entries_) {
      text += "  ";
      text += e.name;
      text += std::string(width - e.name.size(), ' ');
      text += e.description;
      text += "\n";
    }
    return text;
  }

 private:
  std::string what_;
  std::vector<Entry> entries_;
};

}  // namespace pr
