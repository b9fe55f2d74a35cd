// The AMG preconditioner: SmoothedAggregation (smoothed_aggregation.hpp) on
// A = c_m M + c_k K (+ c_b K0). The hierarchy (aggregates, prolongators) is
// built at the first set-up from the rest shape and the edge graph and kept;
// each later set-up (a new K) assembles A into its fixed pattern
// (SystemMatrix) and refreshes the Galerkin operators, smoothers and the
// coarsest factorisation. The finest level's products are the LinearSystem's
// matrix-free ones (the per-edge K on the back-end's executor). A
// whole-vector preconditioner: one V-cycle per CG iteration. On the host.
#include "edgefem/core/smoothed_aggregation.hpp"
#include "solvers/preconditioner.hpp"
#include "solvers/system_matrix.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class Amg final : public Preconditioner<S> {
public:
    explicit Amg(const SimState<S>& state) : s_(state), matrix_(state) { matrix_.keep(false, true); }

    void setup(LinearSystem<S>& A) override {
        A_ = &A;
        matrix_.assemble(A);
        if (!built_) amg_.build(matrix_.projected(), s_.scene.mesh.X, s_.free_host);
        else amg_.refresh(matrix_.projected());
        built_ = true;
    }

    bool whole_vector() const override { return true; }

    void apply(std::size_t lo, std::size_t hi, const double* r, double* z) const override {
        if (lo != 0 || hi != s_.n()) throw InvalidArgument("AMG preconditioner: applies to the whole vector only");
        const auto& fr = s_.free_host;
        amg_.apply(r, z, [&](const double* x, double* y) {
            A_->apply(x, y);
            for (std::size_t i = 0; i < fr.size(); ++i)
                if (!fr[i]) y[i] = 0;
        });
    }

    std::size_t bytes() const override { return amg_.bytes() + matrix_.bytes(); }

private:
    const SimState<S>& s_;
    SystemMatrix<S> matrix_;
    SmoothedAggregation amg_;
    LinearSystem<S>* A_ = nullptr;
    bool built_ = false;
};

}  // namespace

template <class S>
std::unique_ptr<Preconditioner<S>> make_amg(const SimState<S>& state) {
    return std::make_unique<Amg<S>>(state);
}

template std::unique_ptr<Preconditioner<double>> make_amg(const SimState<double>&);
template std::unique_ptr<Preconditioner<float>> make_amg(const SimState<float>&);

}  // namespace edgefem::sim
