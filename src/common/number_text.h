// Numbers in the product's messages: one way to write a value to a chosen number of significant
// digits (the stream's general format: 0.52, 12.5, 1.2e+03), and a length in millimetres.
#pragma once
#include <sstream>
#include <string>

namespace topopt {

/// `v` with `significant` significant digits.
inline std::string number_text(double v, int significant) {
  std::ostringstream s;
  s.precision(significant);
  s << v;
  return s.str();
}

/// An amount with its unit, to 2 significant digits below 10 and 4 above: "6.4 mm", "1118 mm³".
inline std::string amount_text(double v, const char* unit) { return number_text(v, v < 10 ? 2 : 4) + unit; }

/// A length for a message: "2.5 mm".
inline std::string mm_text(double v, int significant = 3) { return number_text(v, significant) + " mm"; }

}  // namespace topopt
