#include "edgefem/core/smoothed_aggregation.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/core/executor.hpp"
#include "amg/block_rows.hpp"
#include "amg/coarse_ldlt.hpp"
#include "amg/galerkin_product.hpp"

namespace edgefem {

using amg::BlockRows;

namespace {

constexpr int kModes = 6;

// The inverse of the n x n row-major matrix a (Gauss-Jordan, partial
// pivoting), written to inv. Small blocks only (3x3, 6x6); plain loops:
// Eigen's dense kernels trip g++ 12's false -Wmaybe-uninitialized with
// AVX-512 (GCC PR 105593).
void invert_small(std::vector<double> a, int n, double* inv) {
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) inv[i * n + j] = i == j;
    for (int c = 0; c < n; ++c) {
        int piv = c;
        for (int r = c + 1; r < n; ++r)
            if (std::abs(a[std::size_t(r * n + c)]) > std::abs(a[std::size_t(piv * n + c)])) piv = r;
        if (piv != c)
            for (int j = 0; j < n; ++j) {
                std::swap(a[std::size_t(c * n + j)], a[std::size_t(piv * n + j)]);
                std::swap(inv[c * n + j], inv[piv * n + j]);
            }
        const double d = a[std::size_t(c * n + c)];
        if (d == 0) throw Error("AMG: a singular diagonal block");
        for (int j = 0; j < n; ++j) {
            a[std::size_t(c * n + j)] /= d;
            inv[c * n + j] /= d;
        }
        for (int r = 0; r < n; ++r) {
            if (r == c) continue;
            const double f = a[std::size_t(r * n + c)];
            if (f == 0) continue;
            for (int j = 0; j < n; ++j) {
                a[std::size_t(r * n + j)] -= f * a[std::size_t(c * n + j)];
                inv[r * n + j] -= f * inv[c * n + j];
            }
        }
    }
}

// Thin QR of the rows x 6 matrix B (column-major) by modified Gram-Schmidt
// with one re-orthogonalisation: B = Q R, Q rows x 6 with orthonormal
// columns where B's column adds a direction (zero columns where it does
// not: R's row is then zero), R upper triangular 6 x 6 (row-major).
void thin_qr(const std::vector<double>& B, std::size_t rows, std::vector<double>& Q, double* R) {
    Q = B;
    std::fill(R, R + kModes * kModes, 0.0);
    double scale = 0;
    for (double b : B) scale = std::max(scale, std::abs(b));
    for (int j = 0; j < kModes; ++j) {
        double* qj = &Q[std::size_t(j) * rows];
        for (int pass = 0; pass < 2; ++pass)
            for (int k = 0; k < j; ++k) {
                const double* qk = &Q[std::size_t(k) * rows];
                double d = 0;
                for (std::size_t i = 0; i < rows; ++i) d += qk[i] * qj[i];
                for (std::size_t i = 0; i < rows; ++i) qj[i] -= d * qk[i];
                R[k * kModes + j] += d;
            }
        double nrm = 0;
        for (std::size_t i = 0; i < rows; ++i) nrm += qj[i] * qj[i];
        nrm = std::sqrt(nrm);
        if (nrm <= 1e-10 * scale * std::sqrt(double(rows))) {  // dependent (or zero): no new direction
            for (std::size_t i = 0; i < rows; ++i) qj[i] = 0;
            continue;
        }
        R[j * kModes + j] = nrm;
        for (std::size_t i = 0; i < rows; ++i) qj[i] /= nrm;
    }
}

// The block graph of A (nodes of `bs` dofs): the nodes j != i with a
// stored entry in node i's rows and, when theta > 0, a strong coupling:
// |A_ij|_F^2 > theta^2 |A_ii|_F |A_jj|_F (the coarse levels' Galerkin
// operators couple every pair of nearby aggregates, mostly weakly).
std::vector<std::vector<index_t>> node_graph(const SparseRows& A, int bs, double theta) {
    const index_t nodes = index_t(A.rows() / bs);
    std::vector<double> diag(std::size_t(nodes), 0.0);
    for (index_t i = 0; i < nodes; ++i)
        for (int r = 0; r < bs; ++r)
            for (SparseRows::InnerIterator it(A, i * bs + r); it; ++it)
                if (it.col() / bs == i) diag[std::size_t(i)] += it.value() * it.value();
    std::vector<std::vector<index_t>> adj{std::size_t(nodes)};
    std::vector<double> w(std::size_t(nodes), 0.0);
    for (index_t i = 0; i < nodes; ++i) {
        auto& a = adj[std::size_t(i)];
        for (int r = 0; r < bs; ++r)
            for (SparseRows::InnerIterator it(A, i * bs + r); it; ++it) {
                const index_t j = index_t(it.col() / bs);
                if (j == i) continue;
                if (w[std::size_t(j)] == 0) a.push_back(j);
                w[std::size_t(j)] += it.value() * it.value() + 1e-300;
            }
        std::sort(a.begin(), a.end());
        std::size_t kept = 0;
        for (index_t j : a) {
            const double dd = std::sqrt(diag[std::size_t(i)]) * std::sqrt(diag[std::size_t(j)]);
            if (theta == 0 || w[std::size_t(j)] > theta * theta * dd) a[kept++] = j;
            w[std::size_t(j)] = 0;
        }
        a.resize(kept);
    }
    return adj;
}

// Greedy aggregation: a node whose neighbours are all free starts an
// aggregate with them; each node left joins a neighbour's aggregate (or
// starts its own when it has none). Returns the aggregate of each node.
std::vector<index_t> aggregate(const std::vector<std::vector<index_t>>& adj, index_t& count) {
    const std::size_t n = adj.size();
    std::vector<index_t> agg(n, -1);
    count = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (agg[i] >= 0) continue;
        bool all_free = true;
        for (index_t j : adj[i]) all_free = all_free && agg[std::size_t(j)] < 0;
        if (!all_free) continue;
        agg[i] = count;
        for (index_t j : adj[i]) agg[std::size_t(j)] = count;
        ++count;
    }
    const std::vector<index_t> first = agg;
    for (std::size_t i = 0; i < n; ++i) {
        if (agg[i] >= 0) continue;
        for (index_t j : adj[i])
            if (first[std::size_t(j)] >= 0) {
                agg[i] = first[std::size_t(j)];
                break;
            }
        if (agg[i] < 0) agg[i] = count++;
    }
    return agg;
}

