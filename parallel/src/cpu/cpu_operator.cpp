#include "cpu/cpu_operator.hpp"

#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/inverted_tets.hpp"
#include "edgefem/core/operator_blocks.hpp"
#include "edgefem/core/tet_model.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "cpu/edge_kernels.hpp"
#include "cpu/parallel_edge_kernels.hpp"
#include "cpu/parallel_tet_kernels.hpp"
#include "cpu/tet_edge_form.hpp"
#include "cpu/tet_kernels.hpp"

namespace edgefem {

StiffnessLayout parse_stiffness_layout(const std::string& name) {
    if (name == "tet-local") return StiffnessLayout::TetLocal;
    if (name == "tsep-list") return StiffnessLayout::TsepList;
    throw InvalidArgument("unknown stiffness layout '" + name + "' (expected tet-local or tsep-list)");
}

const char* to_string(StiffnessLayout layout) { return layout == StiffnessLayout::TetLocal ? "tet-local" : "tsep-list"; }

Variant parse_variant(std::string_view name) {
    if (name == "colour" || name == "color") return Variant::Colour;
    if (name == "gather") return Variant::Gather;
    if (name == "atomic") return Variant::Atomic;
    if (name == "private") return Variant::Private;
    if (name == "owner") return Variant::Owner;
    if (name == "auto") return Variant::Auto;
    throw InvalidArgument("unknown variant '" + std::string(name) +
                          "' (expected auto, colour, gather, atomic, private or owner)");
}

const char* to_string(Variant v) {
    switch (v) {
        case Variant::Colour: return "colour";
        case Variant::Gather: return "gather";
        case Variant::Atomic: return "atomic";
        case Variant::Owner: return "owner";
        case Variant::Auto: return "auto";
        default: return "private";
    }
}

template <class S>
index_t count_inverted_tets_parallel(const Executor& ex, const Mesh& mesh, const S* u, std::vector<double>& x) {
    x.resize(mesh.X.size());
    double* xs = x.data();
    for_blocks(ex, std::size_t(mesh.num_vertices()), [&](std::size_t b, std::size_t e) {
        deformed_positions(mesh, u, xs, index_t(b), index_t(e));
    });
    const std::size_t nt = std::size_t(mesh.num_tets());
    const std::size_t chunks = vector_blocks(nt);
    std::vector<index_t> partial(chunks, 0);
    for_blocks(ex, nt, [&](std::size_t b, std::size_t e) {
        partial[b / kVectorBlock] = count_inverted_in(mesh, xs, index_t(b), index_t(e));
    });
    index_t n = 0;
    for (index_t c : partial) n += c;
    return n;
}
template <class S>
index_t count_inverted_tets_parallel(const Executor& ex, const Mesh& mesh, const S* u) {
    std::vector<double> x;
    return count_inverted_tets_parallel(ex, mesh, u, x);
}

namespace {

// ---- The serial loops (no executor) ----------------------------------------

template <class S, ModelKind Kind>
class SerialEdgeOperator final : public ElasticOperator<S> {
public:
    SerialEdgeOperator(const Mesh& mesh, const Materials& materials, StiffnessLayout layout) : mesh_(mesh) {
        const Topology topo = build_topology(mesh);
        model_ = make_edge_model<S>(topo, compute_coefficients(mesh, topo, materials));
        if (Kind == ModelKind::FE && layout == StiffnessLayout::TetLocal) {
            form_ = make_tet_edge_form<S>(mesh, topo, materials);
            model_.target = {};  // the TSEP targets serve only the TSEP-list stiffness
            ring_ = make_form_ring(form_, model_.edge_first);
            if (!ring_.empty()) u_last_.resize(3 * std::size_t(model_.num_vertices));
        }
        state_.resize(model_.num_edges());
        K_.resize(model_.num_edges());
        scratch_.resize(3 * std::size_t(model_.num_vertices));
    }
    index_t num_vertices() const override { return model_.num_vertices; }
    // With the tet-local form, its g pass replaces the TSEP loop in the
    // forces too (same terms, another summation order: bench_kernels
    // force/edge-fe-tetform, 1.1-1.35x faster on bunny-4k and armadillo-7k).
    // On the ring (keep_state(false)) u is kept, so that build_stiffness()
    // can rebuild the state if it is asked for after all. (Copying u on
    // every call cost bunny-4k's force 2-3 %.)
    double forces(const S* u, S* f, bool energy) override {
        const bool ring = !keep_state_ && !ring_.empty();
        state_stale_ = last_on_ring_ = ring;
        if (ring) std::copy(u, u + u_last_.size(), u_last_.begin());
        return energy ? forces_with<true>(u, f, ring, state_) : forces_with<false>(u, f, ring, state_);
    }
    // Never touches state_ (a K built after it is still at the last forces()
    // call's u): on the ring, else on a state of its own.
    double energy(const S* u) override {
        if (!ring_.empty()) return forces_with<true>(u, scratch_.data(), true, state_);
        return forces_with<true>(u, scratch_.data(), false, energy_state_);
    }
    void keep_state(bool keep) override { keep_state_ = keep; }
    void build_stiffness(bool definite) override {
        if (state_stale_) {
            forces_with<false>(u_last_.data(), scratch_.data(), false, state_);
            state_stale_ = false;
        }
        if (form_.num_tets > 0) {
            if (definite)
                tet_form_stiffness_all<Kind, true>(model_, form_, state_, K_);
            else
                tet_form_stiffness_all<Kind, false>(model_, form_, state_, K_);
        } else if (definite) {
            edge_stiffness_all<Kind, true>(model_, state_, K_);
        } else {
            edge_stiffness_all<Kind, false>(model_, state_, K_);
        }
    }
    void multiply(const S* x, S* y) const override { edge_multiply(model_, K_, x, y); }
    void diagonal_blocks(S* D) const override { edge_diagonal_blocks(model_, K_, D); }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        std::vector<S> D(9 * std::size_t(num_vertices()));
        diagonal_blocks(D.data());
        visit_edge_blocks(model_.edge, K_.K.data(), D, [&](index_t i, index_t j, const S* b) { visit(ctx, i, j, b); });
    }
    index_t inverted_tets(const S* u) const override { return count_inverted_tets(mesh_, u, positions_); }
    bool forces_from_tet_local_form() const override { return form_.num_tets > 0; }
    bool forces_stored_state() const override { return !last_on_ring_; }

private:
    // `ring`: on ring_, else leaving the state in `st`.
    template <bool Energy>
    double forces_with(const S* u, S* f, bool ring, EdgeState<S>& st) {
        if (ring) return tet_form_forces_ring<Kind, Energy>(model_, form_, u, f, ring_);
        if (form_.num_tets > 0) return tet_form_forces<Kind, Energy>(model_, form_, u, f, st);
        return edge_forces<Kind, Energy>(model_, u, f, st);
    }

