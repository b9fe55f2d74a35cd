// A preconditioner for CG on a LinearSystem: set up after K was built,
// then applied range by range inside the cg kernel's passes.
#pragma once

#include <memory>

#include "solvers/linear_system.hpp"

namespace edgefem::sim {

template <class S>
class Preconditioner : public CgPreconditioner {
public:
    virtual void setup(const LinearSystem<S>& A) = 0;
};

// Block-Jacobi (block_jacobi.cpp).
template <class S>
std::unique_ptr<Preconditioner<S>> make_block_jacobi(const SimState<S>& state);

}  // namespace edgefem::sim
