// The per-tet StVK method on the device (the baseline the edge form is
// compared with on a GPU): per-tet passes (deformation, nodal forces, the 10
// stiffness blocks, the tet's share of K x) into per-tet slots, and a
// vertex gather of the slots (no floating-point atomics). Every term is a
// formula of edgefem/physics/tet_stvk.hpp.
#include "cuda/device_operators.cuh"
#include "edgefem/core/operator_blocks.hpp"
#include "edgefem/core/tet_model.hpp"
#include "edgefem/physics/edge_blocks.hpp"

namespace edgefem::cuda {

namespace tet_detail {

template <class S>
__device__ void tet_displacements(const index_t* tet, std::size_t t, const S* u, S (&U)[4][3]) {
    for (int i = 0; i < 4; ++i)
        for (int r = 0; r < 3; ++r) U[i][r] = u[3 * std::size_t(tet[4 * t + i]) + r];
}

// Tet t's deformation at u (with its energy).
template <class S>
__device__ physics::TetDeformation<S> deformation(const index_t* tet, const TetData<S>* data, std::size_t t,
                                                  const S* u) {
    S U[4][3];
    tet_displacements(tet, t, u, U);
    physics::TetDeformation<S> d;
    physics::tet_deformation<true, S>(U, data[t].Dinv, data[t].vol_lambda, data[t].vol_mu, d);
    return d;
}

template <class S>
class DeviceTetOperator final : public ElasticOperator<S> {
public:
    DeviceTetOperator(const Mesh& mesh, const Materials& materials)
        : tets_(mesh), host_(make_tet_model<S>(mesh, materials)), data_(host_.data) {
        nt_ = host_.num_tets();
        nv_ = host_.num_vertices;
        std::vector<index_t> first(std::size_t(nv_) + 1, 0), slot(4 * std::size_t(nt_));
        for (const auto& t : host_.tet)
            for (index_t v : t) ++first[std::size_t(v) + 1];
        for (index_t v = 0; v < nv_; ++v) first[v + 1] += first[v];
        std::vector<index_t> next(first.begin(), first.end() - 1);
        for (index_t t = 0; t < nt_; ++t)
            for (int i = 0; i < 4; ++i) slot[std::size_t(next[host_.tet[t][i]]++)] = 4 * t + i;
        v_first_ = DeviceArray<index_t>(first);
        v_slot_ = DeviceArray<index_t>(slot);
        per_tet_.resize(12 * std::size_t(nt_));
        w_.resize(nt_);
        u_.resize(3 * std::size_t(nv_));
    }
    index_t num_vertices() const override { return nv_; }
    double forces(const S* u, S* f, bool energy) override {
        check(cudaMemcpy(u_.data(), u, u_.size() * sizeof(S), cudaMemcpyDeviceToDevice), "cudaMemcpy (u)");
        evaluate(u, true);
        gather(f);
        return energy ? total_energy() : 0.0;
    }
    double energy(const S* u) override {
        evaluate(u, false);
        return total_energy();
    }
    void build_stiffness(bool definite) override {
        if (definite) throw InvalidArgument("the definite tangent (clamped g) exists only for the edge method");
        K_.resize(90 * std::size_t(nt_));
        const index_t* tet = tets_.tets.data();
        const TetData<S>* data = data_.data();
        const S* u = u_.data();
        S* K = K_.data();
        launch_.each(std::size_t(nt_), [=] __device__(std::size_t t) {
            const physics::TetDeformation<S> d = deformation(tet, data, t, u);
            physics::TetStiffnessTerms<S> k;
            physics::tet_stiffness_terms<S>(d, data[t].Dinv, data[t].vol_lambda, data[t].vol_mu, k);
            physics::tet_stiffness_blocks(k, &K[90 * t]);
        });
    }
    void multiply(const S* x, S* y) const override {
        const index_t* tet = tets_.tets.data();
        const S* K = K_.data();
        S* out = per_tet_.data();
        launch_.each(std::size_t(nt_), [=] __device__(std::size_t t) {
            S X[4][3];
            tet_displacements(tet, t, x, X);
            const S* Kt = &K[90 * t];
            for (int i = 0; i < 4; ++i)
                for (int r = 0; r < 3; ++r) {
                    S s = 0;
                    for (int j = 0; j < 4; ++j) {
                        const S* blk = &Kt[9 * physics::tet_block_index(i < j ? i : j, i < j ? j : i)];
                        s += i <= j ? physics::row_times(blk[3 * r], blk[3 * r + 1], blk[3 * r + 2], X[j][0], X[j][1], X[j][2])
                                    : physics::transpose_times(blk[r], blk[3 + r], blk[6 + r], X[j][0], X[j][1], X[j][2]);
                    }
                    out[12 * t + 3 * i + r] = s;
                }
        });
        gather(y);
    }
    void diagonal_blocks(S* D) const override {
        const index_t *first = v_first_.data(), *slot = v_slot_.data();
        const S* K = K_.data();
        launch_.each(std::size_t(nv_), [=] __device__(std::size_t v) {
            S d[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
            for (index_t j = first[v]; j < first[v + 1]; ++j) {
                const std::size_t t = std::size_t(slot[j] >> 2);
                const S* blk = &K[90 * t + 9 * physics::tet_block_index(slot[j] & 3, slot[j] & 3)];
                for (int i = 0; i < 9; ++i) d[i] += blk[i];
            }
            for (int i = 0; i < 9; ++i) D[9 * v + i] = d[i];
        });
    }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        const std::vector<S> K = K_.to_host();
        visit_tet_blocks(host_.tet, K.data(), [&](index_t i, index_t j, const S* b) { visit(ctx, i, j, b); });
    }
    index_t inverted_tets(const S* u) const override { return tets_.inverted(launch_, u); }

