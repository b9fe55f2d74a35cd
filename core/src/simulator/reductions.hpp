// Reductions over the dofs on the executor, the same for any thread count:
// several blocked sums at once, and Newton's underflow-safe norms and dot
// products.
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include "edgefem/core/executor.hpp"

namespace edgefem::sim {

// K sums at once: block(lo, hi) gives a block's K partials, which are added
// in block order, as blocked_sum: the same for any thread count.
template <std::size_t K, class Block>
std::array<double, K> blocked_sums(const Executor& ex, std::size_t n, Block&& block) {
    std::vector<std::array<double, K>> partial(vector_blocks(n));
    for_blocks(ex, n, [&](std::size_t lo, std::size_t hi) { partial[lo / kVectorBlock] = block(lo, hi); });
    std::array<double, K> s{};
    for (const auto& p : partial)
        for (std::size_t k = 0; k < K; ++k) s[k] += p[k];
    return s;
}

// Sums of squares and products for Newton without underflow: a damped
// body's motion decays to 1e-160 m and below, whose squares leave the double
// range (a zero slope, a zero norm, a Newton iteration of noise). Each
// vector is scaled by a power of two near its largest entry first (exact);
// the result is mant x 2^exp. A non-finite entry makes it non-finite.
struct Scaled {
    double mant = 0;
    int exp = 0;
    double value() const { return std::ldexp(mant, exp); }
};

// The exponent of the largest |term(i)|; `bad` gets the last non-finite
// one in index order. Per block on the executor (a maximum is exact in any
// order), so that Newton has no serial pass over the dofs.
template <class Term>
int max_exponent(const Executor& ex, std::size_t n, Term&& term, double& bad) {
    std::vector<std::array<double, 2>> part(vector_blocks(n), {0.0, 0.0});  // {max, last non-finite}
    for_blocks(ex, n, [&](std::size_t lo, std::size_t hi) {
        double mx = 0, b = 0;
        for (std::size_t i = lo; i < hi; ++i) {
            const double t = std::abs(term(i));
            if (!std::isfinite(t)) b = t;
            mx = std::max(mx, t);
        }
        part[lo / kVectorBlock] = {mx, b};
    });
    double mx = 0;
    for (const auto& p : part) {
        if (p[1] != 0) bad = p[1];
        mx = std::max(mx, p[0]);
    }
    return mx > 0 ? std::ilogb(mx) : 0;
}

template <class A, class B>
Scaled scaled_dot(const Executor& ex, std::size_t n, A&& a, B&& b) {
    double bad = 0;
    const int ea = max_exponent(ex, n, a, bad), eb = max_exponent(ex, n, b, bad);
    if (bad != 0) return {bad, 0};
    return {blocked_sum(ex, n, [&](std::size_t i) { return std::ldexp(a(i), -ea) * std::ldexp(b(i), -eb); }), ea + eb};
}

template <class Term>
double scaled_norm(const Executor& ex, std::size_t n, Term&& term) {
    const Scaled s = scaled_dot(ex, n, term, term);
    return std::isfinite(s.mant) ? std::ldexp(std::sqrt(s.mant), s.exp / 2) : s.mant;
}

}  // namespace edgefem::sim
