// Compressed sparse rows: row r holds items[offsets[r] .. offsets[r+1]).
#pragma once

#include <span>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

struct Csr {
    std::vector<index_t> offsets;  // #rows + 1
    std::vector<index_t> items;

    index_t rows() const { return offsets.empty() ? 0 : static_cast<index_t>(offsets.size() - 1); }
    std::span<const index_t> row(index_t r) const {
        return {items.data() + offsets[r], items.data() + offsets[r + 1]};
    }
};

}  // namespace edgefem
