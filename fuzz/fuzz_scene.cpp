// libFuzzer target for the scene loader (scripts/fuzz.sh): the bytes go through
// parse_scene_text, the function `crevasse run` reads a scene file with. A loader may only
// refuse bad input with InputError; any other exception, crash, leak, hang or undefined
// behaviour is a finding. An accepted scene must also
// survive the round trip through its canonical form, which is what scene_resolved.json holds
// and what a study hashes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/error.hpp"
#include "engine/scene.hpp"
#include "study/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using nlohmann::json;
  crevasse::SceneConfig scene;
  try {
    scene = crevasse::parse_scene_text(std::string(reinterpret_cast<const char*>(data), size),
                                       "fuzz.json");
  } catch (const crevasse::InputError&) {
    return 0;
  }
  const json canonical = crevasse::scene_to_json(scene);
  // Re-reading the resolved scene must give the same scene: no InputError allowed here.
  if (crevasse::scene_to_json(crevasse::scene_from_json(canonical)) != canonical) std::abort();
  return 0;
}
