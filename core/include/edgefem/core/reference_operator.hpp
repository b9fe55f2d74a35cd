// The reference back-end's elastic operators: every kernel declared by
// ElasticOperator (forces, energy, stiffness blocks, K x, diagonal blocks)
// as plain serial loops over the items in index order, each item computed
// by the formulas of edgefem/physics/ and nothing else: no lanes, tiles,
// rings, colours or threads. It is the oracle the tests hold every other
// back-end to; it is not tuned for speed.
//
// The edge method keeps the mesh-wide TSEP list (L(P) and the four stiffness
// targets per pair); the per-tet method one 12 x 12 stiffness (10 blocks)
// per tet.
#pragma once

#include <memory>

#include "edgefem/core/elastic_operator.hpp"

namespace edgefem {

// Throws InvalidArgument for SN with the per-tet method and for invalid
// materials.
template <class S>
std::unique_ptr<ElasticOperator<S>> make_reference_operator(const Mesh& mesh, const Materials& materials,
                                                            ModelKind model, Method method);

extern template std::unique_ptr<ElasticOperator<double>> make_reference_operator<double>(const Mesh&,
                                                                                        const Materials&, ModelKind,
                                                                                        Method);
extern template std::unique_ptr<ElasticOperator<float>> make_reference_operator<float>(const Mesh&, const Materials&,
                                                                                      ModelKind, Method);

}  // namespace edgefem
