// Counting inverted tets of a deformed mesh (a per-step statistic).
#pragma once

#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

// Tets whose deformed volume (X + u) is not positive; u is 3 #V. The
// deformed positions go to `x` (3 #V, resized) first: a tet then gathers 4
// positions instead of 4 rest positions and 4 displacements (bunny-1m:
// 9.2 -> 4.5 ns per tet, that pass included).
template <class S>
index_t count_inverted_tets(const Mesh& mesh, const S* u, std::vector<double>& x);
// The same with a scratch of its own.
template <class S>
index_t count_inverted_tets(const Mesh& mesh, const S* u);

// The two passes, for callers that split them over threads: x = X + u for
// vertices [v0, v1); the tets of [t0, t1) with non-positive volume at x.
template <class S>
void deformed_positions(const Mesh& mesh, const S* u, double* x, index_t v0, index_t v1);
index_t count_inverted_in(const Mesh& mesh, const double* x, index_t t0, index_t t1);

extern template index_t count_inverted_tets<double>(const Mesh&, const double*, std::vector<double>&);
extern template index_t count_inverted_tets<float>(const Mesh&, const float*, std::vector<double>&);
extern template index_t count_inverted_tets<double>(const Mesh&, const double*);
extern template index_t count_inverted_tets<float>(const Mesh&, const float*);
extern template void deformed_positions<double>(const Mesh&, const double*, double*, index_t, index_t);
extern template void deformed_positions<float>(const Mesh&, const float*, double*, index_t, index_t);

}  // namespace edgefem
