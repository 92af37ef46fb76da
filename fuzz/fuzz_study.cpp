// libFuzzer target for the study-file loader (scripts/fuzz.sh): parse_study, with relative
// base_scene paths taken from studies/ so that the shipped seeds resolve. A loader may only
// refuse bad input with InputError; any other exception, crash, leak, hang or undefined
// behaviour is a finding.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "engine/error.hpp"
#include "study/study_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path studies =
      std::filesystem::path(CREVASSE_SOURCE_DIR) / "studies";
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    crevasse::parse_study(text, studies, "fuzz.json");
  } catch (const crevasse::InputError&) {
  }
  return 0;
}
