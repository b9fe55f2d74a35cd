#include "edgefem/core/reference_operator.hpp"

#include <algorithm>
#include <vector>

#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/inverted_tets.hpp"
#include "edgefem/core/operator_blocks.hpp"
#include "edgefem/core/tet_model.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "edgefem/physics/edge_blocks.hpp"
#include "edgefem/physics/edge_force.hpp"
#include "edgefem/physics/edge_g.hpp"
#include "edgefem/physics/edge_stiffness.hpp"
#include "edgefem/physics/edge_strain.hpp"
#include "edgefem/physics/tet_stvk.hpp"
#include "edgefem/physics/tsep_stiffness.hpp"

namespace edgefem {

namespace {

template <class S>
void fill_zero(S* x, std::size_t n) {
    std::fill(x, x + n, S(0));
}

// The edge-based method: an edge loop (p~, zeta, g = L(E) zeta), a TSEP
// loop (the pair terms of g), an edge scatter; the stiffness as edge terms
// plus every pair's four target blocks.
template <class S, ModelKind Kind>
class ReferenceEdgeOperator final : public ElasticOperator<S> {
public:
    ReferenceEdgeOperator(const Mesh& mesh, const Materials& materials) : mesh_(mesh) {
        const Topology topo = build_topology(mesh);
        m_ = make_edge_model<S>(topo, compute_coefficients(mesh, topo, materials));
        K_.resize(9 * (std::size_t(m_.num_edges()) + 1));  // + the sink block of diagonal targets
        scratch_.resize(3 * std::size_t(m_.num_vertices));
    }
    index_t num_vertices() const override { return m_.num_vertices; }

    double forces(const S* u, S* f, bool energy) override { return evaluate(u, f, energy, state_); }
    // On a state of its own: a K built after it stays at the last forces()
    // call's u.
    double energy(const S* u) override { return evaluate(u, scratch_.data(), true, energy_state_); }
    // K at the state of the last forces() call (which must have run).
    void build_stiffness(bool definite) override {
        const index_t ne = m_.num_edges();
        if (state_.g.size() != std::size_t(ne)) throw Error("build_stiffness: forces() has not been called");
        const S* p = state_.p.data();
        for (index_t e = 0; e < ne; ++e)
            physics::edge_stiffness(m_.LE[e], S(physics::stiffness_g(state_.g[e], definite)), &p[3 * std::size_t(e)],
                                    &K_[9 * std::size_t(e)]);
        if constexpr (Kind == ModelKind::FE)
            for (index_t e0 = 0; e0 < ne; ++e0)
                for (index_t P = m_.tsep_first[e0]; P < m_.tsep_first[e0 + 1]; ++P) {
                    const S* ends[2] = {&p[3 * std::size_t(e0)], &p[3 * std::size_t(m_.tsep_other[P])]};
                    const S c = physics::pair_coefficient(m_.LP[P]);
                    for (int k = 0; k < 4; ++k) {
                        const index_t t = m_.target[P][k];  // the sink block #E for a diagonal target
                        physics::add_pair_block(physics::slot_coefficient(c, k), ends[t & 1], ends[(t & 1) ^ 1],
                                                &K_[9 * std::size_t(t >> 1)]);
                    }
                }
    }
    void multiply(const S* x, S* y) const override {
        fill_zero(y, 3 * std::size_t(m_.num_vertices));
        for (index_t e = 0; e < m_.num_edges(); ++e) {
            const index_t a = m_.edge[e][0], b = m_.edge[e][1];
            const S* k = &K_[9 * std::size_t(e)];
            const S d0 = x[3 * a] - x[3 * b], d1 = x[3 * a + 1] - x[3 * b + 1], d2 = x[3 * a + 2] - x[3 * b + 2];
            for (int i = 0; i < 3; ++i) {
                y[3 * a + i] -= physics::row_times(k[3 * i], k[3 * i + 1], k[3 * i + 2], d0, d1, d2);
                y[3 * b + i] += physics::transpose_times(k[i], k[3 + i], k[6 + i], d0, d1, d2);
            }
        }
    }
    void diagonal_blocks(S* D) const override {
        fill_zero(D, 9 * std::size_t(m_.num_vertices));
        for (index_t e = 0; e < m_.num_edges(); ++e) {
            const S* k = &K_[9 * std::size_t(e)];
            physics::subtract_block(k, &D[9 * std::size_t(m_.edge[e][0])]);
            physics::subtract_block_transposed(k, &D[9 * std::size_t(m_.edge[e][1])]);
        }
    }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        std::vector<S> D(9 * std::size_t(m_.num_vertices));
        diagonal_blocks(D.data());
        visit_edge_blocks(m_.edge, K_.data(), D, [&](index_t i, index_t j, const S* b) { visit(ctx, i, j, b); });
    }
    index_t inverted_tets(const S* u) const override { return count_inverted_tets(mesh_, u, positions_); }

private:
    // p~ (3 #E), zeta and g (#E) of one evaluation.
    struct State {
        std::vector<S> p, zeta;
        std::vector<double> g;
    };