// The smoothers' inverse diagonal blocks, row-major bs x bs each: A_ii^-1,
// or with l1 the l1 block-Jacobi's (A_ii + diag(sum of |a_kj| over the
// row's entries outside the block))^-1; dofs with a zero row left out (0 in
// the inverse).
std::vector<double> block_inverse(const SparseRows& A, int bs, bool l1) {
    const index_t nodes = index_t(A.rows() / bs);
    const std::size_t bb = std::size_t(bs * bs);
    std::vector<double> inv(std::size_t(nodes) * bb, 0.0), B(bb);
    for (index_t i = 0; i < nodes; ++i) {
        std::fill(B.begin(), B.end(), 0.0);
        std::vector<bool> live(std::size_t(bs), false);
        for (int r = 0; r < bs; ++r)
            for (SparseRows::InnerIterator it(A, i * bs + r); it; ++it) {
                if (it.value() != 0) live[std::size_t(r)] = true;
                if (it.col() / bs == i) B[std::size_t(r * bs) + std::size_t(it.col() % bs)] += it.value();
                else if (l1) B[std::size_t(r * bs + r)] += std::abs(it.value());
            }
        for (int r = 0; r < bs; ++r)
            if (!live[std::size_t(r)])
                for (int c = 0; c < bs; ++c) B[std::size_t(r * bs + c)] = B[std::size_t(c * bs + r)] = r == c;
        double* out = &inv[std::size_t(i) * bb];
        invert_small(B, bs, out);
        for (int r = 0; r < bs; ++r)  // exactly symmetric, as the V-cycle must be
            for (int c = r + 1; c < bs; ++c) out[r * bs + c] = out[c * bs + r] = 0.5 * (out[r * bs + c] + out[c * bs + r]);
        for (int r = 0; r < bs; ++r)
            if (!live[std::size_t(r)])
                for (int c = 0; c < bs; ++c) out[r * bs + c] = out[c * bs + r] = 0;
    }
    return inv;
}

// y = f D^-1 v + keep y, D^-1 given by its bs x bs inverse blocks (keep 0:
// y overwritten).
// Nodes [first, last) only (block_apply_range), or all of them.
template <int BS>
void block_apply_sized(const std::vector<double>& Dinv, int bs_runtime, const double* v, double* y, double f,
                       double keep, std::size_t first, std::size_t last) {
    const std::size_t bs = BS ? std::size_t(BS) : std::size_t(bs_runtime), bb = bs * bs;
    for (std::size_t i = first; i < last; ++i) {
        const double* m = &Dinv[i * bb];
        const double* vi = v + i * bs;
        double* yi = y + i * bs;
        for (std::size_t a = 0; a < bs; ++a) {
            double s = 0;
            for (std::size_t c = 0; c < bs; ++c) s += m[a * bs + c] * vi[c];
            yi[a] = keep == 0 ? f * s : keep * yi[a] + f * s;
        }
    }
}
// (3- and 6-dof nodes with compile-time sizes, so that the loops unroll)
void block_apply_range(const std::vector<double>& Dinv, int bs, const double* v, double* y, double f, double keep,
                       std::size_t first, std::size_t last) {
    if (bs == 3) return block_apply_sized<3>(Dinv, bs, v, y, f, keep, first, last);
    if (bs == 6) return block_apply_sized<6>(Dinv, bs, v, y, f, keep, first, last);
    block_apply_sized<0>(Dinv, bs, v, y, f, keep, first, last);
}
void block_apply(const std::vector<double>& Dinv, int bs, const double* v, double* y, double f, double keep) {
    block_apply_range(Dinv, bs, v, y, f, keep, 0, Dinv.size() / std::size_t(bs * bs));
}

