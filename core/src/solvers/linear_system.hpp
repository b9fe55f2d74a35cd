// The system the implicit steps solve: A = c_m M + c_k K + c_b K0, with M
// the lumped mass, K the operator's tangent and K0 a second operator's (the
// tangent frozen at the step's start for Rayleigh damping; none when
// c_b = 0). Applied in two parts, as the cg kernel takes it: the products
// K x (and K0 x), then per range the mass term and the sum.
#pragma once

#include "simulator/state.hpp"

namespace edgefem::sim {

template <class S>
class LinearSystem final : public CgSystem {
public:
    explicit LinearSystem(SimState<S>& state)
        : s_(state), Ax_(state.template vector<double>(0)) {}

    // `definite`: K was built definite (SolverSettings::definite_stiffness
    // or the retry on negative curvature), recorded for checkpoints.
    void set(double c_m, double c_k, double c_b, const ElasticOperator<S>* K0, bool definite = false) {
        c_m_ = c_m;
        c_k_ = c_k;
        c_b_ = c_b;
        K0_ = K0;
        definite_ = definite;
    }
    bool definite() const { return definite_; }
    double c_m() const { return c_m_; }
    double c_k() const { return c_k_; }
    double c_b() const { return c_b_; }
    const ElasticOperator<S>& K() const { return *s_.op; }
    const ElasticOperator<S>* K0() const { return K0_; }

    // out = K in, and K0 in kept for finish().
    void products(const double* in, double* out) override;
    // out = c_m M in + c_k out (+ c_b K0 in) on [lo, hi), after products().
    void finish(std::size_t lo, std::size_t hi, const double* in, double* out) const override;
    // out = A in.
    void apply(const double* in, double* out);

private:
    SimState<S>& s_;
    double c_m_ = 0, c_k_ = 0, c_b_ = 0;
    const ElasticOperator<S>* K0_ = nullptr;
    bool definite_ = false;
    BackendVector<double> Ax_;  // K0 x
};

extern template class LinearSystem<double>;
extern template class LinearSystem<float>;

}  // namespace edgefem::sim
