// The inputs of a tangent set-up that outlives its step (the lagged K of
// SolverSettings::stiffness_interval, the AMG's hierarchy and last refresh):
// the u K was built at (the operator's last forces() state), the damping
// tangent's u, whether K was definite and A's coefficients. A checkpoint
// saves them instead of the matrices and rebuilds the set-up from them on
// loading, bit for bit (the kernels are deterministic).
#pragma once

#include <memory>
#include <vector>

#include "simulator/checkpoint_stream.hpp"
#include "solvers/linear_system.hpp"

namespace edgefem::sim {

template <class S>
struct TangentPoint {
    std::vector<S> u;   // K's state
    std::vector<S> u0;  // K0's (c_b != 0)
    bool definite = false;
    double c_m = 0, c_k = 0, c_b = 0;
    bool valid = false;

    // The set-up A is being made for, now (its K just built at s.u).
    void record(const SimState<S>& s, const LinearSystem<S>& A);
    // s.op's K rebuilt at the point (and K0 in `k0` when c_b != 0); A set
    // to the point's coefficients.
    void rebuild(const SimState<S>& s, LinearSystem<S>& A, std::unique_ptr<ElasticOperator<S>>& k0) const;

    void save(CheckpointWriter& w) const;
    void load(CheckpointReader& r, std::size_t n);
};

extern template struct TangentPoint<double>;
extern template struct TangentPoint<float>;

}  // namespace edgefem::sim