// The largest eigenvalue of D^-1 A, D^-1 given by its inverse blocks, by
// power iteration from a fixed start (deterministic).
double largest_eigenvalue(const SparseRows& A, const std::vector<double>& Dinv, int bs, int iterations) {
    const Eigen::Index n = A.rows();
    Eigen::VectorXd x(n), Ax(n), y(n);
    for (Eigen::Index i = 0; i < n; ++i) x[i] = 1.0 + 0.5 * std::sin(double(i));
    double lambda = 1;
    for (int k = 0; k < iterations; ++k) {
        Ax = A * x;
        block_apply(Dinv, bs, Ax.data(), y.data(), 1.0, 0.0);
        double nx = 0, ny = 0;  // plain loops: see invert_small
        for (Eigen::Index i = 0; i < n; ++i) {
            nx += x[i] * x[i];
            ny += y[i] * y[i];
        }
        if (!(ny > 0)) break;
        lambda = std::sqrt(ny / nx);
        const double s = 1 / std::sqrt(ny);
        for (Eigen::Index i = 0; i < n; ++i) x[i] = y[i] * s;
    }
    return lambda;
}




// The nodes of each aggregate, in increasing order (agg: each node's
// aggregate, count of them): nodes [start[a], start[a + 1]) of `node`.
struct Members {
    std::vector<index_t> start, node;
    Members(const std::vector<index_t>& agg, index_t count) : start(std::size_t(count) + 1, 0), node(agg.size()) {
        for (const index_t a : agg) ++start[std::size_t(a) + 1];
        for (std::size_t a = 0; a < std::size_t(count); ++a) start[a + 1] += start[a];
        std::vector<index_t> next(start.begin(), start.end() - 1);
        for (std::size_t i = 0; i < agg.size(); ++i) node[std::size_t(next[std::size_t(agg[i])]++)] = index_t(i);
    }
    index_t count() const { return index_t(start.size() - 1); }
};

// The tentative prolongator of near-nullspace B (bs-dof nodes) on the
// aggregates: per aggregate, its nodes' rows of B = Q R (thin QR); Q
// written per node (Qn: bs x 6 row-major per node, the node's block of
// P_tent, zero on dofs that are not free where `free` is given), R as the
// aggregate's 6 rows of the coarse near-nullspace Bc.
void tentative_blocks(const Eigen::MatrixXd& B, int bs, const Members& members, const std::uint8_t* free,
                      std::vector<double>& Qn, Eigen::MatrixXd& Bc) {
    const std::size_t w = std::size_t(bs) * kModes;
    Qn.assign(members.node.size() * w, 0.0);
    Bc = Eigen::MatrixXd::Zero(Eigen::Index(members.count()) * kModes, kModes);
    std::vector<double> Ba, Q;
    double R[kModes * kModes];
    for (index_t a = 0; a < members.count(); ++a) {
        const index_t* mem = &members.node[std::size_t(members.start[std::size_t(a)])];
        const std::size_t size = std::size_t(members.start[std::size_t(a) + 1] - members.start[std::size_t(a)]);
        const std::size_t rows = size * std::size_t(bs);
        Ba.assign(rows * kModes, 0.0);  // column-major
        for (std::size_t k = 0; k < size; ++k)
            for (int r = 0; r < bs; ++r)
                for (int c = 0; c < kModes; ++c)
                    Ba[std::size_t(c) * rows + k * std::size_t(bs) + std::size_t(r)] = B(Eigen::Index(mem[k]) * bs + r, c);
        thin_qr(Ba, rows, Q, R);
        for (int r = 0; r < kModes; ++r)
            for (int c = 0; c < kModes; ++c) Bc(Eigen::Index(a) * kModes + r, c) = R[r * kModes + c];
        for (std::size_t v = 0; v < size; ++v)
            for (int r = 0; r < bs; ++r) {
                const std::size_t dof = std::size_t(mem[v]) * std::size_t(bs) + std::size_t(r);
                if (free && !free[dof]) continue;
                for (int c = 0; c < kModes; ++c) Qn[dof * kModes + std::size_t(c)] = Q[std::size_t(c) * rows + v * std::size_t(bs) + std::size_t(r)];
            }
    }
}

// A's sparsity pattern (its rows' column indices), hashed (FNV-1a).
std::uint64_t pattern_hash(const SparseRows& A) {
    std::uint64_t h = 1469598103934665603ull;
    const auto mix = [&](std::uint64_t v) { h = (h ^ v) * 1099511628211ull; };
    mix(std::uint64_t(A.rows()));
    mix(std::uint64_t(A.cols()));
    for (Eigen::Index i = 0; i < A.outerSize(); ++i) {
        for (SparseRows::InnerIterator it(A, i); it; ++it) mix(std::uint64_t(it.col()));
        mix(~std::uint64_t(0));
    }
    return h;
}

