// JSON text as users write it (job files): parsed strictly, so that a key written twice in
// one object is an error instead of one value silently replacing the other, and a syntax
// error is reported by line and column in plain words.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace topopt::io {

/// Parses `text` as JSON. `what` names the document in messages ("job file").
/// Throws Error(Io) for a syntax error (with its line and column) and
/// Error(InvalidParameter) for a key that appears twice in one object, naming its path
/// ("load_cases[0].loads[1].faces").
nlohmann::json parse_json_text(const std::string& text, const std::string& what);

/// Reads the file at `path` whole. Throws Error(Io) naming it if it cannot be read.
std::string read_text_file(const std::string& path, const std::string& what);

}  // namespace topopt::io
