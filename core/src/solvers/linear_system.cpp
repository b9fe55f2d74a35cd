#include "solvers/linear_system.hpp"

namespace edgefem::sim {

template <class S>
void LinearSystem<S>::products(const double* in, double* out) {
    s_.multiply(*s_.op, in, out);
    if (c_b_ != 0) {
        Ax_.resize(s_.n());
        s_.multiply(*K0_, in, Ax_.data());
    }
}

template <class S>
void LinearSystem<S>::finish(std::size_t lo, std::size_t hi, const double* in, double* out) const {
    s_.kernels.system_diagonal_range(lo, hi, c_m_, c_k_, c_b_, s_.mass_dof.data(), in, Ax_.data(), out);
}

template <class S>
void LinearSystem<S>::apply(const double* in, double* out) {
    products(in, out);
    s_.kernels.system_diagonal(s_.n(), c_m_, c_k_, c_b_, s_.mass_dof.data(), in, Ax_.data(), out);
}

template class LinearSystem<double>;
template class LinearSystem<float>;

}  // namespace edgefem::sim