// The block pattern of P = (I - f D^-1 A) P_tent (values zero): block row
// I (node I of bs dofs) has a block in the column of each aggregate that I
// or a node A couples it to belongs to (agg: each node's aggregate, count
// of them).
BlockRows prolongator_pattern(const SparseRows& A, int bs, const std::vector<index_t>& agg, index_t count) {
    BlockRows P;
    P.rows = A.rows();
    P.cols = Eigen::Index(count) * kModes;
    P.rb = bs;
    P.cb = kModes;
    const std::size_t nodes = agg.size();
    P.start.assign(nodes + 1, 0);
    std::vector<char> seen(std::size_t(count), 0);
    std::vector<int> here;
    for (std::size_t I = 0; I < nodes; ++I) {
        here.assign(1, int(agg[I]));
        seen[std::size_t(agg[I])] = 1;
        for (int r = 0; r < bs; ++r)
            for (SparseRows::InnerIterator it(A, Eigen::Index(I) * bs + r); it; ++it) {
                const std::size_t a = std::size_t(agg[std::size_t(it.col() / bs)]);
                if (!seen[a]) {
                    seen[a] = 1;
                    here.push_back(int(a));
                }
            }
        std::sort(here.begin(), here.end());
        for (const int a : here) seen[std::size_t(a)] = 0;
        P.col.insert(P.col.end(), here.begin(), here.end());
        P.start[I + 1] = int(P.col.size());
    }
    P.val.assign(P.col.size() * std::size_t(bs) * kModes, 0.0f);
    return P;
}

// P_tent as a sparse matrix, from its node blocks Qn (tentative_blocks).
SparseRows tentative_matrix(const std::vector<double>& Qn, const std::vector<index_t>& agg, int bs, index_t count) {
    std::vector<Eigen::Triplet<double>> t;
    const std::size_t dofs = agg.size() * std::size_t(bs);
    for (std::size_t dof = 0; dof < dofs; ++dof)
        for (int c = 0; c < kModes; ++c)
            if (const double q = Qn[dof * kModes + std::size_t(c)]; q != 0)
                t.emplace_back(int(dof), agg[dof / std::size_t(bs)] * kModes + c, q);
    SparseRows P(Eigen::Index(dofs), Eigen::Index(count) * kModes);
    P.setFromTriplets(t.begin(), t.end());
    return P;
}

// P = (I - f D^-1 A) P_tent, numerically into P's block pattern (BS x 6
// blocks, prolongator_pattern's, kept after build(); no product that
// allocates): P_tent's block of
// node J is Qn's (tentative_blocks), in column agg[J]; D^-1 by its inverse
// blocks. Block row I's A P_tent is summed per aggregate in a scratch row,
// then D_I^-1 times it subtracted from P_tent's block. False where a
// nonzero block falls outside the pattern (build() found it zero).
template <int BS>
bool smooth_into(const SparseRows& A, const std::vector<double>& Dinv, const std::vector<double>& Qn,
                 const std::vector<index_t>& agg, double f, BlockRows& P) {
    constexpr std::size_t bs = BS, w = std::size_t(BS) * kModes;
    std::vector<int> slot(std::size_t(P.cols / kModes), -1), cols;
    std::vector<double> s;
    double block[w];
    const auto open = [&](std::size_t a) {
        if (slot[a] >= 0) return;
        slot[a] = int(cols.size());
        cols.push_back(int(a));
        if (s.size() < cols.size() * w) s.resize(cols.size() * w);
        std::fill_n(s.begin() + std::ptrdiff_t((cols.size() - 1) * w), w, 0.0);
    };
    for (std::size_t I = 0; I + 1 < P.start.size(); ++I) {
        cols.clear();
        open(std::size_t(agg[I]));
        for (std::size_t r = 0; r < bs; ++r)
            for (SparseRows::InnerIterator it(A, Eigen::Index(I * bs + r)); it; ++it) {
                const std::size_t J = std::size_t(it.col()) / bs, j = std::size_t(it.col()) % bs;
                const std::size_t a = std::size_t(agg[J]);
                open(a);
                double* sa = &s[std::size_t(slot[a]) * w + r * kModes];
                const double* q = &Qn[(J * bs + j) * kModes];
                const double v = it.value();
                for (int c = 0; c < kModes; ++c) sa[c] += v * q[c];
            }
        const double* d = &Dinv[I * bs * bs];
        const double* qi = &Qn[I * w];
        const int* first = P.col.data() + P.start[I];
        const int* last = P.col.data() + P.start[I + 1];
        std::fill(P.val.begin() + std::ptrdiff_t(std::size_t(P.start[I]) * w),
                  P.val.begin() + std::ptrdiff_t(std::size_t(P.start[I + 1]) * w), 0.0f);
        bool covered = true;
        for (std::size_t t = 0; t < cols.size(); ++t) {
            const double* st = &s[t * w];
            const bool own = cols[t] == agg[I];
            bool zero = true;
            for (std::size_t r = 0; r < bs; ++r)
                for (int c = 0; c < kModes; ++c) {
                    double ds = 0;
                    for (std::size_t k = 0; k < bs; ++k) ds += d[r * bs + k] * st[k * kModes + std::size_t(c)];
                    const double v = (own ? qi[r * kModes + std::size_t(c)] : 0.0) - f * ds;
                    block[r * kModes + std::size_t(c)] = v;
                    zero = zero && v == 0;
                }
            const int* pos = std::lower_bound(first, last, cols[t]);
            if (pos != last && *pos == cols[t]) {
                float* out = &P.val[std::size_t(pos - P.col.data()) * w];
                for (std::size_t e = 0; e < w; ++e) out[e] = float(block[e]);
            } else if (!zero) {
                covered = false;
            }
        }
        for (const int a : cols) slot[std::size_t(a)] = -1;
        if (!covered) return false;
    }
    return true;
}

}  // namespace

