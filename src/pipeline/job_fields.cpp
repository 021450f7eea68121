// Typed, checked access to one object of a job file (see job_fields.h).
#include "pipeline/job_fields.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/error.h"

namespace topopt::pipeline {
using nlohmann::json;

namespace {

/// Optimal string alignment distance: edits of one character and swaps of two neighbours.
size_t edit_distance(const std::string& a, const std::string& b) {
  const size_t n = a.size(), m = b.size();
  std::vector<std::vector<size_t>> d(n + 1, std::vector<size_t>(m + 1));
  for (size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (size_t i = 1; i <= n; ++i)
    for (size_t j = 1; j <= m; ++j) {
      const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

std::string listed(const std::vector<std::string>& items) {
  std::string s;
  for (size_t i = 0; i < items.size(); ++i) s += (i ? ", '" : "'") + items[i] + "'";
  return s;
}

/// A number as a user wrote it (no trailing zeros).
std::string shown(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

std::string nearest_key(const std::string& key, const std::vector<std::string>& known) {
  std::string best;
  size_t best_d = std::max<size_t>(2, key.size() / 3) + 1;
  for (const std::string& k : known) {
    // a key cut short ("beta" for "beta_max") is as near as one typo
    const bool prefix = key.size() >= 3 && (k.rfind(key, 0) == 0 || key.rfind(k, 0) == 0);
    const size_t d = prefix ? 1 : edit_distance(key, k);
    if (d < best_d) best_d = d, best = k;
  }
  return best;
}

Fields::Fields(const json& object, std::string path, std::vector<std::string> known, const std::string& example)
    : object_(object), path_(std::move(path)) {
  if (!object_.is_object()) {
    if (path_.empty()) throw Error(ErrorCode::InvalidParameter, "job file: the top level must be a JSON object {...}");
    throw Error(ErrorCode::InvalidParameter, "job file: '" + path_ + "' must be an object such as " + example);
  }
  for (const auto& item : object_.items()) {
    if (std::find(known.begin(), known.end(), item.key()) != known.end()) continue;
    const std::string near = nearest_key(item.key(), known);
    throw Error(ErrorCode::InvalidParameter,
                "job file: unknown key '" + name(item.key()) + "': " +
                    (near.empty() ? "the keys known " + (path_.empty() ? std::string("at the top level") : "here") +
                                        " are " + listed(known)
                                  : "did you mean '" + near + "'?"));
  }
}

bool Fields::has(const std::string& key) const { return object_.contains(key) && !object_[key].is_null(); }

const json& Fields::at(const std::string& key) const { return object_.at(key); }

std::string Fields::name(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

void Fields::bad(const std::string& key, const std::string& what) const {
  throw Error(ErrorCode::InvalidParameter, "job file: '" + name(key) + "' " + what);
}

double Fields::number(const std::string& key, double fallback) const {
  if (!has(key)) return fallback;
  const json& v = at(key);
  if (!v.is_number()) bad(key, "must be a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) bad(key, "must be a finite number");
  return x;
}

int Fields::integer(const std::string& key, int fallback, int lo, int hi) const {
  if (!has(key)) return fallback;
  const json& v = at(key);
  const std::string range = "a whole number from " + std::to_string(lo) + " to " + std::to_string(hi);
  if (!v.is_number()) bad(key, "must be " + range);
  const double x = v.get<double>();
  if (!(x == std::floor(x))) bad(key, "must be " + range + ", not " + shown(x));
  if (!(x >= lo && x <= hi)) bad(key, "must be " + range + ", not " + shown(x));
  return static_cast<int>(x);
}

bool Fields::boolean(const std::string& key, bool fallback) const {
  if (!has(key)) return fallback;
  if (!at(key).is_boolean()) bad(key, "must be true or false");
  return at(key).get<bool>();
}

std::string Fields::text(const std::string& key, const std::string& fallback) const {
  if (!has(key)) return fallback;
  if (!at(key).is_string()) bad(key, "must be a string");
  return at(key).get<std::string>();
}

std::string Fields::choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& choices,
                           const std::string& explain) const {
  if (!has(key)) return fallback;
  const json& v = at(key);
  const std::string options = "must be one of " + listed(choices) + (explain.empty() ? "" : " (" + explain + ")");
  if (!v.is_string()) bad(key, options);
  const std::string s = v.get<std::string>();
  if (std::find(choices.begin(), choices.end(), s) != choices.end()) return s;
  const std::string near = nearest_key(s, choices);
  bad(key, options + ", not '" + s + "'" + (near.empty() ? "" : ": did you mean '" + near + "'?"));
}

std::array<double, 3> Fields::vec3(const std::string& key) const {
  const std::string form = "must be a list of three numbers [x, y, z]";
  if (!has(key) || !at(key).is_array() || at(key).size() != 3) bad(key, form);
  std::array<double, 3> out{};
  for (int i = 0; i < 3; ++i) {
    const json& c = at(key)[i];
    if (!c.is_number() || !std::isfinite(c.get<double>())) bad(key, form);
    out[i] = c.get<double>();
  }
  return out;
}

}  // namespace topopt::pipeline
