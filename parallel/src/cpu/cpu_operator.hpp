// The CPU back-end's operators with the plan's tuning knobs exposed (tests
// and benchmarks set colourings, owner parts and tiles; applications use
// make_cpu_operator of edgefem/parallel/cpu_backend.hpp), and the CPU
// back-end's other whole-mesh passes.
#pragma once

#include <memory>
#include <vector>

#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/executor.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "cpu/colouring.hpp"
#include "cpu/variant.hpp"

namespace edgefem {

// As make_cpu_operator; `plan` tunes the threaded variants (its
// stiffness_layout is replaced by options.layout).
template <class S>
std::unique_ptr<ElasticOperator<S>> make_cpu_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                      Method method, const CpuOptions& options, const PlanOptions& plan);
template <class S>
OperatorFactory<S> cpu_operator_factory(CpuOptions options, PlanOptions plan);

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