Eigen::MatrixXd rigid_body_modes(const std::vector<double>& p) {
    const std::size_t nv = p.size() / 3;
    double c[3] = {0, 0, 0};
    for (std::size_t v = 0; v < nv; ++v)
        for (int k = 0; k < 3; ++k) c[k] += p[3 * v + std::size_t(k)] / double(std::max<std::size_t>(nv, 1));
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(Eigen::Index(3 * nv), kModes);
    for (std::size_t v = 0; v < nv; ++v) {
        const double x = p[3 * v] - c[0], y = p[3 * v + 1] - c[1], z = p[3 * v + 2] - c[2];
        const Eigen::Index r = Eigen::Index(3 * v);
        for (int k = 0; k < 3; ++k) B(r + k, k) = 1;
        // rotations: omega x (x, y, z) for omega = e_x, e_y, e_z
        B(r + 1, 3) = -z;
        B(r + 2, 3) = y;
        B(r + 0, 4) = z;
        B(r + 2, 4) = -x;
        B(r + 0, 5) = -y;
        B(r + 1, 5) = x;
    }
    return B;
}

struct SmoothedAggregation::Impl {
    struct Level {
        int bs = 3;
        BlockRows A;           // level >= 1 and not the coarsest: R A P of the level above
        // The prolongator to the next level, grouped by rows with a serial
        // executor, by columns with a threaded one (the restriction then a
        // gather over coarse rows in parallel, the prolongation a scatter;
        // bitwise the serial products: amg/block_rows.hpp).
        BlockRows P;
        SparseRows P_tent;     // before smoothing (build only; release_build_data() frees it)
        Eigen::MatrixXd B;     // near-nullspace, dofs x 6
        std::vector<index_t> agg;  // not the coarsest: each node's aggregate (its block column of P; rebuild())
        std::vector<double> Minv;  // the smoother's inverse blocks (D^-1, or l1 block-Jacobi's)
        double lambda = 1;     // Chebyshev: the largest eigenvalue of D^-1 A
        amg::GalerkinProduct galerkin;  // level >= 1: forms its operator from the level above's at each refresh
        mutable Eigen::VectorXd x, b, r, d, t;  // V-cycle work
    };
    AmgSettings settings;
    double fine_entries = 0;  // the finest matrix's entries on and above the diagonal
    std::vector<Level> level;
    amg::CoarseLdlt coarse;
    std::vector<std::uint8_t> free;  // build()'s free dofs and its A's pattern (hashed), for rebuild()
    std::uint64_t pattern = 0;
    std::shared_ptr<const Executor> ex;  // null or one thread: serial

    bool threaded() const { return ex && ex->threads() > 1; }
    // Level L's prolongator grouped by rows: P, or P regrouped in `scratch`.
    static const BlockRows& prolongator(const Level& L, BlockRows& scratch) {
        return L.P.by_columns ? (scratch = L.P.regrouped()) : L.P;
    }
    // Groups level L's prolongator the way the executor uses it.
    void hold(Level& L) const {
        if (L.P.rows > 0 && L.P.by_columns != threaded()) L.P = L.P.regrouped();
    }
    // body(begin, end) over [0, n) in the fixed blocks of for_blocks (their
    // ends are multiples of 384: whole 3- and 6-dof nodes), on the executor.
    template <class Body>
    void par(Eigen::Index n, const Body& body) const {
        for_blocks_if_threaded(ex.get(), std::size_t(n), body);
    }
    void blocks(const Level& L, const double* v, double* y, double f, double keep) const {
        const std::size_t bs = std::size_t(L.bs);
        par(Eigen::Index(L.Minv.size() / bs), [&](std::size_t b, std::size_t e) {
            block_apply_range(L.Minv, L.bs, v, y, f, keep, b / bs, e / bs);
        });
    }

    // L.r = b - A x.
    template <class Product>
    void residual(const Level& L, const double* b, const double* x, const Product& product) const {
        double* r = L.r.data();
        product(x, r);
        par(L.r.size(), [&](std::size_t i0, std::size_t i1) {
            for (std::size_t i = i0; i < i1; ++i) r[i] = b[i] - r[i];
        });
    }

