#pragma once
// What every JSON input (scene, study and observation files, stored JSON) shares: one-line
// refusals naming the field, one number format, ranges, name lists, and the parser's limits.
#include <cstddef>
#include <initializer_list>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/error.hpp"

namespace crevasse {

// Throws InputError "<field>: <what>".
[[noreturn]] void fail(const std::string& field, const std::string& what);

// A number as input messages write it: up to 10 significant digits, so that a value just
// outside a range never prints as its bound.
std::string input_number(double v);

// An interval, closed unless marked open; infinite and NaN values are never inside.
struct Range {
  double lo, hi;
  bool lo_open = false, hi_open = false;
  bool contains(double v) const;
  std::string text() const;  // "[lo, hi)"
};

// fail(field, "value v is outside the allowed range [lo, hi]") unless r contains v.
void check_range(const std::string& field, double v, const Range& r);

// "a, b, c", or with `quoted_or` "'a', 'b' or 'c'".
std::string name_list(const std::vector<std::string>& names, bool quoted_or = false);

// Every key of the JSON object `obj` must be one of `allowed`; otherwise InputError
// "<where>.<key>: unknown key (allowed: a, b, ...)" (a typo never silently falls back to a
// default). J is nlohmann::json or nlohmann::ordered_json.
template <class J>
void refuse_unknown_keys(const J& obj, const std::string& where,
                         std::initializer_list<const char*> allowed) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) {
      fail(where.empty() ? it.key() : where + "." + it.key(),
           "unknown key (allowed: " + name_list({allowed.begin(), allowed.end()}) + ")");
    }
  }
}

// `text` with control characters (terminal escapes, newlines) shown as '?', for messages that
// echo user input.
std::string printable(std::string text);

// Deepest nesting of arrays and objects any input may have. The shipped files need 4; a limit
// far below what exhausts the stack makes a hostile file a one-line refusal, not a crash.
inline constexpr int kMaxJsonDepth = 64;

// Parses `text` as J (nlohmann::json or ordered_json) for the input named `source`, refusing with
// an InputError naming it: nesting deeper than kMaxJsonDepth (checked on the text before any
// parser or destructor recurses), a NUL byte anywhere (nothing may hide after one), a key given
// twice in one object (the last would silently win), and invalid JSON.
template <class J>
J parse_json_input(const std::string& text, const std::string& source) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\0')
      throw InputError(source + ": a NUL byte at offset " + std::to_string(i) +
                       "; a JSON input file is text");
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw InputError(source + ": arrays and objects nested deeper than " +
                         std::to_string(kMaxJsonDepth) + " levels (at offset " +
                         std::to_string(i) + ")");
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  std::vector<std::set<std::string>> keys;  // per open object or array (arrays stay empty)
  std::string duplicate;
  const typename J::parser_callback_t check = [&](int, typename J::parse_event_t event, J& parsed) {
    using E = typename J::parse_event_t;
    if (event == E::object_start || event == E::array_start) keys.emplace_back();
    if ((event == E::object_end || event == E::array_end) && !keys.empty()) keys.pop_back();
    if (event == E::key && !keys.empty() && !keys.back().insert(parsed.template get<std::string>()).second &&
        duplicate.empty())
      duplicate = parsed.template get<std::string>();
    return true;
  };
  J doc;
  try {
    doc = J::parse(text, check);
  } catch (const nlohmann::json::exception& e) {  // also out_of_range: 1e400
    throw InputError(source + ": not valid JSON (" + e.what() + ")");
  }
  if (!duplicate.empty())
    throw InputError(source + ": key \"" + printable(duplicate.substr(0, 64)) +
                     "\" appears twice in one object; give each key once");
  return doc;
}

// JSON a study database holds, under the same limits; a value that breaks them, or is not JSON,
// comes back discarded (is_discarded()) for the caller to skip or refuse.
nlohmann::json parse_stored_json(const std::string& text);

}  // namespace crevasse
