// A preconditioner for CG on a LinearSystem: set up after K was built,
// then applied block by block inside CG's passes.
#pragma once

#include <cstddef>
#include <memory>

#include "solvers/linear_system.hpp"

namespace edgefem::sim {

template <class S>
class Preconditioner {
public:
    virtual ~Preconditioner() = default;
    virtual void setup(const LinearSystem<S>& A) = 0;
    // z = M^-1 r on [lo, hi) from r on [lo, hi) only; lo and hi are
    // multiples of 3 (whole vertices) or n.
    virtual void apply(std::size_t lo, std::size_t hi, const double* r, double* z) const = 0;
};

// Block-Jacobi (block_jacobi.cpp).
template <class S>
std::unique_ptr<Preconditioner<S>> make_block_jacobi(const SimState<S>& state);

}  // namespace edgefem::sim
