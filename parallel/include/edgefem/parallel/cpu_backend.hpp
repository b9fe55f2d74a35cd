// The CPU back-end's elastic operators: the kernels declared by
// ElasticOperator (forces, energy, stiffness blocks, K x, diagonal blocks)
// in their tuned CPU form (SIMD lanes, the tet-local form's tiles, owner /
// colour / gather scatters), on one thread or on an Executor's threads.
//
//   auto ex = make_executor(ExecutorKind::Pool, 0);               // every core
//   auto op = make_cpu_operator<double>(mesh, materials, ModelKind::FE, Method::Edge, {ex});
//
// Without an executor (and with Variant::Auto) the kernels run the serial
// loops: one thread, tiled on meshes larger than the cache, the forces of a
// call that keeps no state (keep_state(false)) on a ring of slots. With an
// executor they run the chosen variant on its threads; colour, gather and
// owner (hence Auto) give bitwise the same results for any thread count.
// The reference back-end (edgefem/core/reference_operator.hpp) computes the
// same quantities with plain loops; the tests hold this one to it.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/executor.hpp"
#include "edgefem/core/simulator.hpp"

namespace edgefem {

// How a threaded kernel resolves concurrent writes to one target.
enum class Variant {
    Colour,   // coloured scatter: colours in a fixed order, plain stores (deterministic)
    Gather,   // pull: each target sums its sources via CSR lists (deterministic)
    Atomic,   // scatter with std::atomic_ref fetch_add (order varies run to run)
    Private,  // one accumulator per thread part, then a parallel blocked reduction
    Owner,    // owner computes: fixed parts of consecutive items, forward spill + ordered reduction (deterministic)
    Auto,     // the default: Owner when the vertex numbering has locality (spill windows <= the vertices), else Gather
};
inline constexpr Variant kAllVariants[] = {Variant::Colour, Variant::Gather, Variant::Atomic, Variant::Private,
                                           Variant::Owner};
// "colour" (or "color") | "gather" | "atomic" | "private" | "owner" | "auto"; throws InvalidArgument.
Variant parse_variant(std::string_view name);
const char* to_string(Variant v);
// True for the variants whose results are bitwise independent of the thread count.
inline bool is_deterministic(Variant v) {
    return v == Variant::Colour || v == Variant::Gather || v == Variant::Owner || v == Variant::Auto;
}

// Where the edge method's FE stiffness takes its pair terms from: the
// per-tet 6x6 form (the default; 1.8-2.9x faster in double: docs/layouts.md,
// "Layouts: tet-local against tsep-list") or the mesh-wide TSEP list with its
// 4 targets per pair. With the tet-local form the serial loops and the owner
// variant take g from the form in the forces too; the other variants run the
// TSEP list for the forces. SN and the per-tet method ignore it.
enum class StiffnessLayout { TetLocal, TsepList };
// "tet-local" | "tsep-list"; throws InvalidArgument otherwise.
StiffnessLayout parse_stiffness_layout(const std::string& name);
const char* to_string(StiffnessLayout layout);

struct CpuOptions {
    // Null: the serial loops (or, with a variant other than Auto, that
    // variant on one thread).
    std::shared_ptr<const Executor> executor;
    Variant variant = Variant::Auto;
    StiffnessLayout layout = StiffnessLayout::TetLocal;
};

// Throws InvalidArgument for SN with the per-tet method and for invalid
// materials.
template <class S>
std::unique_ptr<ElasticOperator<S>> make_cpu_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                      Method method, const CpuOptions& options = {});

// The factory a Simulator takes (OperatorFactory).
template <class S>
OperatorFactory<S> cpu_operator_factory(CpuOptions options = {});

}  // namespace edgefem
