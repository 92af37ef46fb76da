#include "engine/json_input.hpp"

#include <cmath>
#include <cstdio>

namespace crevasse {

void fail(const std::string& field, const std::string& what) { throw InputError(field + ": " + what); }

std::string input_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

bool Range::contains(double v) const {
  return std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
}

std::string Range::text() const {
  return std::string(lo_open ? "(" : "[") + input_number(lo) + ", " + input_number(hi) + (hi_open ? ")" : "]");
}

void check_range(const std::string& field, double v, const Range& r) {
  if (!r.contains(v)) fail(field, "value " + input_number(v) + " is outside the allowed range " + r.text());
}

std::string name_list(const std::vector<std::string>& names, bool quoted_or) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += quoted_or && i + 1 == names.size() ? " or " : ", ";
    out += quoted_or ? "'" + names[i] + "'" : names[i];
  }
  return out;
}

std::string printable(std::string text) {
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return text;
}

nlohmann::json parse_stored_json(const std::string& text) {
  try {
    return parse_json_input<nlohmann::json>(text, "stored JSON");
  } catch (const InputError&) {
    return nlohmann::json(nlohmann::json::value_t::discarded);
  }
}

}  // namespace crevasse