    const Mesh& mesh_;
    EdgeModel<S> model_;
    TetEdgeForm<S> form_;  // empty unless FE with the tet-local layout
    EdgeState<S> state_;
    EdgeState<S> energy_state_;  // energy()'s, sized on first use (edge_forces resizes)
    FormRing<S> ring_;  // empty unless the form runs in tiles (make_form_ring)
    bool keep_state_ = true, state_stale_ = false, last_on_ring_ = false;
    std::vector<S> u_last_;  // u of the last forces() call on the ring
    mutable std::vector<double> positions_;  // inverted_tets' scratch
    EdgeStiffness<S> K_;
    std::vector<S> scratch_;
};

template <class S>
class SerialTetOperator final : public ElasticOperator<S> {
public:
    SerialTetOperator(const Mesh& mesh, const Materials& materials)
        : mesh_(mesh), model_(make_batched_tet_model<S>(mesh, materials)), u_(mesh.X.size()), scratch_(mesh.X.size()) {}
    index_t num_vertices() const override { return model_.num_vertices; }
    double forces(const S* u, S* f, bool energy) override {
        std::copy(u, u + u_.size(), u_.begin());
        return energy ? tet_forces<true>(model_, u, f) : tet_forces<false>(model_, u, f);
    }
    double energy(const S* u) override { return tet_forces<true>(model_, u, scratch_.data()); }
    void build_stiffness(bool definite) override {
        if (definite)
            throw InvalidArgument("the definite tangent (clamped g) exists only for the edge method");
        tet_stiffness_all(model_, u_.data(), K_);
    }
    void multiply(const S* x, S* y) const override { tet_multiply(model_, K_, x, y); }
    void diagonal_blocks(S* D) const override {
        tet_diagonal_blocks(model_.tet, K_.K.data(), std::size_t(model_.num_vertices), D);
    }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        visit_tet_blocks(model_.tet, K_.K.data(), [&](index_t i, index_t j, const S* b) { visit(ctx, i, j, b); });
    }
    index_t inverted_tets(const S* u) const override { return count_inverted_tets(mesh_, u, positions_); }

private:
    const Mesh& mesh_;
    BatchedTetModel<S> model_;
    TetStiffness<S> K_;
    std::vector<S> u_, scratch_;
    mutable std::vector<double> positions_;  // inverted_tets' scratch
};

