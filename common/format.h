#pragma once
// Numbers as text, one grammar for every input and one form for every message.

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>

namespace specimen {

// Numbers in messages and reports, as a user would write them: shortest of fixed and
// scientific with `significant_digits` digits (std::to_string prints fixed-point, so that
// -1e-9 becomes "-0.000000" and the value a user gave disappears from the message).
inline std::string Number(double value, int significant_digits = 6) {
  std::ostringstream out;
  out.precision(significant_digits);
  out << value;
  return out.str();
}

// The number grammar of every input (options, packing files, domains): a finite decimal,
// [+-]digits[.digits][(e|E)[+-]digits]. strtod alone would also take hexadecimal ("0x10"),
// "inf" and "nan". True with *value set, else false.
inline bool ParseDecimal(const std::string& token, double* value) {
  if (token.empty() || token.find_first_not_of("0123456789+-.eE") != std::string::npos) return false;
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  if (end == token.c_str() || *end != '\0' || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

}  // namespace specimen
