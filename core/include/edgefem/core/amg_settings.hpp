// The smoothed-aggregation AMG's parameters (smoothed_aggregation.hpp;
// docs/solvers.md has the measurements behind the defaults). Plain data, so
// that SolverSettings can hold them without the AMG's headers.
#pragma once

namespace edgefem {

enum class AmgSmoother {
    Chebyshev,  // a Chebyshev polynomial in D^-1 A (D: the diagonal blocks), degree smoothing_steps
    L1Jacobi,   // smoothing_steps sweeps of l1 block-Jacobi
};

struct AmgSettings {
    // A level with at most this many dofs is the coarsest (factorised:
    // a dense LDL^T, rounded to float).
    int max_coarse_dofs = 250;
    int max_levels = 8;
    // Before and after the coarse correction: the Chebyshev degree or the
    // number of l1 sweeps; either costs 2 x smoothing_steps products with
    // the level's matrix per V-cycle.
    int smoothing_steps = 2;
    int power_iterations = 12;   // for the largest eigenvalue of D^-1 A (prolongator smoother, Chebyshev)
    AmgSmoother smoother = AmgSmoother::Chebyshev;
    // Chebyshev: the polynomial damps the eigenvalues of D^-1 A in
    // [lambda_max / chebyshev_ratio, 1.1 lambda_max].
    double chebyshev_ratio = 10;
    // The prolongator smoother P = (I - w / lambda_max D^-1 A) P_tent.
    double prolongator_weight = 4.0 / 3.0;
    // Coarse levels aggregate over couplings with |A_ij|_F^2 > strength^2
    // |A_ii|_F |A_jj|_F (the finest level over the whole edge graph). At
    // 0.08, a small step's mass-dominated coarse operator had too few strong
    // couplings to coarsen (bunny-4k at 1 ms: 462 -> 246 dofs, dense below);
    // 0.04: the same iterations, less memory (docs/solvers.md, "Memory").
    double strength = 0.04;
    // A coarse level (not the finest) whose operator has at least this share
    // of its entries nonzero is the coarsest too: its two triangular solves
    // (n^2 multiply-adds) then cost no more than the four products with it
    // (4 nnz) a V-cycle would spend there, before the levels below. bunny-4k
    // stops at its 462-dof level 1 (38 % nonzero): AMG / block-Jacobi step
    // 1.45 -> 0.65 at dt = 4 ms (docs/solvers.md); 0 turns it off.
    double dense_coarsest = 0.25;
};

}  // namespace edgefem
