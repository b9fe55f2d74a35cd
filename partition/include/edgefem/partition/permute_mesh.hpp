// Applying a vertex ordering: the renumbered mesh and the mapping of
// per-vertex data between the user's numbering and the internal one.
#pragma once

#include <span>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

// The mesh with vertex v renamed new_of_old[v]; tets are sorted by their
// smallest new vertex (then the others), so tet loops follow the same order.
// Regions and source information travel with their items.
Mesh permute_mesh(const Mesh& mesh, const std::vector<index_t>& new_of_old);

// old_of_new from new_of_old.
std::vector<index_t> invert_permutation(const std::vector<index_t>& new_of_old);

// Per-vertex data with `width` values per vertex (3 for xyz vectors):
// out[new_of_old[v]] = in[v] (to internal) and back.
template <class T>
void to_internal(std::span<const T> user, std::span<T> internal, const std::vector<index_t>& new_of_old, int width = 3) {
    for (std::size_t v = 0; v < new_of_old.size(); ++v)
        for (int r = 0; r < width; ++r) internal[width * std::size_t(new_of_old[v]) + r] = user[width * v + r];
}
template <class T>
void to_user(std::span<const T> internal, std::span<T> user, const std::vector<index_t>& new_of_old, int width = 3) {
    for (std::size_t v = 0; v < new_of_old.size(); ++v)
        for (int r = 0; r < width; ++r) user[width * v + r] = internal[width * std::size_t(new_of_old[v]) + r];
}

}  // namespace edgefem