// ---- The threaded variants on an executor ----------------------------------

template <class S, ModelKind Kind>
class ParallelEdgeOperator final : public ElasticOperator<S> {
public:
    ParallelEdgeOperator(const Mesh& mesh, const Materials& materials, std::shared_ptr<const Executor> ex,
                         Variant variant, const PlanOptions& opts)
        : mesh_(mesh), k_(build_kernels(mesh, materials, std::move(ex), variant, opts)) {
        state_.resize(k_.model().num_edges());
        k_.resize(K_);
        scratch_.resize(3 * std::size_t(k_.model().num_vertices));
    }
    index_t num_vertices() const override { return k_.model().num_vertices; }
    double forces(const S* u, S* f, bool energy) override {
        return energy ? k_.template forces<Kind, true>(u, f, state_) : k_.template forces<Kind, false>(u, f, state_);
    }
    double energy(const S* u) override { return k_.template forces<Kind, true>(u, scratch_.data(), state_); }
    void build_stiffness(bool definite) override {
        if (definite)
            k_.template stiffness<Kind, true>(state_, K_);
        else
            k_.template stiffness<Kind, false>(state_, K_);
    }
    void multiply(const S* x, S* y) const override { k_.multiply(K_, x, y); }
    void diagonal_blocks(S* D) const override { k_.diagonal_blocks(K_, D); }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        std::vector<S> D(9 * std::size_t(num_vertices()));
        diagonal_blocks(D.data());
        visit_edge_blocks(k_.model().edge, K_.K.data(), D, [&](index_t i, index_t j, const S* b) { visit(ctx, i, j, b); });
    }
    index_t inverted_tets(const S* u) const override {
        return count_inverted_tets_parallel(k_.executor(), mesh_, u, positions_);
    }
    bool forces_from_tet_local_form() const override { return Kind == ModelKind::FE && k_.form_forces(); }

private:
    static ParallelEdgeKernels<S> build_kernels(const Mesh& mesh, const Materials& materials,
                                                std::shared_ptr<const Executor> ex, Variant variant,
                                                const PlanOptions& opts) {
        const Topology topo = build_topology(mesh);
        TetEdgeForm<S> form;
        if (Kind == ModelKind::FE && opts.stiffness && opts.stiffness_layout == StiffnessLayout::TetLocal)
            form = make_tet_edge_form<S>(mesh, topo, materials);
        return ParallelEdgeKernels<S>(make_edge_model<S>(topo, compute_coefficients(mesh, topo, materials)),
                                      std::move(ex), variant, opts, std::move(form));
    }
    const Mesh& mesh_;
    ParallelEdgeKernels<S> k_;
    EdgeState<S> state_;
    EdgeStiffness<S> K_;
    std::vector<S> scratch_;
    mutable std::vector<double> positions_;  // inverted_tets' scratch
};

template <class S>
class ParallelTetOperator final : public ElasticOperator<S> {
public:
    ParallelTetOperator(const Mesh& mesh, const Materials& materials, std::shared_ptr<const Executor> ex,
                        Variant variant, const PlanOptions& opts)
        : mesh_(mesh),
          ex_(ex),
          k_(make_batched_tet_model<S>(mesh, materials), ex, variant, opts),
          u_(mesh.X.size()),
          scratch_(mesh.X.size()) {}
    index_t num_vertices() const override { return k_.model().num_vertices; }
    double forces(const S* u, S* f, bool energy) override {
        par::for_range(*ex_, index_t(u_.size()), 8192, [&](index_t b, index_t e) { std::copy(u + b, u + e, u_.begin() + b); });
        return energy ? k_.template forces<true>(u, f) : k_.template forces<false>(u, f);
    }
    double energy(const S* u) override { return k_.template forces<true>(u, scratch_.data()); }
    void build_stiffness(bool definite) override {
        if (definite) throw InvalidArgument("the definite tangent (clamped g) exists only for the edge method");
        k_.stiffness(u_.data(), K_);
    }
    void multiply(const S* x, S* y) const override { k_.multiply(K_, x, y); }
    void diagonal_blocks(S* D) const override { k_.diagonal_blocks(K_, D); }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        visit_tet_blocks(k_.model().tet, K_.K.data(), [&](index_t i, index_t j, const S* b) { visit(ctx, i, j, b); });
    }
    index_t inverted_tets(const S* u) const override { return count_inverted_tets_parallel(*ex_, mesh_, u, positions_); }

private:
    const Mesh& mesh_;
    std::shared_ptr<const Executor> ex_;
    ParallelTetKernels<S> k_;
    TetStiffness<S> K_;
    mutable std::vector<double> positions_;  // inverted_tets' scratch
    std::vector<S> u_, scratch_;
};

}  // namespace