    double evaluate(const S* u, S* f, bool energy, State& st) const {
        const index_t ne = m_.num_edges();
        st.p.resize(3 * std::size_t(ne));
        st.zeta.resize(ne);
        st.g.resize(ne);
        for (index_t e = 0; e < ne; ++e) {
            const index_t a = m_.edge[e][0], b = m_.edge[e][1];
            const S* r = &m_.rest[3 * std::size_t(e)];
            S* q = &st.p[3 * std::size_t(e)];
            st.zeta[e] = physics::edge_strain(u[3 * a] - u[3 * b], u[3 * a + 1] - u[3 * b + 1],
                                              u[3 * a + 2] - u[3 * b + 2], r[0], r[1], r[2], q[0], q[1], q[2]);
            st.g[e] = physics::own_g(m_.LE[e], st.zeta[e]);
        }
        if constexpr (Kind == ModelKind::FE)
            for (index_t e0 = 0; e0 < ne; ++e0)
                for (index_t P = m_.tsep_first[e0]; P < m_.tsep_first[e0 + 1]; ++P) {
                    const index_t e1 = m_.tsep_other[P];
                    st.g[e0] += physics::pair_g(double(m_.LP[P]), double(st.zeta[e1]));
                    st.g[e1] += physics::pair_g(double(m_.LP[P]), double(st.zeta[e0]));
                }
        fill_zero(f, 3 * std::size_t(m_.num_vertices));
        double W = 0;
        for (index_t e = 0; e < ne; ++e) {
            const index_t a = m_.edge[e][0], b = m_.edge[e][1];
            for (int r = 0; r < 3; ++r) {
                const S v = physics::edge_force(st.p[3 * std::size_t(e) + r], S(st.g[e]));
                f[3 * a + r] += v;
                f[3 * b + r] -= v;
            }
            if (energy) W += physics::energy_term(double(st.zeta[e]), st.g[e]);
        }
        return energy ? physics::energy_from_terms(W) : 0.0;
    }

