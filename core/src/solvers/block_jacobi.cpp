// Block-Jacobi: the inverse of each vertex's 3x3 diagonal block of A; a
// block that is not positive definite falls back to its mass part so the
// preconditioner stays SPD.
#include <algorithm>
#include <cmath>
#include <vector>

#include "solvers/preconditioner.hpp"

namespace edgefem::sim {

namespace {

// Inverse of the symmetric part of B (row-major into inv) by Cholesky;
// false when it is not positive definite. Written out for 3x3: Eigen's LLT
// solve against the identity went through its general triangular solver
// and made the block-Jacobi set-up ~5% of a semi-implicit step.
bool spd_inverse3(const double (&B)[3][3], double* inv) {
    const double a00 = B[0][0], a11 = B[1][1], a22 = B[2][2];
    const double a10 = 0.5 * (B[1][0] + B[0][1]), a20 = 0.5 * (B[2][0] + B[0][2]), a21 = 0.5 * (B[2][1] + B[1][2]);
    if (!(a00 > 0)) return false;
    const double l00 = std::sqrt(a00), l10 = a10 / l00, l20 = a20 / l00;
    const double d11 = a11 - l10 * l10;
    if (!(d11 > 0)) return false;
    const double l11 = std::sqrt(d11), l21 = (a21 - l20 * l10) / l11;
    const double d22 = a22 - l20 * l20 - l21 * l21;
    if (!(d22 > 0)) return false;
    const double l22 = std::sqrt(d22);
    // M = L^-1 (lower triangular), inv = M^T M.
    const double m00 = 1 / l00, m11 = 1 / l11, m22 = 1 / l22;
    const double m10 = -l10 * m00 * m11, m21 = -l21 * m11 * m22, m20 = -(l20 * m00 + l21 * m10) * m22;
    inv[0] = m00 * m00 + m10 * m10 + m20 * m20;
    inv[1] = inv[3] = m10 * m11 + m20 * m21;
    inv[2] = inv[6] = m20 * m22;
    inv[4] = m11 * m11 + m21 * m21;
    inv[5] = inv[7] = m21 * m22;
    inv[8] = m22 * m22;
    return true;
}

template <class S>
class BlockJacobi final : public Preconditioner<S> {
public:
    explicit BlockJacobi(const SimState<S>& state)
        : s_(state), mass_(state.mass), D_(9 * state.mass.size()),
          Dinv_(9 * state.mass.size() + 1) {}  // + 1: the last 4-lane row read (apply)

    void setup(const LinearSystem<S>& A) override {
        A.K().diagonal_blocks(D_.data());
        if (A.c_b() != 0) {
            D0_.resize(D_.size());
            A.K0()->diagonal_blocks(D0_.data());
        }
        build(A.c_m(), A.c_k(), A.c_b());
    }

    void apply(std::size_t lo, std::size_t hi, const double* r_in, double* z_out) const override {
        const double* __restrict r = r_in;
        double* __restrict z = z_out;
        const double* __restrict Minv = Dinv_.data();
        // z = Dinv r per vertex as rows times broadcasts in 4-lane
        // vectors: Dinv is exactly symmetric (spd_inverse3), so its
        // rows are its columns; lane 3 reads the next value (Dinv
        // has one spare at the end) and is never stored.
        typedef double V4 __attribute__((vector_size(32)));
        for (std::size_t vtx = lo / 3; vtx < hi / 3; ++vtx) {
            const double* M = &Minv[9 * vtx];
            const double* rv = &r[3 * vtx];
            V4 m0, m1, m2;
            __builtin_memcpy(&m0, M, sizeof m0);
            __builtin_memcpy(&m1, M + 3, sizeof m1);
            __builtin_memcpy(&m2, M + 6, sizeof m2);
            const V4 zv = rv[0] * m0 + rv[1] * m1 + rv[2] * m2;
            for (int i = 0; i < 3; ++i) z[3 * vtx + i] = zv[i];
        }
    }

private:
    // Dinv per vertex from B = c_k D + c_b D0 + c_m m I.
    void build(double c_m, double c_k, double c_b) {
        s_.each_vertex([&](std::size_t vtx) {
            double B[3][3];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    B[i][j] = c_k * double(D_[9 * vtx + 3 * i + j]) + (c_b != 0 ? c_b * double(D0_[9 * vtx + 3 * i + j]) : 0.0) +
                              (i == j ? c_m * mass_[vtx] : 0.0);
            double* inv = &Dinv_[9 * vtx];
            if (!spd_inverse3(B, inv)) {
                const double d = std::max({c_m * mass_[vtx], B[0][0], B[1][1], B[2][2], 1e-300});
                for (int i = 0; i < 9; ++i) inv[i] = (i % 4 == 0) ? 1 / d : 0.0;
            }
        });
    }

    const SimState<S>& s_;
    // #V. A copy: read through a reference to the state's vector, g++ 12
    // fused a different product of one of B's sums into an FMA, which
    // changed the preconditioner's last bits.
    std::vector<double> mass_;
    std::vector<S> D_, D0_;      // diagonal blocks of K and K0 (9 #V)
    std::vector<double> Dinv_;   // their inverses (9 #V + 1)
};

}  // namespace

template <class S>
std::unique_ptr<Preconditioner<S>> make_block_jacobi(const SimState<S>& state) {
    return std::make_unique<BlockJacobi<S>>(state);
}

template std::unique_ptr<Preconditioner<double>> make_block_jacobi(const SimState<double>&);
template std::unique_ptr<Preconditioner<float>> make_block_jacobi(const SimState<float>&);

}  // namespace edgefem::sim
