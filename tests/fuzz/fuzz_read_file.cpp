// libFuzzer harness for a one-file mesh reader: EDGEFEM_FUZZ_READER (read_gmsh,
// read_medit or read_vega) on arbitrary bytes written to input.EDGEFEM_FUZZ_EXT,
// then validate_mesh. CMakeLists.txt builds it once per reader.
#include <cstddef>
#include <cstdint>

#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path =
        edgefem::fuzz::write("input." EDGEFEM_FUZZ_EXT, {reinterpret_cast<const char*>(data), size});
    edgefem::fuzz::run([&] {
        edgefem::ReadReport report;
        edgefem::Mesh mesh = edgefem::EDGEFEM_FUZZ_READER(path, &report);
        edgefem::validate_mesh(mesh);
    });
    return 0;
}
