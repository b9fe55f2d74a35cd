// libFuzzer harness: read_tetgen on arbitrary bytes, split into the .node
// and .ele files at the first "@@" line (without one, all is the .node file
// and the .ele file is empty), then validate_mesh.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    const std::size_t cut = text.find("\n@@\n");
    const std::string_view node = text.substr(0, cut);
    const std::string_view ele = cut == std::string_view::npos ? std::string_view() : text.substr(cut + 4);
    edgefem::fuzz::write("input.node", node);
    edgefem::fuzz::write("input.ele", ele);
    edgefem::fuzz::run([&] {
        edgefem::ReadReport report;
        edgefem::Mesh mesh = edgefem::read_tetgen(edgefem::fuzz::folder() + "/input", &report);
        edgefem::validate_mesh(mesh);
    });
    return 0;
}
