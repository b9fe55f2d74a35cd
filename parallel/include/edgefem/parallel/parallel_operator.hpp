// Elastic operators whose kernels run on an Executor, for the Simulator:
//
//   auto ex = make_executor(Backend::TBB, 2);
//   Simulator<double> sim(scene, ex, parallel_operator_factory<double>(ex));  // Variant::Auto
//
// Variant::Auto, the default, picks owner when the vertex numbering has
// locality, else gather. The executor runs the CG vector operations, the
// factory's operators run forces, stiffness, K x, diagonal blocks and the
// inverted-tet count on the same executor. Colour, gather and owner (hence
// Auto) are deterministic: each gives bitwise the same step for any thread
// count (is_deterministic in variant.hpp).
#pragma once

#include <memory>
#include <vector>

#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/executor.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/colouring.hpp"
#include "edgefem/parallel/variant.hpp"

namespace edgefem {

template <class S>
OperatorFactory<S> parallel_operator_factory(std::shared_ptr<const Executor> executor, Variant variant = Variant::Auto,
                                             PlanOptions opts = {});

// Direct construction (what the factory calls).
template <class S>
std::unique_ptr<ElasticOperator<S>> make_parallel_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                           Method method, std::shared_ptr<const Executor> executor,
                                                           Variant variant = Variant::Auto,
                                                           const PlanOptions& opts = {});

// Tets with non-positive deformed volume, counted on the executor (blocked,
// so the count is exact for any thread count); the deformed positions go to
// `x` first (as count_inverted_tets).
template <class S>
index_t count_inverted_tets_parallel(const Executor& ex, const Mesh& mesh, const S* u, std::vector<double>& x);
template <class S>
index_t count_inverted_tets_parallel(const Executor& ex, const Mesh& mesh, const S* u);

// Colour counts of the edge method's colourings and the per-tet method's
// (batches of kTetBatchLanes tets) for a mesh (for `edgefem info` and the
// docs).
struct ColouringReport {
    ColouringStats edges, tsep_strain, tsep_stiffness, tets;
};
ColouringReport colouring_report(const Mesh& mesh, const PlanOptions& opts = {});

}  // namespace edgefem
