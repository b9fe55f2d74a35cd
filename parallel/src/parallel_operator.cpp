#include "edgefem/parallel/parallel_operator.hpp"

#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/inverted_tets.hpp"
#include "edgefem/core/tet_model.hpp"
#include "edgefem/parallel/parallel_edge_kernels.hpp"
#include "edgefem/parallel/parallel_tet_kernels.hpp"

namespace edgefem {

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
        const auto& m = k_.model();
        S T[9];
        for (index_t e = 0; e < m.num_edges(); ++e) {
            const S* k = &K_.K[9 * std::size_t(e)];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) T[3 * i + j] = k[3 * j + i];
            visit(ctx, m.edge[e][0], m.edge[e][1], k);
            visit(ctx, m.edge[e][1], m.edge[e][0], T);
        }
        std::vector<S> D(9 * std::size_t(m.num_vertices));
        diagonal_blocks(D.data());
        for (index_t v = 0; v < m.num_vertices; ++v) visit(ctx, v, v, &D[9 * std::size_t(v)]);
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
          k_(make_tet_model<S>(mesh, materials), ex, variant, opts),
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
        const auto& m = k_.model();
        S T[9];
        for (index_t t = 0; t < m.num_tets(); ++t)
            for (int a = 0; a < 4; ++a)
                for (int b = a; b < 4; ++b) {
                    const S* blk = &K_.K[90 * std::size_t(t) + 9 * tet_block_index(a, b)];
                    visit(ctx, m.tet[t][a], m.tet[t][b], blk);
                    if (a == b) continue;
                    for (int i = 0; i < 3; ++i)
                        for (int j = 0; j < 3; ++j) T[3 * i + j] = blk[3 * j + i];
                    visit(ctx, m.tet[t][b], m.tet[t][a], T);
                }
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
std::unique_ptr<ElasticOperator<S>> make_parallel_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                           Method method, std::shared_ptr<const Executor> executor,
                                                           Variant variant, const PlanOptions& opts) {
    if (!executor) executor = std::make_shared<SerialExecutor>();
    if (method == Method::Tet) {
        if (model == ModelKind::SN)
            throw InvalidArgument("the spring-network model exists only for the edge method");
        return std::make_unique<ParallelTetOperator<S>>(mesh, materials, executor, variant, opts);
    }
    if (model == ModelKind::SN)
        return std::make_unique<ParallelEdgeOperator<S, ModelKind::SN>>(mesh, materials, executor, variant, opts);
    return std::make_unique<ParallelEdgeOperator<S, ModelKind::FE>>(mesh, materials, executor, variant, opts);
}

template <class S>
OperatorFactory<S> parallel_operator_factory(std::shared_ptr<const Executor> executor, Variant variant, PlanOptions opts) {
    return [executor = std::move(executor), variant, opts](const Mesh& mesh, const Materials& materials, ModelKind model,
                                                           Method method) {
        return make_parallel_operator<S>(mesh, materials, model, method, executor, variant, opts);
    };
}

ColouringReport colouring_report(const Mesh& mesh, const PlanOptions& opts) {
    const Topology topo = build_topology(mesh);
    const Materials mat(Material{});
    const EdgeModel<double> m = make_edge_model<double>(topo, compute_coefficients(mesh, topo, mat));
    ColouringReport r;
    r.edges = colour_vertex_segments(m, resolved_vertex_colouring(opts.vertex_colouring, m.num_vertices)).stats();
    r.tsep_strain = colour_tsep_strain(m, opts.segment_colouring).stats();
    r.tsep_stiffness = colour_tsep_stiffness(m, opts.segment_colouring).stats();
    r.tets = colour_tet_batches(make_tet_model<double>(mesh, mat), opts.tet_colouring).stats();
    return r;
}

template index_t count_inverted_tets_parallel<double>(const Executor&, const Mesh&, const double*);
template index_t count_inverted_tets_parallel<float>(const Executor&, const Mesh&, const float*);
template index_t count_inverted_tets_parallel<double>(const Executor&, const Mesh&, const double*,
                                                      std::vector<double>&);
template index_t count_inverted_tets_parallel<float>(const Executor&, const Mesh&, const float*, std::vector<double>&);
template OperatorFactory<double> parallel_operator_factory<double>(std::shared_ptr<const Executor>, Variant, PlanOptions);
template OperatorFactory<float> parallel_operator_factory<float>(std::shared_ptr<const Executor>, Variant, PlanOptions);
template std::unique_ptr<ElasticOperator<double>> make_parallel_operator<double>(const Mesh&, const Materials&, ModelKind,
                                                                                Method, std::shared_ptr<const Executor>,
                                                                                Variant, const PlanOptions&);
template std::unique_ptr<ElasticOperator<float>> make_parallel_operator<float>(const Mesh&, const Materials&, ModelKind,
                                                                              Method, std::shared_ptr<const Executor>,
                                                                              Variant, const PlanOptions&);

}  // namespace edgefem