    // Public only because nvcc's extended lambdas may not sit in a private
    // member function.
    // Per tet: its energy into w_ and (`forces`) its nodal forces into the slots.
    void evaluate(const S* u, bool forces) const {
        const index_t* tet = tets_.tets.data();
        const TetData<S>* data = data_.data();
        S* out = per_tet_.data();
        double* w = w_.data();
        launch_.each(std::size_t(nt_), [=] __device__(std::size_t t) {
            const physics::TetDeformation<S> d = deformation(tet, data, t, u);
            w[t] = double(d.energy);
            if (!forces) return;
            S ft[4][3];
            physics::tet_forces(d, data[t].Dinv, ft);
            for (int i = 0; i < 4; ++i)
                for (int r = 0; r < 3; ++r) out[12 * t + 3 * i + r] = ft[i][r];
        });
    }
    // out[v] = the sum of v's slots, in slot order.
    void gather(S* out) const {
        const index_t *first = v_first_.data(), *slot = v_slot_.data();
        const S* in = per_tet_.data();
        launch_.each(std::size_t(nv_), [=] __device__(std::size_t v) {
            S acc[3] = {0, 0, 0};
            for (index_t j = first[v]; j < first[v + 1]; ++j)
                for (int r = 0; r < 3; ++r) acc[r] += in[3 * std::size_t(slot[j]) + r];
            for (int r = 0; r < 3; ++r) out[3 * v + r] = acc[r];
        });
    }
    double total_energy() const {
        const double* w = w_.data();
        return launch_.sum(std::size_t(nt_), [=] __device__(std::size_t t) { return w[t]; });
    }

private:
    DeviceLaunch launch_;
    DeviceTets tets_;
    TetModel<S> host_;  // the tets for for_each_block
    DeviceArray<TetData<S>> data_;
    index_t nt_ = 0, nv_ = 0;
    DeviceArray<index_t> v_first_, v_slot_;  // per vertex, its slots 4 t + i
    mutable DeviceArray<S> per_tet_;         // 12 #T: forces or K x per tet slot
    mutable DeviceArray<double> w_;          // #T energies
    DeviceArray<S> K_;                       // 90 #T
    DeviceArray<S> u_;                       // u of the last forces() call
};

}  // namespace tet_detail

template <class S>
std::unique_ptr<ElasticOperator<S>> make_device_tet_operator(const Mesh& mesh, const Materials& materials) {
    return std::make_unique<tet_detail::DeviceTetOperator<S>>(mesh, materials);
}

template std::unique_ptr<ElasticOperator<double>> make_device_tet_operator<double>(const Mesh&, const Materials&);
template std::unique_ptr<ElasticOperator<float>> make_device_tet_operator<float>(const Mesh&, const Materials&);

}  // namespace edgefem::cuda
