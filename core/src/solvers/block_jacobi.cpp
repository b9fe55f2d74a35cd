// Block-Jacobi: the inverse of each vertex's 3x3 diagonal block of A
// (ops::block_jacobi_inverse, through the back-end's kernels).
#include "solvers/preconditioner.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class BlockJacobi final : public Preconditioner<S> {
public:
    explicit BlockJacobi(const SimState<S>& state)
        : s_(state), D_(state.template vector<S>(state.n() * 3)), D0_(state.template vector<S>(0)),
          Dinv_(state.template vector<double>(3 * state.n() + 1)) {}  // + 1: the last 4-lane row read (apply)

    void setup(LinearSystem<S>& A) override {
        A.K().diagonal_blocks(D_.data());
        if (A.c_b() != 0) {
            D0_.resize(D_.size());
            A.K0()->diagonal_blocks(D0_.data());
        }
        s_.kernels.block_jacobi_build(Dinv_.data(), D_.data(), D0_.data(), s_.mass.data(), A.c_m(), A.c_k(), A.c_b(),
                                      s_.n());
    }

    // A lagged K's (stiffness_interval > 1) set-up serves later steps.
    void save(CheckpointWriter& w) const override {
        const bool lagged = s_.scene.solver.stiffness_interval > 1;
        w.value(lagged);
        if (lagged) w.vector(Dinv_);
    }
    void load(CheckpointReader& r, LinearSystem<S>&) override {
        if (r.value<bool>("block-Jacobi flag")) r.vector(Dinv_, "block-Jacobi inverses");
    }

    std::size_t bytes() const override { return sizeof(double) * Dinv_.size() + sizeof(S) * (D_.size() + D0_.size()); }

    void apply(std::size_t lo, std::size_t hi, const double* r, double* z) const override {
        s_.kernels.block_jacobi_apply_range(lo, hi, Dinv_.data(), r, z);
    }

private:
    const SimState<S>& s_;
    BackendVector<S> D_, D0_;      // diagonal blocks of K and K0 (9 #V)
    BackendVector<double> Dinv_;   // their inverses (9 #V + 1)
};

}  // namespace

template <class S>
std::unique_ptr<Preconditioner<S>> make_block_jacobi(const SimState<S>& state) {
    return std::make_unique<BlockJacobi<S>>(state);
}

template std::unique_ptr<Preconditioner<double>> make_block_jacobi(const SimState<double>&);
template std::unique_ptr<Preconditioner<float>> make_block_jacobi(const SimState<float>&);

}  // namespace edgefem::sim
