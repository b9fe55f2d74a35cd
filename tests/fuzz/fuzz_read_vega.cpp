// libFuzzer harness: read_vega on arbitrary bytes, then validate_mesh.
#include <cstddef>
#include <cstdint>

#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = edgefem::fuzz::write("input.veg", {reinterpret_cast<const char*>(data), size});
    edgefem::fuzz::run([&] {
        edgefem::ReadReport report;
        edgefem::Mesh mesh = edgefem::read_vega(path, &report);
        edgefem::validate_mesh(mesh);
    });
    return 0;
}