    const Mesh& mesh_;
    EdgeModel<S> m_;
    State state_, energy_state_;  // the last forces() call's; energy()'s
    std::vector<S> K_;            // 9 (#E + 1)
    std::vector<S> scratch_;
    mutable std::vector<double> positions_;
};

// The per-tet method: each tet's deformation, forces and 10 stiffness
// blocks from physics/tet_stvk.hpp.
template <class S>
class ReferenceTetOperator final : public ElasticOperator<S> {
public:
    ReferenceTetOperator(const Mesh& mesh, const Materials& materials)
        : mesh_(mesh), m_(make_tet_model<S>(mesh, materials)), u_(mesh.X.size()) {}
    index_t num_vertices() const override { return m_.num_vertices; }
    double forces(const S* u, S* f, bool energy) override {
        std::copy(u, u + u_.size(), u_.begin());
        fill_zero(f, 3 * std::size_t(m_.num_vertices));
        double W = 0;
        for (index_t t = 0; t < m_.num_tets(); ++t) {
            const physics::TetDeformation<S> d = deformation(t, u);
            S ft[4][3];
            physics::tet_forces(d, m_.data[t].Dinv, ft);
            scatter(t, ft, f);
            W += double(d.energy);
        }
        return energy ? W : 0.0;
    }
    double energy(const S* u) override {
        double W = 0;
        for (index_t t = 0; t < m_.num_tets(); ++t) W += double(deformation(t, u).energy);
        return W;
    }
    void build_stiffness(bool definite) override {
        if (definite) throw InvalidArgument("the definite tangent (clamped g) exists only for the edge method");
        K_.resize(90 * std::size_t(m_.num_tets()));
        for (index_t t = 0; t < m_.num_tets(); ++t) {
            const physics::TetDeformation<S> d = deformation(t, u_.data());
            physics::TetStiffnessTerms<S> k;
            physics::tet_stiffness_terms<S>(d, m_.data[t].Dinv, m_.data[t].vol_lambda, m_.data[t].vol_mu, k);
            physics::tet_stiffness_blocks(k, &K_[90 * std::size_t(t)]);
        }
    }
    void multiply(const S* x, S* y) const override {
        fill_zero(y, 3 * std::size_t(m_.num_vertices));
        for (index_t t = 0; t < m_.num_tets(); ++t) {
            const auto& v = m_.tet[t];
            const S* Kt = &K_[90 * std::size_t(t)];
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j) {
                    const S* xj = &x[3 * v[j]];
                    const S* blk = &Kt[9 * physics::tet_block_index(std::min(i, j), std::max(i, j))];
                    for (int r = 0; r < 3; ++r)
                        y[3 * v[i] + r] += i <= j ? physics::row_times(blk[3 * r], blk[3 * r + 1], blk[3 * r + 2], xj[0], xj[1], xj[2])
                                                  : physics::transpose_times(blk[r], blk[3 + r], blk[6 + r], xj[0], xj[1], xj[2]);
                }
        }
    }
    void diagonal_blocks(S* D) const override { tet_diagonal_blocks(m_.tet, K_.data(), std::size_t(m_.num_vertices), D); }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        visit_tet_blocks(m_.tet, K_.data(), [&](index_t i, index_t j, const S* b) { visit(ctx, i, j, b); });
    }
    index_t inverted_tets(const S* u) const override { return count_inverted_tets(mesh_, u, positions_); }

private:
    physics::TetDeformation<S> deformation(index_t t, const S* u) const {
        S U[4][3];
        for (int i = 0; i < 4; ++i)
            for (int r = 0; r < 3; ++r) U[i][r] = u[3 * m_.tet[t][i] + r];
        physics::TetDeformation<S> d;
        physics::tet_deformation<true, S>(U, m_.data[t].Dinv, m_.data[t].vol_lambda, m_.data[t].vol_mu, d);
        return d;
    }
    void scatter(index_t t, const S (&ft)[4][3], S* f) const {
        for (int i = 0; i < 4; ++i)
            for (int r = 0; r < 3; ++r) f[3 * m_.tet[t][i] + r] += ft[i][r];
    }

    const Mesh& mesh_;
    TetModel<S> m_;
    std::vector<S> K_;  // 90 #T
    std::vector<S> u_;  // u of the last forces() call
    mutable std::vector<double> positions_;
};

}  // namespace

template <class S>
std::unique_ptr<ElasticOperator<S>> make_reference_operator(const Mesh& mesh, const Materials& materials,
                                                            ModelKind model, Method method) {
    check_mesh_indices(mesh);
    if (method == Method::Tet) {
        if (model == ModelKind::SN) throw InvalidArgument("the spring-network model exists only for the edge method");
        return std::make_unique<ReferenceTetOperator<S>>(mesh, materials);
    }
    if (model == ModelKind::SN) return std::make_unique<ReferenceEdgeOperator<S, ModelKind::SN>>(mesh, materials);
    return std::make_unique<ReferenceEdgeOperator<S, ModelKind::FE>>(mesh, materials);
}

template std::unique_ptr<ElasticOperator<double>> make_reference_operator<double>(const Mesh&, const Materials&,
                                                                                 ModelKind, Method);
template std::unique_ptr<ElasticOperator<float>> make_reference_operator<float>(const Mesh&, const Materials&,
                                                                               ModelKind, Method);

}  // namespace edgefem