template <class S>
std::unique_ptr<ElasticOperator<S>> make_cpu_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                      Method method, const CpuOptions& options, const PlanOptions& plan) {
    check_mesh_indices(mesh);
    if (method == Method::Tet && model == ModelKind::SN)
        throw InvalidArgument("the spring-network model exists only for the edge method");
    if (!options.executor && options.variant == Variant::Auto) {  // the serial loops
        if (method == Method::Tet) return std::make_unique<SerialTetOperator<S>>(mesh, materials);
        if (model == ModelKind::SN) return std::make_unique<SerialEdgeOperator<S, ModelKind::SN>>(mesh, materials, options.layout);
        return std::make_unique<SerialEdgeOperator<S, ModelKind::FE>>(mesh, materials, options.layout);
    }
    const std::shared_ptr<const Executor> ex = options.executor ? options.executor : std::make_shared<SerialExecutor>();
    PlanOptions opts = plan;
    opts.stiffness_layout = options.layout;
    if (method == Method::Tet) return std::make_unique<ParallelTetOperator<S>>(mesh, materials, ex, options.variant, opts);
    if (model == ModelKind::SN)
        return std::make_unique<ParallelEdgeOperator<S, ModelKind::SN>>(mesh, materials, ex, options.variant, opts);
    return std::make_unique<ParallelEdgeOperator<S, ModelKind::FE>>(mesh, materials, ex, options.variant, opts);
}

template <class S>
std::unique_ptr<ElasticOperator<S>> make_cpu_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                      Method method, const CpuOptions& options) {
    return make_cpu_operator<S>(mesh, materials, model, method, options, PlanOptions{});
}

template <class S>
OperatorFactory<S> cpu_operator_factory(CpuOptions options, PlanOptions plan) {
    return [options = std::move(options), plan](const Mesh& mesh, const Materials& materials, ModelKind model,
                                                Method method) {
        return make_cpu_operator<S>(mesh, materials, model, method, options, plan);
    };
}

template <class S>
OperatorFactory<S> cpu_operator_factory(CpuOptions options) {
    return cpu_operator_factory<S>(std::move(options), PlanOptions{});
}

ColouringReport colouring_report(const Mesh& mesh, const PlanOptions& opts) {
    const Topology topo = build_topology(mesh);
    const Materials mat(Material{});
    const EdgeModel<double> m = make_edge_model<double>(topo, compute_coefficients(mesh, topo, mat));
    ColouringReport r;
    r.edges = colour_vertex_segments(m, resolved_vertex_colouring(opts.vertex_colouring, m.num_vertices)).stats();
    r.tsep_strain = colour_tsep_strain(m, opts.segment_colouring).stats();
    r.tsep_stiffness = colour_tsep_stiffness(m, opts.segment_colouring).stats();
    r.tets = colour_tet_batches(make_batched_tet_model<double>(mesh, mat), opts.tet_colouring).stats();
    return r;
}

template index_t count_inverted_tets_parallel<double>(const Executor&, const Mesh&, const double*);
template index_t count_inverted_tets_parallel<float>(const Executor&, const Mesh&, const float*);
template index_t count_inverted_tets_parallel<double>(const Executor&, const Mesh&, const double*,
                                                      std::vector<double>&);
template index_t count_inverted_tets_parallel<float>(const Executor&, const Mesh&, const float*, std::vector<double>&);
template std::unique_ptr<ElasticOperator<double>> make_cpu_operator<double>(const Mesh&, const Materials&, ModelKind, Method,
                                                                          const CpuOptions&, const PlanOptions&);
template std::unique_ptr<ElasticOperator<double>> make_cpu_operator<double>(const Mesh&, const Materials&, ModelKind, Method,
                                                                          const CpuOptions&);
template OperatorFactory<double> cpu_operator_factory<double>(CpuOptions, PlanOptions);
template OperatorFactory<double> cpu_operator_factory<double>(CpuOptions);
template std::unique_ptr<ElasticOperator<float>> make_cpu_operator<float>(const Mesh&, const Materials&, ModelKind, Method,
                                                                          const CpuOptions&, const PlanOptions&);
template std::unique_ptr<ElasticOperator<float>> make_cpu_operator<float>(const Mesh&, const Materials&, ModelKind, Method,
                                                                          const CpuOptions&);
template OperatorFactory<float> cpu_operator_factory<float>(CpuOptions, PlanOptions);
template OperatorFactory<float> cpu_operator_factory<float>(CpuOptions);

}  // namespace edgefem
