#include "solvers/linear_system.hpp"

namespace edgefem::sim {

template <class S>
void LinearSystem<S>::multiply(const ElasticOperator<S>& op, const double* in, double* out) {
    if constexpr (std::is_same_v<S, double>) {
        op.multiply(in, out);
    } else {
        xs_.resize(s_.n());
        ys_.resize(s_.n());
        s_.each([&](std::size_t i) { xs_[i] = S(in[i]); });
        op.multiply(xs_.data(), ys_.data());
        s_.each([&](std::size_t i) { out[i] = double(ys_[i]); });
    }
}

template <class S>
void LinearSystem<S>::products(const double* in, double* out) {
    multiply(*s_.op, in, out);
    if (c_b_ != 0) {
        Ax_.resize(s_.n());
        multiply(*K0_, in, Ax_.data());
    }
}

// Mass per dof, scalars by value: vectorises (over mass[i / 3] with c_m,
// c_k by reference it did not).
template <class S>
void LinearSystem<S>::finish(std::size_t lo, std::size_t hi, const double* in, double* out) const {
    const double c_m = c_m_, c_k = c_k_, c_b = c_b_;
    const double* __restrict m = s_.mass_dof.data();
    const double* __restrict xin = in;
    double* __restrict y = out;
    for (std::size_t i = lo; i < hi; ++i) y[i] = c_m * m[i] * xin[i] + c_k * y[i];
    if (c_b != 0) {
        const double* __restrict a = Ax_.data();
        for (std::size_t i = lo; i < hi; ++i) y[i] += c_b * a[i];
    }
}

template <class S>
void LinearSystem<S>::apply(const double* in, double* out) {
    products(in, out);
    for_blocks(*s_.exec, s_.n(), [&](std::size_t lo, std::size_t hi) { finish(lo, hi, in, out); });
}

template class LinearSystem<double>;
template class LinearSystem<float>;

}  // namespace edgefem::sim
