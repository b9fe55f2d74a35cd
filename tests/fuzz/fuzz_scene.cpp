// libFuzzer harness: parse_scene on arbitrary text (paths resolve against an
// empty folder, so only generated boxes make meshes; EDGEFEM_NO_MEMORY_CHECK
// is left unset, so a huge box is refused by the memory estimate).
#include <cstddef>
#include <cstdint>
#include <string>

#include "edgefem/core/scene_json.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    edgefem::fuzz::run([&] { edgefem::parse_scene(text, edgefem::fuzz::folder(), "fuzz.json"); });
    return 0;
}