    // x += S (b - A x), S the smoother (zero: x = S b without a product):
    // l1 block-Jacobi sweeps, or the Chebyshev iteration (Saad, Iterative
    // Methods, Alg. 12.1) preconditioned by D^-1 on [beta / ratio, beta]:
    // x += p(D^-1 A) D^-1 (b - A x), S = p(D^-1 A) D^-1 symmetric. Products
    // with A and axpys only, each entry by itself: bitwise the same on any
    // executor.
    template <class Product>
    void smooth(const Level& L, const double* b, double* x, bool zero, const Product& product) const {
        const Eigen::Index n = Eigen::Index(L.Minv.size() / std::size_t(L.bs));
        const int steps = settings.smoothing_steps;
        L.r.resize(n);
        double* r = L.r.data();
        if (settings.smoother == AmgSmoother::L1Jacobi) {
            for (int s = 0; s < steps; ++s) {
                if (s == 0 && zero) {
                    blocks(L, b, x, 1.0, 0.0);
                    continue;
                }
                residual(L, b, x, product);
                blocks(L, r, x, 1.0, 1.0);
            }
            return;
        }
        const double beta = 1.1 * L.lambda, alpha = beta / settings.chebyshev_ratio;
        const double theta = (beta + alpha) / 2, delta = (beta - alpha) / 2, sigma = theta / delta;
        double rho = 1 / sigma;
        if (zero) {
            par(n, [&](std::size_t i0, std::size_t i1) {
                std::fill(x + i0, x + i1, 0.0);
                std::copy(b + i0, b + i1, r + i0);
            });
        } else {
            residual(L, b, x, product);
        }
        L.d.resize(n);
        L.t.resize(n);
        double *d = L.d.data(), *t = L.t.data();
        blocks(L, r, d, 1 / theta, 0.0);
        for (int k = 1;; ++k) {
            par(n, [&](std::size_t i0, std::size_t i1) {
                for (std::size_t i = i0; i < i1; ++i) x[i] += d[i];
            });
            if (k == steps) break;
            product(d, t);
            par(n, [&](std::size_t i0, std::size_t i1) {
                for (std::size_t i = i0; i < i1; ++i) r[i] -= t[i];
            });
            const double rho_next = 1 / (2 * sigma - rho);
            blocks(L, r, d, 2 * rho_next / delta, rho_next * rho);
            rho = rho_next;
        }
    }

    // build() (`grow`), rebuild() (positions) and refresh(), level by level
    // on its operator Al (the caller's A, then the Galerkin operator of the
    // prolongator just made):
    //  - grow: Al's aggregates and P's block pattern (grow_level), or Al is
    //    the coarsest;
    //  - the smoother's D^-1 and (Chebyshev) the largest eigenvalue of
    //    D^-1 Al;
    //  - with positions, the prolongator: the near-nullspace's QR per
    //    aggregate (the coarse level's near-nullspace) and P's values into
    //    its pattern (smooth_into), smoothed with the same D^-1 and
    //    eigenvalue; grow then drops P's zero blocks.
    // False where a prolongator's value falls outside its pattern (then
    // nothing is consistent: build again).
    bool update(const SparseRows& A, const std::vector<double>* positions, bool grow = false) {
        const SparseRows* Al = &A;
        SparseRows Acur, Anext;  // the Galerkin operator of level l, in double while the next is formed
        Eigen::MatrixXd B, Bc;   // build and rebuild: the near-nullspace of level l, of level l + 1
        std::vector<double> Qn, Dinv;
        if (positions) {
            B = rigid_body_modes(*positions);
            for (std::size_t i = 0; i < free.size(); ++i)
                if (!free[i]) B.row(Eigen::Index(i)).setZero();
        }
        for (std::size_t l = 0; l < level.size(); ++l) {
            if (l > 0) {
                BlockRows scratch;
                const BlockRows& P = prolongator(level[l - 1], scratch);
                const amg::BlockRowsView view{P.start.size() - 1, P.rb, P.cb, P.start.data(), P.col.data(), P.val.data()};
                level[l].galerkin(*Al, view, std::size_t(P.cols / P.cb), Anext);
                Acur.swap(Anext);
                Al = &Acur;
            }
            if (grow) grow_level(l, *Al);
            Level& L = level[l];
            if (grow) L.B = B;  // build()'s, for the accessors (release_build_data() frees them)
            if (l + 1 == level.size()) {
                L.Minv.assign(std::size_t(Al->rows()) * std::size_t(L.bs), 0.0);  // sizes only
                if (!coarse.factor(*Al)) throw Error("AMG: the coarsest level's factorisation failed (a zero pivot)");
                break;
            }
            if (l > 0) L.A.assign(*Al, L.bs, L.bs);
            const bool cheb = settings.smoother == AmgSmoother::Chebyshev;
            L.Minv = block_inverse(*Al, L.bs, !cheb);
            if (cheb) L.lambda = largest_eigenvalue(*Al, L.Minv, L.bs, settings.power_iterations);
            if (!positions) continue;
            if (!cheb) Dinv = block_inverse(*Al, L.bs, false);
            const std::vector<double>& D = cheb ? L.Minv : Dinv;
            const double rho = cheb ? L.lambda : largest_eigenvalue(*Al, D, L.bs, settings.power_iterations);
            BlockRows P = L.P.by_columns ? L.P.regrouped() : std::move(L.P);
            const index_t count = index_t(P.cols / kModes);
            tentative_blocks(B, L.bs, Members(L.agg, count), l == 0 ? free.data() : nullptr, Qn, Bc);
            const double f = settings.prolongator_weight / rho;  // w / rho (w = 4/3 by default)
            const bool covered = L.bs == 3 ? smooth_into<3>(*Al, D, Qn, L.agg, f, P) : smooth_into<6>(*Al, D, Qn, L.agg, f, P);
            if (grow) {
                P.drop_zero_blocks();
                L.P_tent = tentative_matrix(Qn, L.agg, L.bs, count);
            }
            L.P = std::move(P);
            hold(L);
            if (!covered) return false;
            B.swap(Bc);
        }
        return true;
    }

