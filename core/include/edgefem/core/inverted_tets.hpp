// Counting inverted tets of a deformed mesh (a per-step statistic).
#pragma once

#include "edgefem/core/mesh.hpp"

namespace edgefem {

// Tets whose deformed volume (X + u) is not positive; u is 3 #V.
template <class S>
index_t count_inverted_tets(const Mesh& mesh, const S* u);

extern template index_t count_inverted_tets<double>(const Mesh&, const double*);
extern template index_t count_inverted_tets<float>(const Mesh&, const float*);

}  // namespace edgefem
