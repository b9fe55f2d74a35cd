#include "amg/galerkin_product.hpp"

#include <algorithm>
#include <string>

#include "edgefem/core/error.hpp"

namespace edgefem::amg {

namespace {

// The blocks of A's block row I (their block columns), unsorted, each once.
template <class F>
void block_columns(const SparseRows& A, std::size_t I, int b, std::vector<int>& seen, F&& each) {
    for (int r = 0; r < b; ++r)
        for (SparseRows::InnerIterator it(A, Eigen::Index(I) * b + r); it; ++it) {
            const int J = int(it.col() / b);
            if (seen[std::size_t(J)] != int(I)) {
                seen[std::size_t(J)] = int(I);
                each(J);
            }
        }
}

// Whether the rb rows of A's block row I hold the same columns, in runs of
// rb that are whole blocks (columns J rb .. J rb + rb - 1).
template <int rb>
bool whole_blocks(const int* outer, const int* inner, std::size_t I) {
    const int r0 = outer[I * rb], len = outer[I * rb + 1] - r0;
    if (len % rb != 0) return false;
    for (int r = 1; r < rb; ++r)
        if (outer[I * rb + std::size_t(r) + 1] - outer[I * rb + std::size_t(r)] != len ||
            !std::equal(inner + r0, inner + r0 + len, inner + outer[I * rb + std::size_t(r)]))
            return false;
    for (int m = 0; m < len; m += rb)
        for (int j = 0; j < rb; ++j)
            if (inner[r0 + m + j] != (inner[r0 + m] / rb) * rb + j) return false;
    return true;
}

// What multiply_blocks reads and writes of a GalerkinProduct.
struct Work {
    const std::vector<int>& start;  // the result's block pattern
    const std::vector<int>& col;
    std::vector<int>& slot;
    std::vector<int>& cols;
    std::vector<double>& scratch;
    const int* outer;  // the result's scalar rows
    double* val;
};

// The blocks on and above the diagonal of P^T A P, added row by row of A;
// RB x CB blocks of P. False when a block falls outside the pattern.
template <int RB, int CB>
bool multiply_blocks(const SparseRows& A, const BlockRowsView& P, const Work& o) {
    constexpr int rb = RB, cb = CB;
    constexpr std::size_t w = std::size_t(rb) * std::size_t(cb);
    const bool compressed = A.isCompressed();  // outer[i + 1] ends row i
    const int* outer = A.outerIndexPtr();
    const int* inner = A.innerIndexPtr();
    const double* value = A.valuePtr();
    // The scratch block of coarse block c in the current row of A P (zeroed
    // when c first appears in the row).
    const auto block_of = [&](int c) {
        if (o.slot[std::size_t(c)] < 0) {
            o.slot[std::size_t(c)] = int(o.cols.size());
            o.cols.push_back(c);
            if (o.scratch.size() < o.cols.size() * w) o.scratch.resize(o.cols.size() * w);
            std::fill_n(o.scratch.begin() + std::ptrdiff_t((o.cols.size() - 1) * w), w, 0.0);
        }
        return o.scratch.data() + std::size_t(o.slot[std::size_t(c)]) * w;
    };
    for (std::size_t I = 0; I < P.block_rows; ++I) {
        // Row I of A P: rb x cb per coarse block, summed over A's entries.
        o.cols.clear();
        if (compressed && whole_blocks<rb>(outer, inner, I)) {
            // A's rb rows hold the same whole rb x rb blocks (the assembled
            // fine level and every Galerkin operator): per block, one
            // look-up per block of P's row and rb x rb x cb multiply-adds
            const int r0 = outer[I * rb], len = outer[I * rb + 1] - r0;
            for (int m = 0; m < len; m += rb) {
                const std::size_t J = std::size_t(inner[r0 + m] / rb);
                double a[rb][rb];
                for (int r = 0; r < rb; ++r)
                    for (int j = 0; j < rb; ++j) a[r][j] = value[outer[I * rb + std::size_t(r)] + m + j];
                for (int k = P.start[J]; k < P.start[J + 1]; ++k) {
                    double* s = block_of(P.col[k]);
                    const float* p = P.val + std::size_t(k) * w;
                    for (int r = 0; r < rb; ++r)
                        for (int j = 0; j < rb; ++j) {
                            const double v = a[r][j];
                            for (int y = 0; y < cb; ++y) s[r * cb + y] += v * double(p[j * cb + y]);
                        }
                }
            }
        } else {
            for (int r = 0; r < rb; ++r)
                for (SparseRows::InnerIterator it(A, Eigen::Index(I) * rb + r); it; ++it) {
                    const std::size_t J = std::size_t(it.col() / rb);
                    const int j = int(it.col() % rb);
                    const double v = it.value();
                    for (int k = P.start[J]; k < P.start[J + 1]; ++k) {
                        double* s = block_of(P.col[k]) + std::size_t(r) * std::size_t(cb);
                        const float* p = P.val + std::size_t(k) * w + std::size_t(j) * std::size_t(cb);
                        for (int y = 0; y < cb; ++y) s[y] += v * double(p[y]);
                    }
                }
        }
        // P's blocks of row I, transposed, times it, into the blocks on and
        // above the diagonal.
        bool covered = true;
        for (int kp = P.start[I]; kp < P.start[I + 1] && covered; ++kp) {
            const std::size_t a = std::size_t(P.col[kp]);
            const float* pa = P.val + std::size_t(kp) * w;  // pa[r cb + x] = P(I rb + r, a cb + x)
            double pt[w];                                   // P's block transposed, in double
            for (int r = 0; r < rb; ++r)
                for (int x = 0; x < cb; ++x) pt[x * rb + r] = double(pa[r * cb + x]);
            const int* first = o.col.data() + o.start[a];
            const int* last = o.col.data() + o.start[a + 1];
            for (std::size_t t = 0; t < o.cols.size(); ++t) {
                if (std::size_t(o.cols[t]) < a) continue;
                const int* pos = std::lower_bound(first, last, o.cols[t]);
                if (pos == last || *pos != o.cols[t]) {
                    covered = false;
                    break;
                }
                const std::size_t k = std::size_t(pos - first);
                const double* s = o.scratch.data() + t * w;
                // the block P_Ia^T (A P)_It in registers (no aliasing with
                // the result: vectorised), then added
                double block[cb * cb] = {};
                for (int x = 0; x < cb; ++x)
                    for (int r = 0; r < rb; ++r) {
                        const double pr = pt[x * rb + r];
                        for (int y = 0; y < cb; ++y) block[x * cb + y] += pr * s[r * cb + y];
                    }
                for (int x = 0; x < cb; ++x) {
                    double* out = o.val + o.outer[a * std::size_t(cb) + std::size_t(x)] + k * std::size_t(cb);
                    for (int y = 0; y < cb; ++y) out[y] += block[x * cb + y];
                }
            }
        }
        for (const int c : o.cols) o.slot[std::size_t(c)] = -1;
        if (!covered) return false;
    }
    return true;
}

}  // namespace

void GalerkinProduct::find_pattern(const SparseRows& A, const BlockRowsView& P, std::size_t coarse_blocks) {
    std::vector<std::vector<int>> rows(coarse_blocks);
    std::vector<int> seen(P.block_rows, -1), mark(coarse_blocks, -1), ap;
    for (std::size_t I = 0; I < P.block_rows; ++I) {
        ap.clear();
        block_columns(A, I, P.rb, seen, [&](int J) {
            for (int k = P.start[J]; k < P.start[J + 1]; ++k)
                if (const int c = P.col[k]; mark[std::size_t(c)] != int(I)) {
                    mark[std::size_t(c)] = int(I);
                    ap.push_back(c);
                }
        });
        for (int k = P.start[I]; k < P.start[I + 1]; ++k) {
            std::vector<int>& row = rows[std::size_t(P.col[k])];
            row.insert(row.end(), ap.begin(), ap.end());
        }
    }
    // Symmetric (P^T A P is, for a symmetric A): only the blocks on and
    // above the diagonal are formed, the others mirrored from them.
    for (std::size_t a = 0; a < coarse_blocks; ++a)
        for (std::size_t k = 0, n = rows[a].size(); k < n; ++k)
            if (const int c = rows[a][k]; std::size_t(c) != a) rows[std::size_t(c)].push_back(int(a));
    start_.assign(coarse_blocks + 1, 0);
    col_.clear();
    for (std::size_t a = 0; a < coarse_blocks; ++a) {
        std::vector<int>& row = rows[a];
        std::sort(row.begin(), row.end());
        row.erase(std::unique(row.begin(), row.end()), row.end());
        col_.insert(col_.end(), row.begin(), row.end());
        start_[a + 1] = int(col_.size());
        std::vector<int>().swap(row);
    }
    slot_.assign(coarse_blocks, -1);
}

bool GalerkinProduct::multiply(const SparseRows& A, const BlockRowsView& P, SparseRows& out) {
    const int cb = P.cb;
    const std::size_t nbc = start_.size() - 1;
    // The result's scalar pattern: block row a's scalar rows each hold its
    // blocks' cb columns in block order.
    out.resize(Eigen::Index(nbc) * cb, Eigen::Index(nbc) * cb);
    out.resizeNonZeros(Eigen::Index(col_.size()) * cb * cb);
    int* outer = out.outerIndexPtr();
    int* inner = out.innerIndexPtr();
    double* val = out.valuePtr();
    outer[0] = 0;
    for (std::size_t a = 0; a < nbc; ++a)
        for (int x = 0; x < cb; ++x) {
            const std::size_t row = a * std::size_t(cb) + std::size_t(x);
            int at = outer[row];
            for (int k = start_[a]; k < start_[a + 1]; ++k)
                for (int y = 0; y < cb; ++y) inner[at++] = col_[std::size_t(k)] * cb + y;
            outer[row + 1] = at;
        }
    std::fill(val, val + out.nonZeros(), 0.0);
    const Work work{start_, col_, slot_, cols_, scratch_, outer, val};
    bool covered;
    if (P.rb == 3 && P.cb == 6)
        covered = multiply_blocks<3, 6>(A, P, work);
    else if (P.rb == 6 && P.cb == 6)
        covered = multiply_blocks<6, 6>(A, P, work);
    else
        throw InvalidArgument("GalerkinProduct: prolongator blocks of " + std::to_string(P.rb) + " x " +
                              std::to_string(P.cb) + ", expected 3 x 6 or 6 x 6");
    if (!covered) return false;
    // The blocks below the diagonal: the transposes of those above.
    for (std::size_t a = 0; a < nbc; ++a)
        for (int k = start_[a]; k < start_[a + 1]; ++k) {
            const std::size_t b = std::size_t(col_[std::size_t(k)]);
            if (b <= a) continue;
            const int* first = col_.data() + start_[b];
            const int* last = col_.data() + start_[b + 1];
            const std::size_t kb = std::size_t(std::lower_bound(first, last, int(a)) - first);
            const std::size_t ka = std::size_t(k - start_[a]);
            for (int x = 0; x < cb; ++x)
                for (int y = 0; y < cb; ++y)
                    val[outer[b * std::size_t(cb) + std::size_t(y)] + kb * std::size_t(cb) + std::size_t(x)] =
                        val[outer[a * std::size_t(cb) + std::size_t(x)] + ka * std::size_t(cb) + std::size_t(y)];
        }
    return true;
}

void GalerkinProduct::operator()(const SparseRows& A, const BlockRowsView& P, std::size_t coarse_blocks, SparseRows& out) {
    if (A.rows() != A.cols() || A.rows() != Eigen::Index(P.block_rows) * P.rb)
        throw InvalidArgument("GalerkinProduct: A is " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                              ", P has " + std::to_string(Eigen::Index(P.block_rows) * P.rb) + " rows");
    if (start_.size() != coarse_blocks + 1) find_pattern(A, P, coarse_blocks);
    if (multiply(A, P, out)) return;
    find_pattern(A, P, coarse_blocks);  // A brought entries the pattern did not cover
    if (!multiply(A, P, out)) throw Error("GalerkinProduct: the pattern found does not cover A P");
}

std::size_t GalerkinProduct::bytes() const {
    return (start_.size() + col_.size() + slot_.size() + cols_.size()) * sizeof(int) + scratch_.size() * sizeof(double);
}

}  // namespace edgefem::amg
