// libFuzzer harness: read_tetgen on arbitrary bytes, split into the .node,
// .ele and .face files at the first and second "@@" lines (a missing part
// is an empty file; no second "@@": no .face file), then validate_mesh.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string_view>

#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    const std::size_t cut = text.find("\n@@\n");
    const std::string_view node = text.substr(0, cut);
    std::string_view ele = cut == std::string_view::npos ? std::string_view() : text.substr(cut + 4);
    const std::size_t cut2 = ele.find("\n@@\n");
    const std::string_view face = cut2 == std::string_view::npos ? std::string_view() : ele.substr(cut2 + 4);
    ele = ele.substr(0, cut2);
    edgefem::fuzz::write("input.node", node);
    edgefem::fuzz::write("input.ele", ele);
    const std::string face_path = edgefem::fuzz::folder() + "/input.face";
    if (cut2 == std::string_view::npos)
        std::remove(face_path.c_str());
    else
        edgefem::fuzz::write("input.face", face);
    edgefem::fuzz::run([&] {
        edgefem::ReadReport report;
        edgefem::Mesh mesh = edgefem::read_tetgen(edgefem::fuzz::folder() + "/input", &report);
        edgefem::validate_mesh(mesh);
    });
    return 0;
}
