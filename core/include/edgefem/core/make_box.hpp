// Generated box meshes: NX x NY x NZ cubes of side `cell`, each split into the
// 6 Kuhn (Freudenthal) tets along its (0,0,0)->(1,1,1) diagonal, all positively
// oriented. make_box(10, 5, 4) is the paper's 1,200-tet box.
#pragma once

#include <cstdint>
#include <string>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

// The most tets a generated box may have (2^28, 268 million: 270 times
// bunny-1m; its mesh alone takes 5 GB), so that a mistyped size is an error
// naming the size rather than an out-of-memory failure.
inline constexpr std::int64_t kMaxBoxTets = std::int64_t(1) << 28;

// The box is centred at the origin. Vertex (i, j, k) has index
// i + (NX+1) (j + (NY+1) k). Throws InvalidArgument for non-positive sizes,
// more than kMaxBoxTets tets, or a box whose simulation would need more
// memory than is available (check_memory, memory_estimate.hpp: the message
// names the estimate and the memory available; EDGEFEM_NO_MEMORY_CHECK=1
// overrides it), before allocating anything.
Mesh make_box(index_t nx, index_t ny, index_t nz, double cell = 0.01);

// "box:NXxNYxNZ" (cubes of 0.01 m), the spelling the CLI and scene files
// accept for a generated mesh. is_box_spec tells whether a string uses it;
// make_box_from_spec throws InvalidArgument unless the whole spec parses.
bool is_box_spec(const std::string& spec);
Mesh make_box_from_spec(const std::string& spec);

// A box of about `target_tets` tets with the paper box's 5:2.5:2 aspect
// (cells of 0.1 / nx m); used as a stand-in when a named mesh is absent.
Mesh make_box_of_size(double target_tets);

}  // namespace edgefem
