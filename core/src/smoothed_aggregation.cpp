#include "edgefem/core/smoothed_aggregation.hpp"

#include <algorithm>
#include <cmath>

#include "edgefem/core/error.hpp"
#include "edgefem/core/sparse_cholesky.hpp"

namespace edgefem {

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

// The l1 block-Jacobi smoother's inverse blocks: (A_ii + diag(sum of |a_kj|
// over the row's entries outside the block))^-1, dofs with a zero row left
// out (0 in the inverse).
std::vector<double> l1_block_inverse(const SparseRows& A, int bs) {
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
                else B[std::size_t(r * bs + r)] += std::abs(it.value());
            }
        for (int r = 0; r < bs; ++r)
            if (!live[std::size_t(r)])
                for (int c = 0; c < bs; ++c) B[std::size_t(r * bs + c)] = B[std::size_t(c * bs + r)] = r == c;
        double* out = &inv[std::size_t(i) * bb];
        invert_small(B, bs, out);
        for (int r = 0; r < bs; ++r)
            if (!live[std::size_t(r)])
                for (int c = 0; c < bs; ++c) out[r * bs + c] = out[c * bs + r] = 0;
    }
    return inv;
}

// The block-diagonal matrix of D's inverse blocks (plain block Jacobi; zero
// blocks' dofs left out).
SparseRows block_diagonal_inverse(const SparseRows& A, int bs) {
    const index_t nodes = index_t(A.rows() / bs);
    std::vector<Eigen::Triplet<double>> t;
    std::vector<double> B(static_cast<std::size_t>(bs * bs));
    for (index_t i = 0; i < nodes; ++i) {
        std::fill(B.begin(), B.end(), 0.0);
        for (int r = 0; r < bs; ++r)
            for (SparseRows::InnerIterator it(A, i * bs + r); it; ++it)
                if (it.col() / bs == i) B[std::size_t(r * bs) + std::size_t(it.col() % bs)] = it.value();
        std::vector<int> live;
        for (int r = 0; r < bs; ++r)
            if (B[std::size_t(r * bs + r)] != 0) live.push_back(r);
        const int m = int(live.size());
        std::vector<double> S(std::size_t(m * m)), Si(std::size_t(m * m));
        for (int a = 0; a < m; ++a)
            for (int b = 0; b < m; ++b) S[std::size_t(a * m + b)] = B[std::size_t(live[std::size_t(a)] * bs + live[std::size_t(b)])];
        if (m > 0) invert_small(S, m, Si.data());
        for (int a = 0; a < m; ++a)
            for (int b = 0; b < m; ++b)
                t.emplace_back(i * bs + live[std::size_t(a)], i * bs + live[std::size_t(b)], Si[std::size_t(a * m + b)]);
    }
    SparseRows D(A.rows(), A.cols());
    D.setFromTriplets(t.begin(), t.end());
    return D;
}

// The largest eigenvalue of D^-1 A by power iteration (a fixed start, so
// the hierarchy is deterministic).
double spectral_radius(const SparseRows& DinvA, int iterations) {
    const auto norm = [](const Eigen::VectorXd& v) {  // a plain loop: see invert_small
        double s = 0;
        for (Eigen::Index i = 0; i < v.size(); ++i) s += v[i] * v[i];
        return std::sqrt(s);
    };
    Eigen::VectorXd x(DinvA.rows()), y;
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = 1.0 + 0.5 * std::sin(double(i));
    double lambda = 1;
    for (int k = 0; k < iterations; ++k) {
        y = DinvA * x;
        const double nx = norm(x), ny = norm(y);
        if (!(ny > 0)) break;
        lambda = ny / nx;
        for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = y[i] / ny;
    }
    return lambda;
}

