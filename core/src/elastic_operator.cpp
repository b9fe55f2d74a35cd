#include "edgefem/core/elastic_operator.hpp"

#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/edge_kernels.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/inverted_tets.hpp"
#include "edgefem/core/tet_edge_form.hpp"
#include "edgefem/core/tet_kernels.hpp"

namespace edgefem {

namespace {

template <class S, ModelKind Kind>
class EdgeOperator final : public ElasticOperator<S> {
public:
    EdgeOperator(const Mesh& mesh, const Materials& materials, StiffnessLayout layout) : mesh_(mesh) {
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
        S T[9];
        for (index_t e = 0; e < model_.num_edges(); ++e) {
            const S* k = &K_.K[9 * std::size_t(e)];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) T[3 * i + j] = k[3 * j + i];
            visit(ctx, model_.edge[e][0], model_.edge[e][1], k);
            visit(ctx, model_.edge[e][1], model_.edge[e][0], T);
        }
        std::vector<S> D(9 * std::size_t(model_.num_vertices));
        diagonal_blocks(D.data());
        for (index_t v = 0; v < model_.num_vertices; ++v) visit(ctx, v, v, &D[9 * std::size_t(v)]);
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
class TetOperator final : public ElasticOperator<S> {
public:
    TetOperator(const Mesh& mesh, const Materials& materials)
        : mesh_(mesh), model_(make_tet_model<S>(mesh, materials)), u_(mesh.X.size()), scratch_(mesh.X.size()) {}
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
        std::fill(D, D + 9 * std::size_t(model_.num_vertices), S(0));
        for (index_t t = 0; t < model_.num_tets(); ++t)
            for (int a = 0; a < 4; ++a) {
                const S* blk = &K_.K[90 * std::size_t(t) + 9 * tet_block_index(a, a)];
                S* d = &D[9 * std::size_t(model_.tet[t][a])];
                for (int i = 0; i < 9; ++i) d[i] += blk[i];
            }
    }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        S T[9];
        for (index_t t = 0; t < model_.num_tets(); ++t)
            for (int a = 0; a < 4; ++a)
                for (int b = a; b < 4; ++b) {
                    const S* blk = &K_.K[90 * std::size_t(t) + 9 * tet_block_index(a, b)];
                    visit(ctx, model_.tet[t][a], model_.tet[t][b], blk);
                    if (a == b) continue;
                    for (int i = 0; i < 3; ++i)
                        for (int j = 0; j < 3; ++j) T[3 * i + j] = blk[3 * j + i];
                    visit(ctx, model_.tet[t][b], model_.tet[t][a], T);
                }
    }
    index_t inverted_tets(const S* u) const override { return count_inverted_tets(mesh_, u, positions_); }

private:
    const Mesh& mesh_;
    TetModel<S> model_;
    TetStiffness<S> K_;
    std::vector<S> u_, scratch_;
    mutable std::vector<double> positions_;  // inverted_tets' scratch
};

}  // namespace

StiffnessLayout parse_stiffness_layout(const std::string& name) {
    if (name == "tet-local") return StiffnessLayout::TetLocal;
    if (name == "tsep-list") return StiffnessLayout::TsepList;
    throw InvalidArgument("unknown stiffness layout '" + name + "' (expected tet-local or tsep-list)");
}

const char* to_string(StiffnessLayout layout) { return layout == StiffnessLayout::TetLocal ? "tet-local" : "tsep-list"; }

template <class S>
std::unique_ptr<ElasticOperator<S>> make_elastic_operator(const Mesh& mesh, const Materials& materials,
                                                          ModelKind model, Method method, StiffnessLayout layout) {
    if (method == Method::Tet) {
        if (model == ModelKind::SN)
            throw InvalidArgument("the spring-network model exists only for the edge method");
        return std::make_unique<TetOperator<S>>(mesh, materials);
    }
    if (model == ModelKind::SN) return std::make_unique<EdgeOperator<S, ModelKind::SN>>(mesh, materials, layout);
    return std::make_unique<EdgeOperator<S, ModelKind::FE>>(mesh, materials, layout);
}

template std::unique_ptr<ElasticOperator<double>> make_elastic_operator<double>(const Mesh&, const Materials&, ModelKind,
                                                                               Method, StiffnessLayout);
template std::unique_ptr<ElasticOperator<float>> make_elastic_operator<float>(const Mesh&, const Materials&, ModelKind,
                                                                             Method, StiffnessLayout);

}  // namespace edgefem
