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
#include "cpu/tet_edge_form.hpp"

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

// Per-tet kernels (physics/tet_stvk.hpp): the one-tet loops that the
// counting scalar runs and the 4-lane batches that float and double run
// call the same formulas, so these counts hold for both (per lane).
// tet_deformation: D 9, H = D Dm^-1 9 x (3 mul + 2 add) 45, G's upper
// triangle 6 x (2 add + 3 x (mul + add) + 0.5 x) 48, tr 2, 2 mu and lambda
// tr 2, S 9 x (mul + add) 18.
inline constexpr long kTetDeformation = 124;
// With the energy: G's off-diagonal squares 5, G:G 7, Vol(lambda/2 tr^2 +
// mu G:G) 5 (tet_force computes it; the stiffness does not ask for it).
inline constexpr long kTetEnergyOnly = 17;
// tet_force after the deformation: P = S + H S 9 x (3 mul + 3 add) 54; per
// row 3 x (P a_i 5 + sum 1) 18, x 3 rows 54; 12 vertex updates.
inline constexpr long kTetForceTail = 54 + 54 + 12;
// tet_stiffness after the deformation: F = I + H 9, a_0 6, F a and S a
// 4 x 3 x 10 = 120, lambda F a and mu F a 24, F F^T's upper triangle 6 x 5 =
// 30, per block a_i.S a_j 5 and mu a_i.a_j 6 (x 10 blocks), 90 entries x
// (3 mul + 2 add) and a_i.S a_j on the 30 diagonal entries.
inline constexpr long kTetStiffnessTail = 9 + 6 + 120 + 24 + 30 + 10 * (5 + 6) + 90 * 5 + 30;
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

// Per-tet: the force computes the energy too (`with_energy`: what the
// source computes and the counting scalar sees; an optimising compiler
// drops it where the energy is unused); the stiffness never does.
inline Count tet_force(const Items& n, bool with_energy) {
    const double v = n.T * (kTetDeformation + (with_energy ? kTetEnergyOnly : 0) + kTetForceTail);
    return {v, v};
}
inline Count tet_stiffness(const Items& n) {
    const double v = n.T * (kTetDeformation + kTetStiffnessTail);
    return {v, v};
}
inline Count tet_kx(const Items& n) { return {n.T * kTetKx, n.T * kTetKx}; }

inline Count operator+(Count a, Count b) { return {a.counted + b.counted, a.total + b.total}; }

}  // namespace edgefem::flops