// The lower triangle of A (symmetric) with a unit diagonal on dofs whose
// row is zero (a prolongator column without a mode: a constrained or
// degenerate aggregate), for the coarsest factorisation.
LowerCsc lower_with_unit_dead(const SparseRows& A) {
    std::vector<Eigen::Triplet<double, int>> t;
    for (int i = 0; i < A.outerSize(); ++i) {
        bool dead = true;
        for (SparseRows::InnerIterator it(A, i); it; ++it) {
            dead = dead && it.value() == 0;
            if (it.col() <= i) t.emplace_back(i, int(it.col()), it.value());
        }
        if (dead) t.emplace_back(i, i, 1.0);
    }
    Eigen::SparseMatrix<double, Eigen::ColMajor, int> C(A.rows(), A.cols());  // column-major lower
    C.setFromTriplets(t.begin(), t.end());
    C.makeCompressed();
    LowerCsc out;
    out.n = index_t(A.rows());
    out.col_start.assign(C.outerIndexPtr(), C.outerIndexPtr() + C.cols() + 1);
    out.row.assign(C.innerIndexPtr(), C.innerIndexPtr() + C.nonZeros());
    out.value.assign(C.valuePtr(), C.valuePtr() + C.nonZeros());
    return out;
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
        SparseRows A;          // level >= 1: R A P of the level above
        SparseRows P_tent, P, R;  // to the next level
        Eigen::MatrixXd B;     // near-nullspace, dofs x 6
        std::vector<double> Minv;  // l1 block-Jacobi inverse blocks
        mutable Eigen::VectorXd x, b, r;  // V-cycle work
    };
    AmgSettings settings;
    std::vector<Level> level;
    SparseCholesky coarse;
    mutable Eigen::VectorXd coarse_rhs;

    void smooth(const Level& L, const double* r, double* x, bool add) const {
        const int bs = L.bs, bb = bs * bs;
        const std::size_t nodes = L.Minv.size() / std::size_t(bb);
        for (std::size_t i = 0; i < nodes; ++i) {
            const double* m = &L.Minv[i * std::size_t(bb)];
            const double* ri = r + i * std::size_t(bs);
            double* xi = x + i * std::size_t(bs);
            for (int a = 0; a < bs; ++a) {
                double s = 0;
                for (int c = 0; c < bs; ++c) s += m[a * bs + c] * ri[c];
                xi[a] = add ? xi[a] + s : s;
            }
        }
    }

    // x = V-cycle(b) on level l (x overwritten).
    void cycle(std::size_t l, const double* b, double* x, const std::function<void(const double*, double*)>& fine) const {
        const Level& L = level[l];
        const Eigen::Index n = Eigen::Index(L.Minv.size() / std::size_t(L.bs));
        if (l + 1 == level.size()) {
            coarse.solve(b, x);
            return;
        }
        const auto product = [&](const double* in, double* out) {
            if (l == 0) fine(in, out);
            else Eigen::Map<Eigen::VectorXd>(out, n) = L.A * Eigen::Map<const Eigen::VectorXd>(in, n);
        };
        L.r.resize(n);
        const auto residual = [&] {
            product(x, L.r.data());
            for (Eigen::Index i = 0; i < n; ++i) L.r[i] = b[i] - L.r[i];
        };
        smooth(L, b, x, false);
        for (int s = 1; s < settings.smoothing_steps; ++s) {
            residual();
            smooth(L, L.r.data(), x, true);
        }
        residual();
        const Level& C = level[l + 1];
        C.b = L.R * L.r;
        C.x.resize(C.b.size());
        cycle(l + 1, C.b.data(), C.x.data(), fine);
        Eigen::Map<Eigen::VectorXd>(x, n) += L.P * C.x;
        for (int s = 0; s < settings.smoothing_steps; ++s) {
            residual();
            smooth(L, L.r.data(), x, true);
        }
    }
};

SmoothedAggregation::SmoothedAggregation() : impl_(std::make_unique<Impl>()) {}
SmoothedAggregation::~SmoothedAggregation() = default;

