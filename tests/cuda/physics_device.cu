// Every formula of core/include/edgefem/physics/ called from device code, in
// double and float: the test `physics_formulas_compile_for_device` compiles
// this file with nvcc (when the build finds one) to show that the formulas a
// CUDA back-end will call are host/device functions with nothing host-only
// in them. It is compiled, not run.
#include "edgefem/physics/edge_blocks.hpp"
#include "edgefem/physics/edge_force.hpp"
#include "edgefem/physics/edge_g.hpp"
#include "edgefem/physics/edge_stiffness.hpp"
#include "edgefem/physics/edge_strain.hpp"
#include "edgefem/physics/stress_measures.hpp"
#include "edgefem/physics/tet_local_form.hpp"
#include "edgefem/physics/tet_stvk.hpp"
#include "edgefem/physics/tsep_stiffness.hpp"

using namespace edgefem;

template <class S>
__global__ void edge_formulas(int n, const S* d, const S* r, const S* LE, S* out) {
    const int e = blockIdx.x * blockDim.x + threadIdx.x;
    if (e >= n) return;
    S q[3];
    const S z = physics::edge_strain(d[3 * e], d[3 * e + 1], d[3 * e + 2], r[3 * e], r[3 * e + 1], r[3 * e + 2], q[0],
                                     q[1], q[2]);
    const double g = double(physics::own_g(LE[e], z)) + physics::pair_g(0.5, double(z));
    S K[9];
    physics::edge_stiffness(LE[e], S(physics::stiffness_g(g, true)), q, K);
    physics::add_pair_block(physics::slot_coefficient(physics::pair_coefficient(LE[e]), e & 3), q, q, K);
    S D0[9] = {}, D1[9] = {};
    physics::subtract_block(K, D0);
    physics::subtract_block_transposed(K, D1);
    out[e] = physics::edge_force(q[0], S(g)) + physics::row_times(K[0], K[1], K[2], q[0], q[1], q[2]) +
             physics::transpose_times(K[0], K[3], K[6], q[0], q[1], q[2]) + D0[4] + D1[5] +
             S(physics::energy_from_terms(physics::energy_term(double(z), g)));
}

template <class S>
__global__ void tet_formulas(int n, const S* u, const S* dinv, S* out) {
    const int t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= n) return;
    S U[4][3], Dinv[3][3];
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c) U[i][c] = u[12 * t + 3 * i + c];
    for (int i = 0; i < 3; ++i)
        for (int c = 0; c < 3; ++c) Dinv[i][c] = dinv[9 * t + 3 * i + c];
    physics::TetDeformation<S> d;
    physics::tet_deformation<true, S>(U, Dinv, S(1), S(2), d);
    S f[4][3], y[4][3];
    physics::tet_forces(d, Dinv, f);
    physics::TetStiffnessTerms<S> k;
    physics::tet_stiffness_terms<S>(d, Dinv, S(1), S(2), k);
    physics::tet_stiffness_times<S>(d, U, Dinv, S(1), S(2), y);
    S Kt[90];
    physics::tet_stiffness_blocks(k, Kt);
    // The tet-local form on the same tet's "edge vectors".
    S p[6][3], W[6][4][3], kv[9], zeta[6];
    for (int e = 0; e < 6; ++e) {
        zeta[e] = 0;
        for (int c = 0; c < 3; ++c) {
            p[e][c] = U[physics::tet_edge_vertex(e, 0)][c] - U[physics::tet_edge_vertex(e, 1)][c];
            zeta[e] += p[e][c] * p[e][c];
        }
    }
    const auto coef = [&](int a, int b) { return a == b ? S(0) : Dinv[a % 3][b % 3]; };
    physics::form_w<S>(coef, p, W);
    physics::form_block<S>(t % 6, p, W, kv);
    S G[3][3], S2[3][3], sigma[3][3];  // the output fields' measures
    physics::green_strain<S>(d.H, G);
    physics::stvk_stress(G, S(1), S(2), S2);
    physics::cauchy_stress<S>(d.H, S2, sigma);
    out[t] = physics::von_mises<S>(sigma) + d.energy + f[0][0] + y[1][2] + physics::tet_stiffness_entry(k, 0, 1, 2, 0) + Kt[t % 90] + kv[4] + physics::form_g(t % 6, coef, zeta);
}

template __global__ void edge_formulas<double>(int, const double*, const double*, const double*, double*);
template __global__ void edge_formulas<float>(int, const float*, const float*, const float*, float*);
template __global__ void tet_formulas<double>(int, const double*, const double*, double*);
template __global__ void tet_formulas<float>(int, const float*, const float*, float*);
