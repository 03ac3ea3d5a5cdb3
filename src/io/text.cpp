#include "io/text.h"

#include <charconv>
#include <cstdlib>

#include "pic/types.h"

namespace pic::detail {

std::string quoted(std::string_view token) {
  std::string s;
  for (char c : token.substr(0, 24)) s += (c >= 32 && c < 127) ? c : '?';
  return "'" + s + (token.size() > 24 ? "...'" : "'");
}

double parse_double(std::string_view token, size_t line) {
  std::string_view t = token;
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || end != t.data() + t.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
    throw InvalidInput("line " + std::to_string(line) + ": expected a number, found " + quoted(token));
  // Out of range: strtod gives +-inf for overflow (refused later) and 0 or a denormal for underflow.
  if (ec == std::errc::result_out_of_range) v = std::strtod(std::string(t).c_str(), nullptr);
  return v;
}

int64_t parse_int(std::string_view token, size_t line) {
  std::string_view t = token;
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  int64_t v = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || end != t.data() + t.size() || ec != std::errc())
    throw InvalidInput("line " + std::to_string(line) + ": expected an integer, found " + quoted(token));
  return v;
}

}  // namespace pic::detail
