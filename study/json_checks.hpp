#pragma once
// Checks shared by the JSON inputs of the study layer (study files, field observation files).
#include <initializer_list>
#include <string>

#include "engine/error.hpp"

namespace crevasse {

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
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      throw InputError((where.empty() ? it.key() : where + "." + it.key()) +
                       ": unknown key (allowed: " + list + ")");
    }
  }
}

}  // namespace crevasse