    // build(): level l's aggregates, on the strong couplings of its operator
    // Al (the finest level's on the whole edge graph), and its prolongator's
    // block pattern, and a level l + 1 of 6-mode nodes after it; nothing
    // where l is to be the coarsest (Al small enough, the levels or the
    // density at their limits, or no coarsening left).
    void grow_level(std::size_t l, const SparseRows& Al) {
        const int bs = level[l].bs;
        if (Al.rows() <= settings.max_coarse_dofs || int(level.size()) >= settings.max_levels) return;
        if (l > 0 && settings.dense_coarsest > 0 &&
            double(Al.nonZeros()) >= settings.dense_coarsest * double(Al.rows()) * double(Al.rows()))
            return;
        index_t count = 0;
        std::vector<index_t> agg = aggregate(node_graph(Al, bs, l == 0 ? 0.0 : settings.strength), count);
        if (Eigen::Index(count) * kModes >= Al.rows()) return;
        level[l].P = prolongator_pattern(Al, bs, agg, count);
        level[l].agg = std::move(agg);
        level.emplace_back();
        level.back().bs = kModes;
    }

    // out = A_l in: the caller's product on the finest level.
    auto product(std::size_t l, const std::function<void(const double*, double*)>& fine) const {
        return [this, l, &fine](const double* in, double* out) {
            const Level& L = level[l];
            if (l == 0) return fine(in, out);
            par(L.A.rows, [&](std::size_t i0, std::size_t i1) { L.A.times(in, out, i0, i1); });
        };
    }

    // x = V-cycle(b) on level l (x overwritten).
    void cycle(std::size_t l, const double* b, double* x, const std::function<void(const double*, double*)>& fine) const {
        const Level& L = level[l];
        if (l + 1 == level.size()) {
            coarse.solve(b, x);
            return;
        }
        const auto product = this->product(l, fine);
        smooth(L, b, x, true, product);
        residual(L, b, x, product);
        const double* r = L.r.data();
        const Level& C = level[l + 1];
        const bool gather = L.P.by_columns;  // threaded (build(), set_executor())
        C.b.resize(L.P.cols);
        if (gather)
            par(L.P.cols, [&](std::size_t i0, std::size_t i1) { amg::restrict_gather(L.P, r, C.b.data(), i0, i1); });
        else
            amg::restrict_scatter(L.P, r, C.b.data());
        C.x.resize(C.b.size());
        cycle(l + 1, C.b.data(), C.x.data(), fine);
        if (gather)
            amg::prolong_scatter(L.P, C.x.data(), x);
        else
            amg::prolong_gather(L.P, C.x.data(), x, 0, std::size_t(L.P.rows));
        smooth(L, b, x, false, product);
    }
};

SmoothedAggregation::SmoothedAggregation() : impl_(std::make_unique<Impl>()) {}
SmoothedAggregation::~SmoothedAggregation() = default;

void SmoothedAggregation::build(const SparseRows& A, const std::vector<double>& positions,
                                const std::vector<std::uint8_t>& free_dof, const AmgSettings& settings) {
    if (A.rows() != A.cols() || A.rows() % 3 != 0 || std::size_t(A.rows()) != positions.size() ||
        free_dof.size() != positions.size())
        throw InvalidArgument("SmoothedAggregation::build: A must be 3 #V square with 3 #V coordinates and free flags");
    if (settings.max_coarse_dofs < 1 || settings.max_levels < 1 || settings.smoothing_steps < 1 ||
        settings.power_iterations < 1 || !(settings.chebyshev_ratio > 1) || !(settings.prolongator_weight >= 0) ||
        !(settings.strength >= 0) || !(settings.dense_coarsest >= 0 && settings.dense_coarsest <= 1))
        throw InvalidArgument("AmgSettings: max_coarse_dofs, max_levels, smoothing_steps and power_iterations must be "
                              ">= 1, chebyshev_ratio > 1, prolongator_weight and strength >= 0, dense_coarsest in [0, 1]");
    Impl& m = *impl_;
    m.settings = settings;
    m.fine_entries = 0.5 * (double(A.nonZeros()) + 3.0 * double(A.rows()));  // the 3x3 diagonal blocks counted once
    m.free = free_dof;
    m.pattern = pattern_hash(A);
    m.level.clear();
    m.level.emplace_back();
    m.level[0].bs = 3;
    if (!m.update(A, &positions, true))
        throw Error("AMG: a prolongator's value outside the pattern build() found for it");  // cannot happen
}

