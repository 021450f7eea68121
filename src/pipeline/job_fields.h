// Reading one object of a job file: every key checked against the keys the section knows
// (an unknown key is an error that names it and the nearest known one), typed values
// (numbers finite, integers whole), and messages that name the key by its full path.
#pragma once
#include <array>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace topopt::pipeline {

/// The known key nearest to `key` by edit distance (insertions, deletions, substitutions
/// and swaps of neighbours; a key that begins the other counts as one edit), or "" when none
/// is within a third of its length (at least 2).
std::string nearest_key(const std::string& key, const std::vector<std::string>& known);

/// One JSON object of the job, at `path` ("optimization", "load_cases[0].loads[1]"; "" for
/// the top level). Construction checks that it is an object and that it has no key outside
/// `known`. The getters return a fallback for a key that is absent or null.
class Fields {
 public:
  /// Throws Error(InvalidParameter): `object` is not an object ("must be an object such as
  /// `example`"), or it holds a key not in `known` (named, with the nearest known key).
  Fields(const nlohmann::json& object, std::string path, std::vector<std::string> known,
         const std::string& example = "{...}");

  bool has(const std::string& key) const;                  ///< present and not null
  const nlohmann::json& at(const std::string& key) const;  ///< the raw value (present)
  /// "optimization.penalty": the key's full path for messages.
  std::string name(const std::string& key) const;
  /// Throws Error(InvalidParameter): "job file: '<path.key>' <what>".
  [[noreturn]] void bad(const std::string& key, const std::string& what) const;

  /// A finite number.
  double number(const std::string& key, double fallback) const;
  /// A whole number in [lo, hi] (2.5 is refused; 3.0 is 3).
  int integer(const std::string& key, int fallback, int lo, int hi) const;
  bool boolean(const std::string& key, bool fallback) const;
  std::string text(const std::string& key, const std::string& fallback) const;
  /// A string out of `choices`; the message lists them, with `explain` after the list.
  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& choices,
                     const std::string& explain = "") const;
  /// [x, y, z], finite (required).
  std::array<double, 3> vec3(const std::string& key) const;

 private:
  const nlohmann::json& object_;
  std::string path_;
};

}  // namespace topopt::pipeline
