// Floating-point operation counts of the kernels, derived by hand from the
// source (core/include/edgefem/core/edge_kernels.hpp, tet_kernels.hpp) and
// checked exactly against an instrumented run with a counting scalar
// (bench/counting_scalar.hpp, tests/test_flop_counts.cpp).
//
// Convention: every binary +, -, *, / executed by the source as written
// counts 1 (an FMA is 2), with no common subexpressions removed; unary minus,
// comparisons, max and conversions count 0. The zero-fill of outputs is not
// arithmetic. Item counts: V vertices, E edges, P TSEPs, T tets.
//
// The edge kernels accumulate g(E) in double whatever the scalar is
// (edge_kernels.hpp, EdgeState::g), so a counting scalar cannot see that
// arithmetic: the TSEP strain loop (4 per TSEP, 1 per edge for g(E0) += acc)
// is all double. `counted` below is what the counting scalar sees, `total`
// adds the double part by hand.
#pragma once

#include <cmath>

#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/tet_edge_form.hpp"

namespace edgefem::flops {

// ---- Per item ------------------------------------------------------------
// edge_strain: d = u(a) - u(b) 3, q = r + d 3, zeta = d.(r + q) 3 + 3 + 2, g = L(E) zeta 1.
inline constexpr long kEdgeStrain = 15;
// tsep_strain_segment, per TSEP: acc += L zeta(E1) 2, g(E1) += L zeta(E0) 2 (double).
inline constexpr long kTsepStrainDouble = 4;
// tsep_strain_segment, per edge (segment): g(E0) += acc 1 (double).
inline constexpr long kSegmentStrainDouble = 1;
// tet_form_strain (double, every lane of a 4-lane group; padding lanes of
// the last group compute zeros): 6 rows x 5 terms x (mul + add) = 60; per
// tet, g(E) += s for its 6 edges (double).
inline constexpr long kTetFormStrainPerLane = 60;
inline constexpr long kTetFormStrainUpdates = 6;
// edge_force_segment (edges in V0 segments), per edge: v = p~ g 3, acc += v 3,
// f(b) -= v 3; per vertex: f(a) += acc 3.
inline constexpr long kEdgeForce = 9;
inline constexpr long kVertexForce = 3;
// edge_stiffness: c = -2 L(E) 1; 9 entries c q_i q_j - (g or 0) 3 each.
inline constexpr long kEdgeStiffness = 28;
// tsep_stiffness_segment, per TSEP: c = 2 L(P) 1; 4 targets x (cs x_i 3 + 9 (mul + add)).
inline constexpr long kTsepStiffness = 85;
// tet_form_stiffness, per lane of a batch (every batch runs all kTetLanes
// lanes; padding lanes of the last batch compute zeros): signed rows of A
// 6 x 4 x 3 = 72; W 6 x 4 x 3 x (3 mul + 2 add) = 360; per local edge: signed
// p~ 9, 9 entries x (3 mul + 2 add) = 45, 9 updates; x 6 edges = 378.
inline constexpr long kTetFormStiffnessPerLane = 72 + 360 + 6 * (9 + 45 + 9);
// edge_kx_segment, per edge: d 3; 3 rows x 2 ends x (3 mul + 2 add + 1 update);
// per vertex: y(a) -= acc 3.
inline constexpr long kEdgeKx = 39;
inline constexpr long kVertexKx = 3;

// Per-tet kernels: the one-tet form (tet_kernels.hpp), which the counting
// scalar runs. The batched form that float and double run
// (tet_batch_kernels.hpp) skips G's lower triangle (24) and F F^T's (15)
// and scales F a by lambda and mu once per vertex row (36): fewer FLOPs
// than counted here.
// tet_deformation: D 9, H = D Dm^-1 45, G 72, tr 2, S 30, F 9, G:G 18, energy 5.
inline constexpr long kTetDeformation = 190;
// Of which the energy (G:G 18 + energy 5): dead code when the energy is not used.
inline constexpr long kTetEnergyOnly = 23;
// tet_force after the deformation: P = F S 45; 3 rows x (3 x (5 + 1 + 1) + 1).
inline constexpr long kTetForceTail = 111;
// tet_stiffness after the deformation: a_0 6, F a and S a 120, F F^T 45,
// 10 blocks x (aSa 5 + mu aa 6 + 3 rows x (lambda Fa, mu Fa 2 + 3 entries
// x (3 mul + 2 add) + diagonal 1)).
inline constexpr long kTetStiffnessTail = 6 + 120 + 45 + 10 * (5 + 6 + 3 * (2 + 3 * 5 + 1));
// tet_kx from stored blocks: 4 x (4 blocks x 3 rows x (3 mul + 3 add)) + 12 updates.
inline constexpr long kTetKx = 4 * 4 * 3 * 6 + 12;

struct Items {
    double E = 0, P = 0, T = 0, V = 0;
};

template <class S>
Items items_of(const EdgeModel<S>& m) {
    return {double(m.num_edges()), double(m.num_tseps()), double(m.num_tets), double(m.num_vertices)};
}

struct Count {
    double counted = 0;  // what a counting scalar sees
    double total = 0;    // counted + the double arithmetic on g
};

// Edge-based forces (energy off).
inline Count edge_force(const Items& n, ModelKind kind) {
    Count c;
    c.counted = n.E * (kEdgeStrain + kEdgeForce) + n.V * kVertexForce;
    c.total = c.counted + (kind == ModelKind::FE ? n.P * kTsepStrainDouble + n.E * kSegmentStrainDouble : 0.0);
    return c;
}
// FE forces with the tet-local form's g pass instead of the TSEP loop (the
// serial operator's path when it holds the form: the default layout).
inline Count edge_force_tet_local(const Items& n) {
    Count c = edge_force(n, ModelKind::SN);  // the same counted arithmetic: strains and scatter
    const double lanes = std::ceil(n.T / 4) * 4;
    c.total = c.counted + lanes * kTetFormStrainPerLane + n.T * kTetFormStrainUpdates;
    return c;
}
// Edge-based stiffness (from the state of a force call).
inline Count edge_stiffness(const Items& n, ModelKind kind) {
    const double v = n.E * kEdgeStiffness + (kind == ModelKind::FE ? n.P * kTsepStiffness : 0.0);
    return {v, v};
}
// FE stiffness from the tet-local form (the default layout): the edge terms,
// then every lane of every batch (kTetLanes<double> tets; the counts are taken
// in double).
inline Count edge_stiffness_tet_local(const Items& n) {
    const double lanes = std::ceil(n.T / kTetLanes<double>) * kTetLanes<double>;
    const double v = n.E * kEdgeStiffness + lanes * kTetFormStiffnessPerLane;
    return {v, v};
}
inline Count edge_kx(const Items& n) {
    const double v = n.E * kEdgeKx + n.V * kVertexKx;
    return {v, v};
}

// Per-tet: `with_energy` counts the energy's arithmetic, which the source
// computes in every tet_deformation call (the counting scalar sees it) but an
// optimising compiler drops where the energy is unused.
inline Count tet_force(const Items& n, bool with_energy) {
    const double v = n.T * (kTetDeformation - (with_energy ? 0 : kTetEnergyOnly) + kTetForceTail);
    return {v, v};
}
inline Count tet_stiffness(const Items& n, bool with_energy) {
    const double v = n.T * (kTetDeformation - (with_energy ? 0 : kTetEnergyOnly) + kTetStiffnessTail);
    return {v, v};
}
inline Count tet_kx(const Items& n) { return {n.T * kTetKx, n.T * kTetKx}; }

inline Count operator+(Count a, Count b) { return {a.counted + b.counted, a.total + b.total}; }

}  // namespace edgefem::flops