void SmoothedAggregation::refresh(const SparseRows& A) {
    if (impl_->level.empty()) throw InvalidArgument("SmoothedAggregation::refresh: build() first");
    impl_->update(A, nullptr);
}

bool SmoothedAggregation::rebuild(const SparseRows& A, const std::vector<double>& positions) {
    Impl& m = *impl_;
    if (m.level.empty()) throw InvalidArgument("SmoothedAggregation::rebuild: build() first");
    if (positions.size() != m.free.size())
        throw InvalidArgument("SmoothedAggregation::rebuild: positions has " + std::to_string(positions.size()) +
                              " coordinates, build() had " + std::to_string(m.free.size()));
    if (A.rows() != A.cols() || std::size_t(A.rows()) != m.free.size() || pattern_hash(A) != m.pattern)
        throw InvalidArgument("SmoothedAggregation::rebuild: A's pattern (" + std::to_string(A.rows()) + " x " +
                              std::to_string(A.cols()) + ", " + std::to_string(A.nonZeros()) +
                              " entries) is not the one build() saw");
    for (auto& L : m.level) {  // build()'s; not those of the positions now
        L.P_tent = SparseRows();
        L.B = Eigen::MatrixXd();
    }
    if (m.update(A, &positions)) return true;
    const std::vector<std::uint8_t> free = m.free;
    build(A, positions, free, m.settings);
    return false;
}

void SmoothedAggregation::set_executor(std::shared_ptr<const Executor> ex) {
    impl_->ex = std::move(ex);
    for (auto& L : impl_->level)
        impl_->hold(L);
}

void SmoothedAggregation::apply(const double* r, double* z, const std::function<void(const double*, double*)>& fine) const {
    impl_->cycle(0, r, z, fine);
}

void SmoothedAggregation::smooth(int l, const double* b, double* x,
                                 const std::function<void(const double*, double*)>& fine) const {
    const Impl& m = *impl_;
    if (l < 0 || std::size_t(l) + 1 >= m.level.size())
        throw InvalidArgument("SmoothedAggregation::smooth: level " + std::to_string(l) + " has no smoother");
    m.smooth(m.level[std::size_t(l)], b, x, false, m.product(std::size_t(l), fine));
}

int SmoothedAggregation::levels() const { return int(impl_->level.size()); }
bool SmoothedAggregation::coarsest_indefinite() const { return impl_->coarse.indefinite(); }
index_t SmoothedAggregation::dofs(int l) const {
    const auto& L = impl_->level[std::size_t(l)];
    return index_t(L.Minv.size() / std::size_t(L.bs));
}
const SparseRows& SmoothedAggregation::tentative(int l) const { return impl_->level[std::size_t(l)].P_tent; }
SparseRows SmoothedAggregation::prolongator(int l) const {
    BlockRows scratch;
    return Impl::prolongator(impl_->level[std::size_t(l)], scratch).expand();
}
const Eigen::MatrixXd& SmoothedAggregation::near_nullspace(int l) const { return impl_->level[std::size_t(l)].B; }
SparseRows SmoothedAggregation::matrix(int l) const { return impl_->level[std::size_t(l)].A.expand(); }

void SmoothedAggregation::release_build_data() {
    for (auto& L : impl_->level) {
        L.P_tent = SparseRows();
        L.B = Eigen::MatrixXd();
    }
}

double SmoothedAggregation::cycle_cost() const {
    const Impl& m = *impl_;
    if (m.level.empty() || m.fine_entries <= 0) return 0;
    const double products = 2.0 * m.settings.smoothing_steps;
    const auto entries = [](const BlockRows& M) { return double(M.col.size()) * M.rb * M.cb; };
    double coarse = 0;
    for (std::size_t l = 0; l + 1 < m.level.size(); ++l) {
        const Impl::Level& L = m.level[l];
        if (l > 0) coarse += products * entries(L.A);
        coarse += 2 * entries(L.P);  // restriction and prolongation
    }
    const double nc = double(dofs(levels() - 1));
    coarse += nc * nc;  // the two triangular solves with the dense factor
    return products + coarse / m.fine_entries;
}

std::size_t SmoothedAggregation::bytes() const {
    const auto sp = [](const SparseRows& M) {
        return std::size_t(M.nonZeros()) * (sizeof(double) + sizeof(int)) + std::size_t(M.outerSize() + 1) * sizeof(int);
    };
    const auto vec = [](const Eigen::VectorXd& v) { return std::size_t(v.size()) * sizeof(double); };
    std::size_t b = 0;
    for (const auto& L : impl_->level)
        b += L.A.bytes() + L.P.bytes() + sp(L.P_tent) + std::size_t(L.B.size()) * sizeof(double) +
             L.Minv.size() * sizeof(double) + vec(L.x) + vec(L.b) + vec(L.r) + vec(L.d) + vec(L.t) + L.galerkin.bytes() +
             L.agg.size() * sizeof(index_t);
    b += impl_->coarse.bytes() + impl_->free.size();
    return b;
}

}  // namespace edgefem
