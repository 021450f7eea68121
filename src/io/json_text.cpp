// Strict JSON text reading (see json_text.h).
#include "io/json_text.h"

#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "common/error.h"

namespace topopt::io {
namespace {
using nlohmann::json;

/// One open object or array while parsing: the keys seen so far (objects) or the number of
/// elements completed (arrays), and the key being read.
struct Frame {
  bool array = false;
  int index = 0;
  std::set<std::string> keys;
  std::string key;
};

/// "a.b[2].c" for the value being read at the top of `frames`.
std::string path_of(const std::vector<Frame>& frames) {
  std::string p;
  for (const Frame& f : frames) {
    if (f.array)
      p += "[" + std::to_string(f.index) + "]";
    else if (!f.key.empty())
      p += (p.empty() ? "" : ".") + f.key;
  }
  return p;
}

/// The parser's own wording without its "[json.exception...] parse error at ..." prefix.
std::string reason_of(const json::parse_error& e) {
  const std::string w = e.what();
  const size_t colon = w.find(": ", w.find("parse error"));
  return colon == std::string::npos ? w : w.substr(colon + 2);
}

/// Line and column (1-based) of byte `byte` (1-based, as the parser counts) of `text`.
std::string where_in(const std::string& text, size_t byte) {
  size_t line = 1, column = 1;
  for (size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n')
      ++line, column = 1;
    else
      ++column;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

}  // namespace

json parse_json_text(const std::string& text, const std::string& what) {
  std::vector<Frame> frames;
  auto completed = [&frames] {
    if (!frames.empty() && frames.back().array) ++frames.back().index;
  };
  auto watch = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        frames.push_back(Frame{event == json::parse_event_t::array_start, 0, {}, {}});
        break;
      case json::parse_event_t::key: {
        Frame& f = frames.back();
        f.key.clear();
        const std::string key = parsed.get<std::string>();
        const std::string where = path_of(frames);
        if (!f.keys.insert(key).second)
          throw Error(ErrorCode::InvalidParameter, what + ": the key '" + key + "' appears twice" +
                                                       (where.empty() ? "" : " in '" + where + "'") +
                                                       "; write each key once (a second one would replace the first)");
        f.key = key;
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames.pop_back();
        completed();
        break;
      case json::parse_event_t::value:
        completed();
        break;
    }
    return true;
  };
  try {
    return json::parse(text, watch);
  } catch (const json::parse_error& e) {
    throw Error(ErrorCode::Io, what + " is not valid JSON at " + where_in(text, e.byte) + ": " + reason_of(e));
  } catch (const json::out_of_range& e) {  // a number beyond a double's range ("1e400")
    const std::string w = e.what();
    const size_t quote = w.find('\'');
    throw Error(ErrorCode::Io, what + " holds a number too large for the machine (" +
                                   (quote == std::string::npos ? w : w.substr(w.rfind(' ', quote) + 1)) +
                                   "): numbers must stay below 1e308");
  }
}

std::string read_text_file(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::Io, "cannot open the " + what + " " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::Io, "cannot read the " + what + " " + path);
  return ss.str();
}

}  // namespace topopt::io
