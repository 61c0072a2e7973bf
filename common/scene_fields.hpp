#pragma once
// The scene validator's field reader (common/scene.cpp, common/scene_sections.cpp only): typed
// reads of dotted TOML keys with ranges, error messages naming the key, the value and the
// allowed range, unknown-key detection, and the key catalogue behind `sandbench scene-keys`.
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/geometry.hpp"
#include "common/input_error.hpp"
#include "common/scene.hpp"
#include "common/scene_keys.hpp"

namespace sb::scene_detail {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// An interval with open or closed ends, printed in error messages as "(0, 10]".
struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;
  bool contains(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
  std::string str() const {
    auto num = [](double v) {
      if (std::isinf(v)) return std::string(v > 0 ? "inf" : "-inf");
      std::ostringstream s;
      s << v;
      return s.str();
    };
    return (lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
  }
};
inline Range positive(double hi = kInf) { return {0.0, hi, true, hi == kInf}; }
inline Range closed(double lo, double hi) { return {lo, hi, false, false}; }
inline Range open(double lo, double hi) { return {lo, hi, true, true}; }

inline std::string describe(const toml::node& n) {
  std::ostringstream s;
  if (n.is_string()) {
    s << '"' << *n.value<std::string>() << '"';
  } else if (n.is_table()) {
    s << "a table";
  } else {
    n.visit([&](auto&& v) { s << v; });
  }
  return s.str();
}

// Reads typed fields by dotted key, remembers which keys were read, and at the end reports
// any key that nothing read (a typo, or a key of another version).
class Fields {
 public:
  explicit Fields(const toml::table& root, std::vector<SceneKey>* catalogue = nullptr)
      : root_(root), catalogue_(catalogue) {}

  const toml::node* find(const std::string& key) {
    seen_.insert(key);
    return root_.at_path(key).node();
  }

  double number(const std::string& key, double fallback, Range range, bool required = false) {
    note(key, "number", required ? "" : text(fallback), range.str());
    const toml::node* n = find(key);
    if (!n) {
      if (required) fail(key, "is missing; it must be a number in " + range.str());
      return fallback;
    }
    if (!n->is_number()) fail(key, "= " + describe(*n) + " must be a number in " + range.str());
    const double v = *n->value<double>();
    if (!std::isfinite(v)) fail(key, "= " + describe(*n) + " must be a finite number in " + range.str());
    if (!range.contains(v)) fail(key, "= " + describe(*n) + " is out of range " + range.str());
    return v;
  }

  long long integer(const std::string& key, long long fallback, long long lo, long long hi) {
    note(key, "integer", std::to_string(fallback), "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    const toml::node* n = find(key);
    if (!n) return fallback;
    const std::string allowed = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (!n->is_integer()) fail(key, "= " + describe(*n) + " must be " + allowed);
    const long long v = *n->value<long long>();
    if (v < lo || v > hi) fail(key, "= " + describe(*n) + " is out of range: must be " + allowed);
    return v;
  }

  bool boolean(const std::string& key, bool fallback) {
    note(key, "boolean", fallback ? "true" : "false", "true | false");
    const toml::node* n = find(key);
    if (!n) return fallback;
    if (!n->is_boolean()) fail(key, "= " + describe(*n) + " must be true or false");
    return *n->value<bool>();
  }

  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed) {
    const toml::node* n = find(key);
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : " | ") + a;
    note(key, "choice", "\"" + fallback + "\"", list);
    if (!n) return fallback;
    if (!n->is_string()) fail(key, "= " + describe(*n) + " must be one of " + list);
    const std::string v = *n->value<std::string>();
    for (const auto& a : allowed)
      if (a == v) return v;
    fail(key, "= \"" + v + "\" is not allowed; must be one of " + list);
    return v;
  }

  std::string string(const std::string& key, bool required) {
    note(key, "string", "", "non-empty string");
    const toml::node* n = find(key);
    if (!n) {
      if (required) fail(key, "is missing; it must be a string");
      return {};
    }
    if (!n->is_string() || n->value<std::string>()->empty())
      fail(key, "= " + describe(*n) + " must be a non-empty string");
    const std::string v = *n->value<std::string>();
    // A NUL would cut a path short at the operating system and name another file.
    if (v.find('\0') != std::string::npos) fail(key, "must not contain a NUL character (\\u0000)");
    return v;
  }

  // An array of numbers; `count` 0 means any length >= min_count.
  std::vector<double> numbers(const std::string& key, std::size_t count, std::size_t min_count, Range range,
                              bool required, std::vector<double> fallback = {}) {
    std::string def;
    for (double v : fallback) def += (def.empty() ? "" : ", ") + text(v);
    note(key, count == 2 ? "[x, y]" : "array", required || fallback.empty() ? "" : "[" + def + "]",
         (count ? std::to_string(count) : "at least " + std::to_string(min_count)) + " numbers in " + range.str());
    const toml::node* n = find(key);
    const std::string shape =
        count ? std::to_string(count) + " numbers" : "at least " + std::to_string(min_count) + " numbers";
    if (!n) {
      if (required) fail(key, "is missing; it must be an array of " + shape + " in " + range.str());
      return fallback;
    }
    const toml::array* arr = n->as_array();
    if (!arr) fail(key, "= " + describe(*n) + " must be an array of " + shape);
    if ((count && arr->size() != count) || arr->size() < min_count)
      fail(key, "has " + std::to_string(arr->size()) + " elements; it must have " + shape);
    std::vector<double> out;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const toml::node& e = *arr->get(i);
      const std::string at = key + "[" + std::to_string(i) + "]";
      if (!e.is_number()) fail(at, "= " + describe(e) + " must be a number in " + range.str());
      const double v = *e.value<double>();
      if (!std::isfinite(v) || !range.contains(v))
        fail(at, "= " + describe(e) + " must be a finite number in " + range.str());
      out.push_back(v);
    }
    return out;
  }

