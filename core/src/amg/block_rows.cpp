// The V-cycle's block products (block_rows.hpp has the order they keep).
// Compiled with -ffp-contract=off (core/CMakeLists.txt): a multiply-add
// fused in a gather and not in its scatter twin would break the bitwise
// equality of the serial and threaded V-cycles. The restriction's parts are
// 6-wide vectors (one per block row), the prolongation's pairs of scalar
// products: each block's part is independent of the running sum, so the
// loops are bound by throughput, not by one chain of dependent adds (the
// order before, one fused multiply-add per term into the running sum,
// took 29 and 19 us for bunny-4k's restriction and prolongation serially,
// and std::fma was a libm call in builds without -mfma).
#include "amg/block_rows.hpp"

#include <algorithm>
#include <cstring>

#include "edgefem/core/error.hpp"

namespace edgefem::amg {

namespace {

constexpr int kMaxBlock = 6;  // the largest block side (6 modes)

// Six doubles as a 4- and a 2-wide vector (GCC's vector extensions: AVX or
// SSE2 code, whatever the build targets).
typedef double D4 __attribute__((vector_size(32)));
typedef double D2 __attribute__((vector_size(16)));
typedef float F4 __attribute__((vector_size(16)));
typedef float F2 __attribute__((vector_size(8)));
struct Six {
    D4 lo;
    D2 hi;
};
inline Six load_float(const float* v) {
    F4 a;
    F2 b;
    std::memcpy(&a, v, sizeof a);
    std::memcpy(&b, v + 4, sizeof b);
    return {__builtin_convertvector(a, D4), __builtin_convertvector(b, D2)};
}
inline Six operator*(const Six& a, double s) { return {a.lo * s, a.hi * s}; }
inline Six operator+(const Six& a, const Six& b) { return {a.lo + b.lo, a.hi + b.hi}; }
inline void add_to(double* y, const Six& a) {
    D4 lo;
    D2 hi;
    std::memcpy(&lo, y, sizeof lo);
    std::memcpy(&hi, y + 4, sizeof hi);
    lo += a.lo;
    hi += a.hi;
    std::memcpy(y, &lo, sizeof lo);
    std::memcpy(y + 4, &hi, sizeof hi);
}
inline void store(double* y, const Six& a) {
    std::memcpy(y, &a.lo, sizeof a.lo);
    std::memcpy(y + 4, &a.hi, sizeof a.hi);
}

// v[0] x[0] + v[s] x[1] + ... + v[(n - 1) s] x[n - 1], the products summed
// in pairs: ((p0 + p1) + (p2 + p3)) + ...
inline double pair_dot(const float* v, std::size_t s, const double* x, std::size_t n) {
    const auto p = [&](std::size_t k) { return double(v[k * s]) * x[k]; };
    double sum = n > 1 ? p(0) + p(1) : p(0);
    for (std::size_t m = 2; m < n; m += 2) sum += m + 1 < n ? p(m) + p(m + 1) : p(m);
    return sum;
}

// u = x^T V for an rb x cb block V (u has cb entries): each u_j a pair_dot
// down column j.
template <int B, int C>
inline void restriction_part(const float* v, const double* x, std::size_t rb, std::size_t cb, double* u) {
    const std::size_t b = B ? std::size_t(B) : rb, c = C ? std::size_t(C) : cb;
    for (std::size_t j = 0; j < c; ++j) u[j] = pair_dot(v + j, c, x, b);
}
// The same, six wide (cb = 6), in the same pairs.
template <int B>
inline Six restriction_six(const float* v, const double* x) {
    Six s = B > 1 ? load_float(v) * x[0] + load_float(v + 6) * x[1] : load_float(v) * x[0];
    for (int m = 2; m < B; m += 2)
        s = s + (m + 1 < B ? load_float(v + 6 * m) * x[m] + load_float(v + 6 * (m + 1)) * x[m + 1]
                           : load_float(v + 6 * m) * x[m]);
    return s;
}
// t_i += (V x)_i for an rb x cb block V: a pair_dot along row i.
template <int B, int C>
inline void prolongation_part(const float* v, const double* x, std::size_t rb, std::size_t cb, double* t) {
    const std::size_t b = B ? std::size_t(B) : rb, c = C ? std::size_t(C) : cb;
    for (std::size_t i = 0; i < b; ++i) t[i] += pair_dot(v + i * c, 1, x, c);
}

// Calls f(B, C) with the block sizes as compile-time constants where they
// are the usual 3 and 6 (the loops then unroll), as 0 (read rb and cb at
// run time) otherwise. The same arithmetic either way.
template <class F>
void with_sizes(const BlockRows& M, const F& f) {
    using Three = std::integral_constant<int, 3>;
    using Six = std::integral_constant<int, 6>;
    using Any = std::integral_constant<int, 0>;
    if (M.rb > kMaxBlock || M.cb > kMaxBlock) throw Error("AMG: a block larger than 6 x 6");
    if (M.rb == 6 && M.cb == 6) return f(Six{}, Six{});
    if (M.rb == 3 && M.cb == 6) return f(Three{}, Six{});
    if (M.rb == 6 && M.cb == 3) return f(Six{}, Three{});
    if (M.rb == 3 && M.cb == 3) return f(Three{}, Three{});
    f(Any{}, Any{});
}

// Rows [r0, r1) of y = M x (Add: y + M x), M grouped by rows.
template <int B, int C, bool Add>
void gather_rows(const BlockRows& M, const double* x, double* y, std::size_t r0, std::size_t r1) {
    const std::size_t b = B ? std::size_t(B) : std::size_t(M.rb), c = C ? std::size_t(C) : std::size_t(M.cb);
    double s[kMaxBlock];
    for (std::size_t I = r0 / b; I < r1 / b; ++I) {
        if (Add) std::copy(y + I * b, y + I * b + b, s);
        else std::fill(s, s + b, 0.0);
        for (int k = M.start[I]; k < M.start[I + 1]; ++k)
            prolongation_part<B, C>(&M.val[std::size_t(k) * b * c], x + std::size_t(M.col[std::size_t(k)]) * c, b, c, s);
        std::copy(s, s + b, y + I * b);
    }
}

}  // namespace

void BlockRows::assign(const SparseRows& M, int row_block, int col_block) {
    rows = M.rows();
    cols = M.cols();
    rb = row_block;
    cb = col_block;
    by_columns = false;
    if (rows % rb != 0 || cols % cb != 0) throw Error("AMG: a matrix is not made of whole blocks");
    const std::size_t nbr = std::size_t(rows / rb), w = std::size_t(rb) * std::size_t(cb);
    start.assign(nbr + 1, 0);
    col.clear();
    val.clear();
    std::vector<int> slot(std::size_t(cols / cb), -1);  // block column -> its block in the current row, -1 none
    std::vector<int> here;
    for (std::size_t I = 0; I < nbr; ++I) {
        here.clear();
        for (int i = 0; i < rb; ++i)
            for (SparseRows::InnerIterator it(M, Eigen::Index(I) * rb + i); it; ++it) {
                const std::size_t J = std::size_t(it.col() / cb);
                if (it.value() != 0 && slot[J] == -1) {
                    slot[J] = 0;
                    here.push_back(int(J));
                }
            }
        std::sort(here.begin(), here.end());
        for (const int J : here) {
            slot[std::size_t(J)] = int(col.size());
            col.push_back(J);
        }
        val.resize(col.size() * w, 0.0f);
        for (int i = 0; i < rb; ++i)
            for (SparseRows::InnerIterator it(M, Eigen::Index(I) * rb + i); it; ++it)
                if (it.value() != 0) {
                    const std::size_t k = std::size_t(slot[std::size_t(it.col() / cb)]);
                    val[(k * std::size_t(rb) + std::size_t(i)) * std::size_t(cb) + std::size_t(it.col() % cb)] =
                        float(it.value());
                }
        for (const int J : here) slot[std::size_t(J)] = -1;
        start[I + 1] = int(col.size());
    }
}

BlockRows BlockRows::regrouped() const {
    BlockRows t;
    t.rows = rows;
    t.cols = cols;
    t.rb = rb;
    t.cb = cb;
    t.by_columns = !by_columns;
    const std::size_t groups = by_columns ? std::size_t(rows / rb) : std::size_t(cols / cb),
                      w = std::size_t(rb) * std::size_t(cb);
    t.start.assign(groups + 1, 0);
    for (const int g : col) ++t.start[std::size_t(g) + 1];
    for (std::size_t g = 0; g < groups; ++g) t.start[g + 1] += t.start[g];
    t.col.resize(col.size());
    t.val.resize(val.size());
    std::vector<int> next(t.start.begin(), t.start.end() - 1);
    for (std::size_t G = 0; G + 1 < start.size(); ++G)
        for (int k = start[G]; k < start[G + 1]; ++k) {
            const std::size_t at = std::size_t(next[std::size_t(col[std::size_t(k)])]++);
            t.col[at] = int(G);
            std::copy_n(val.begin() + std::ptrdiff_t(std::size_t(k) * w), w, t.val.begin() + std::ptrdiff_t(at * w));
        }
    return t;
}

SparseRows BlockRows::expand() const {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(val.size());
    for (std::size_t G = 0; G + 1 < start.size(); ++G)
        for (int k = start[G]; k < start[G + 1]; ++k) {
            const int I = by_columns ? col[std::size_t(k)] : int(G), J = by_columns ? int(G) : col[std::size_t(k)];
            for (int i = 0; i < rb; ++i)
                for (int j = 0; j < cb; ++j) {
                    const float v = val[(std::size_t(k) * std::size_t(rb) + std::size_t(i)) * std::size_t(cb) + std::size_t(j)];
                    if (v != 0) t.emplace_back(I * rb + i, J * cb + j, double(v));
                }
        }
    SparseRows M(rows, cols);
    M.setFromTriplets(t.begin(), t.end());
    return M;
}

void BlockRows::drop_zero_blocks() {
    const std::size_t w = std::size_t(rb) * std::size_t(cb);
    std::size_t kept = 0;
    int first = 0;
    for (std::size_t G = 0; G + 1 < start.size(); ++G) {
        const int last = start[G + 1];
        for (int k = first; k < last; ++k) {
            const float* v = &val[std::size_t(k) * w];
            if (std::all_of(v, v + w, [](float x) { return x == 0; })) continue;
            col[kept] = col[std::size_t(k)];
            std::copy(v, v + w, val.begin() + std::ptrdiff_t(kept * w));
            ++kept;
        }
        first = last;
        start[G + 1] = int(kept);
    }
    col.resize(kept);
    val.resize(kept * w);
    col.shrink_to_fit();
    val.shrink_to_fit();
}

void BlockRows::times(const double* x, double* y, std::size_t r0, std::size_t r1) const {
    if (by_columns) throw Error("AMG: BlockRows::times on a matrix grouped by columns");
    with_sizes(*this, [&](auto B, auto C) { gather_rows<B(), C(), false>(*this, x, y, r0, r1); });
}

void restrict_scatter(const BlockRows& P, const double* fine, double* coarse) {
    if (P.by_columns) throw Error("AMG: restrict_scatter needs P grouped by rows");
    std::fill(coarse, coarse + P.cols, 0.0);
    with_sizes(P, [&](auto B, auto C) {
        const std::size_t b = B ? std::size_t(B()) : std::size_t(P.rb), c = C ? std::size_t(C()) : std::size_t(P.cb);
        for (std::size_t I = 0; I + 1 < P.start.size(); ++I) {
            const double* x = fine + I * b;
            for (int k = P.start[I]; k < P.start[I + 1]; ++k) {
                const float* v = &P.val[std::size_t(k) * b * c];
                double* y = coarse + std::size_t(P.col[std::size_t(k)]) * c;
                if constexpr (C() == 6 && B() > 0) {
                    add_to(y, restriction_six<B()>(v, x));
                } else {
                    double u[kMaxBlock];
                    restriction_part<B(), C()>(v, x, b, c, u);
                    for (std::size_t j = 0; j < c; ++j) y[j] += u[j];
                }
            }
        }
    });
}

void restrict_gather(const BlockRows& P, const double* fine, double* coarse, std::size_t r0, std::size_t r1) {
    if (!P.by_columns) throw Error("AMG: restrict_gather needs P grouped by columns");
    with_sizes(P, [&](auto B, auto C) {
        const std::size_t b = B ? std::size_t(B()) : std::size_t(P.rb), c = C ? std::size_t(C()) : std::size_t(P.cb);
        for (std::size_t J = r0 / c; J < r1 / c; ++J) {
            double* y = coarse + J * c;
            if constexpr (C() == 6 && B() > 0) {
                Six s{};
                for (int k = P.start[J]; k < P.start[J + 1]; ++k)
                    s = s + restriction_six<B()>(&P.val[std::size_t(k) * b * c], fine + std::size_t(P.col[std::size_t(k)]) * b);
                store(y, s);
            } else {
                std::fill(y, y + c, 0.0);
                double u[kMaxBlock];
                for (int k = P.start[J]; k < P.start[J + 1]; ++k) {
                    restriction_part<B(), C()>(&P.val[std::size_t(k) * b * c], fine + std::size_t(P.col[std::size_t(k)]) * b,
                                               b, c, u);
                    for (std::size_t j = 0; j < c; ++j) y[j] += u[j];
                }
            }
        }
    });
}

void prolong_gather(const BlockRows& P, const double* coarse, double* fine, std::size_t r0, std::size_t r1) {
    if (P.by_columns) throw Error("AMG: prolong_gather needs P grouped by rows");
    with_sizes(P, [&](auto B, auto C) { gather_rows<B(), C(), true>(P, coarse, fine, r0, r1); });
}

void prolong_scatter(const BlockRows& P, const double* coarse, double* fine) {
    if (!P.by_columns) throw Error("AMG: prolong_scatter needs P grouped by columns");
    with_sizes(P, [&](auto B, auto C) {
        const std::size_t b = B ? std::size_t(B()) : std::size_t(P.rb), c = C ? std::size_t(C()) : std::size_t(P.cb);
        for (std::size_t J = 0; J + 1 < P.start.size(); ++J) {
            const double* x = coarse + J * c;
            for (int k = P.start[J]; k < P.start[J + 1]; ++k)
                prolongation_part<B(), C()>(&P.val[std::size_t(k) * b * c], x, b, c,
                                            fine + std::size_t(P.col[std::size_t(k)]) * b);
        }
    });
}

}  // namespace edgefem::amg