void SmoothedAggregation::build(const SparseRows& A, const std::vector<double>& rest,
                                const std::vector<std::uint8_t>& free_dof, const AmgSettings& settings) {
    if (A.rows() != A.cols() || A.rows() % 3 != 0 || std::size_t(A.rows()) != rest.size() ||
        free_dof.size() != rest.size())
        throw InvalidArgument("SmoothedAggregation::build: A must be 3 #V square with 3 #V coordinates and free flags");
    Impl& m = *impl_;
    m.settings = settings;
    m.level.clear();
    m.level.emplace_back();
    m.level[0].bs = 3;
    m.level[0].B = rigid_body_modes(rest);
    for (std::size_t i = 0; i < free_dof.size(); ++i)
        if (!free_dof[i]) m.level[0].B.row(Eigen::Index(i)).setZero();
    SparseRows Al = A;
    while (true) {
        Impl::Level& L = m.level.back();
        const int bs = L.bs;
        if (Al.rows() <= settings.max_coarse_dofs || int(m.level.size()) >= settings.max_levels) break;
        index_t count = 0;
        // The finest level aggregates on the whole edge graph; coarser ones
        // on their strong couplings only.
        const std::vector<index_t> agg = aggregate(node_graph(Al, bs, m.level.size() == 1 ? 0.0 : 0.08), count);
        if (Eigen::Index(count) * kModes >= Al.rows()) break;  // no coarsening left
        // Tentative prolongator: per aggregate, B's rows = Q R (thin QR).
        std::vector<std::vector<index_t>> members{std::size_t(count)};
        for (std::size_t i = 0; i < agg.size(); ++i) members[std::size_t(agg[i])].push_back(index_t(i));
        std::vector<Eigen::Triplet<double>> t;
        Eigen::MatrixXd Bc = Eigen::MatrixXd::Zero(Eigen::Index(count) * kModes, kModes);
        std::vector<double> Ba, Q;
        double R[kModes * kModes];
        for (index_t a = 0; a < count; ++a) {
            const auto& mem = members[std::size_t(a)];
            const std::size_t rows = mem.size() * std::size_t(bs);
            Ba.assign(rows * kModes, 0.0);  // column-major
            for (std::size_t k = 0; k < mem.size(); ++k)
                for (int r = 0; r < bs; ++r)
                    for (int c = 0; c < kModes; ++c)
                        Ba[std::size_t(c) * rows + k * std::size_t(bs) + std::size_t(r)] =
                            L.B(Eigen::Index(mem[k]) * bs + r, c);
            thin_qr(Ba, rows, Q, R);
            for (int r = 0; r < kModes; ++r)
                for (int c = 0; c < kModes; ++c) Bc(Eigen::Index(a) * kModes + r, c) = R[r * kModes + c];
            for (std::size_t v = 0; v < mem.size(); ++v)
                for (int r = 0; r < bs; ++r) {
                    const std::size_t row = v * std::size_t(bs) + std::size_t(r);
                    const int dof = mem[v] * bs + r;
                    if (m.level.size() == 1 && !free_dof[std::size_t(dof)]) continue;
                    for (int c = 0; c < kModes; ++c)
                        if (const double q = Q[std::size_t(c) * rows + row]; q != 0) t.emplace_back(dof, a * kModes + c, q);
                }
        }
        L.P_tent.resize(Al.rows(), Eigen::Index(count) * kModes);
        L.P_tent.setFromTriplets(t.begin(), t.end());
        // Smoothed: P = (I - 4 / (3 rho) D^-1 A) P_tent.
        const SparseRows Dinv = block_diagonal_inverse(Al, bs);
        const SparseRows DinvA = Dinv * Al;
        const double rho = spectral_radius(DinvA, settings.power_iterations);
        L.P = L.P_tent - (4.0 / (3.0 * rho)) * SparseRows(DinvA * L.P_tent);
        L.P.prune(0.0);
        L.R = L.P.transpose();
        SparseRows Ac = L.R * Al * L.P;
        m.level.emplace_back();
        m.level.back().bs = kModes;
        m.level.back().B = Bc;
        Al = std::move(Ac);
    }
    refresh(A);
}

void SmoothedAggregation::refresh(const SparseRows& A) {
    Impl& m = *impl_;
    if (m.level.empty()) throw InvalidArgument("SmoothedAggregation::refresh: build() first");
    const SparseRows* Al = &A;
    for (std::size_t l = 0; l < m.level.size(); ++l) {
        Impl::Level& L = m.level[l];
        if (l > 0) {
            L.A = m.level[l - 1].R * (*Al * m.level[l - 1].P);
            Al = &L.A;
        }
        if (l + 1 < m.level.size()) {
            L.Minv = l1_block_inverse(*Al, L.bs);
        } else {
            L.Minv.assign(std::size_t(Al->rows()) * std::size_t(L.bs), 0.0);  // sizes only
            if (!m.coarse.factor(lower_with_unit_dead(*Al)))
                throw Error("AMG: the coarsest level's factorisation failed (a zero pivot)");
        }
    }
}

void SmoothedAggregation::apply(const double* r, double* z, const std::function<void(const double*, double*)>& fine) const {
    impl_->cycle(0, r, z, fine);
}

int SmoothedAggregation::levels() const { return int(impl_->level.size()); }
index_t SmoothedAggregation::dofs(int l) const { return index_t(impl_->level[std::size_t(l)].B.rows()); }
const SparseRows& SmoothedAggregation::tentative(int l) const { return impl_->level[std::size_t(l)].P_tent; }
const SparseRows& SmoothedAggregation::prolongator(int l) const { return impl_->level[std::size_t(l)].P; }
const Eigen::MatrixXd& SmoothedAggregation::near_nullspace(int l) const { return impl_->level[std::size_t(l)].B; }
const SparseRows& SmoothedAggregation::matrix(int l) const { return impl_->level[std::size_t(l)].A; }

std::size_t SmoothedAggregation::bytes() const {
    const auto sp = [](const SparseRows& M) {
        return std::size_t(M.nonZeros()) * (sizeof(double) + sizeof(int)) + std::size_t(M.outerSize() + 1) * sizeof(int);
    };
    std::size_t b = 0;
    for (const auto& L : impl_->level)
        b += sp(L.A) + sp(L.P) + sp(L.R) + L.Minv.size() * sizeof(double) + 3 * std::size_t(L.B.rows()) * sizeof(double);
    b += std::size_t(impl_->coarse.factor_nonzeros() * sizeof(double));
    return b;
}

}  // namespace edgefem