  Vec2 vec2(const std::string& key, Vec2 fallback, Range range, bool required = false) {
    auto v = numbers(key, 2, 2, range, required, {fallback.x(), fallback.y()});
    return {v[0], v[1]};
  }

  std::vector<Vec2> points(const std::string& key, std::size_t min_count, bool required) {
    note(key, "points", "", "at least " + std::to_string(min_count) + " [x, y] pairs of finite numbers");
    const toml::node* n = find(key);
    if (!n) {
      if (required) fail(key, "is missing; it must be an array of [x, y] points");
      return {};
    }
    const toml::array* arr = n->as_array();
    if (!arr || arr->size() < min_count)
      fail(key, "must be an array of at least " + std::to_string(min_count) + " [x, y] points");
    std::vector<Vec2> out;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const toml::array* p = arr->get(i)->as_array();
      const std::string at = key + "[" + std::to_string(i) + "]";
      if (!p || p->size() != 2 || !p->get(0)->is_number() || !p->get(1)->is_number())
        fail(at, "= " + describe(*arr->get(i)) + " must be an [x, y] pair of numbers");
      const double x = *p->get(0)->value<double>(), y = *p->get(1)->value<double>();
      if (!std::isfinite(x) || !std::isfinite(y)) fail(at, "must hold finite numbers");
      out.emplace_back(x, y);
    }
    return out;
  }

  // Every leaf key present in the file must have been read.
  void reject_unknown() const { walk(root_, ""); }

  [[noreturn]] static void fail(const std::string& key, const std::string& what) {
    throw InputError("scene: " + key + " " + what);
  }

 private:
  void walk(const toml::table& t, const std::string& prefix) const {
    for (auto&& [k, v] : t) {
      const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      if (const toml::table* sub = v.as_table()) {
        walk(*sub, key);
      } else if (!seen_.count(key)) {
        // A key of the format that these settings do not read (tool.profile with a pour tool,
        // terrain.amplitude_m on flat sand) is a different mistake from a misspelt one.
        if (!scene_key_meaning(key).empty())
          fail(key,
               "does not apply with this scene's terrain.kind, tool.shape or tool.profile (see the scene "
               "format in README.md)");
        fail(key, "is not a known key (see the scene format in README.md)");
      }
    }
  }

  // In catalogue mode every read key is noted (once) with its type, default and range.
  void note(const std::string& key, const std::string& type, const std::string& fallback, const std::string& allowed) {
    if (!catalogue_) return;
    // Keys seen only in a later pass (another tool shape) go after the key read before them.
    for (std::size_t i = 0; i < catalogue_->size(); ++i)
      if ((*catalogue_)[i].key == key) {
        next_ = i + 1;
        return;
      }
    next_ = std::min(next_, catalogue_->size());
    catalogue_->insert(catalogue_->begin() + static_cast<std::ptrdiff_t>(next_), {key, type, fallback, allowed, {}});
    ++next_;
  }
  static std::string text(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

  const toml::table& root_;
  std::vector<SceneKey>* catalogue_;
  std::size_t next_ = 0;
  std::set<std::string> seen_;
};

}  // namespace sb::scene_detail
