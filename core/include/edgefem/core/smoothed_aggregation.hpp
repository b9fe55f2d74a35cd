// Smoothed-aggregation algebraic multigrid (Vanek, Mandel, Brezina 1996) for
// elasticity: nodes are 3x3 vertex blocks on the finest level (6x6 on the
// coarse ones), the near-nullspace is the six rigid-body modes of the
// positions build() is given (the rest shape, or the body deformed).
// build() forms the aggregates (greedy, on the matrix's block graph) and
// the prolongators P = (I - w D^-1 A) P_tent once, level by level on the
// operator the level above's prolongator gives (the values as rebuild()
// forms them, into a block pattern found from the aggregates and A's
// couplings, its zero blocks then dropped); refresh() recomputes
// the Galerkin operators R A P, the smoothers (Chebyshev in D^-1 A or l1
// block-Jacobi) and the coarsest level's dense LDL^T (its factor in float;
// core/src/amg/coarse_ldlt.hpp) for a new A of the same pattern; apply() runs one symmetric
// V-cycle (the smoothers are symmetric and only products and axpys), the finest level's
// products through a caller's function (the matrix-free per-edge K). On the
// host: on an executor's threads when set_executor() gives one (the vector
// passes, the smoothers' blocks, the coarse products and the transfers in
// the fixed blocks of for_blocks; the prolongator then held grouped by
// aggregates, the restriction a gather over them: core/src/amg/block_rows.hpp),
// bitwise the same for any executor and thread count.
#pragma once

#include <Eigen/SparseCore>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "edgefem/core/amg_settings.hpp"
#include "edgefem/core/executor.hpp"
#include "edgefem/core/mesh.hpp"

namespace edgefem {

using SparseRows = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

class SmoothedAggregation {
public:
    SmoothedAggregation();
    ~SmoothedAggregation();

    // A: the fine system over 3 #V dofs with the rows and columns of
    // constrained dofs zero; positions: 3 coordinates per vertex (where the body is); free_dof: 1 on
    // unknowns. Builds the hierarchy with refresh(A)'s operators and smoothers.
    // Runs apply() and smooth() on `ex` (null: serial). With more than one
    // thread the prolongators are held grouped by their block columns (the
    // same blocks, the same memory): the restriction a gather, the
    // prolongation a scatter.
    void set_executor(std::shared_ptr<const Executor> ex);
    void build(const SparseRows& A, const std::vector<double>& positions, const std::vector<std::uint8_t>& free_dof,
               const AmgSettings& settings = {});
    // Galerkin operators, smoothers and coarsest factorisation for a new A
    // with the pattern build() saw.
    void refresh(const SparseRows& A);
    // The hierarchy made again for a new A of build()'s pattern and the body
    // at `positions` (3 #V), on build()'s aggregates and the patterns of its
    // prolongators and coarse operators: the near-nullspace (the positions'
    // rigid-body modes on build()'s free dofs), per aggregate its QR (the
    // tentative prolongator, the coarse near-nullspace), the smoothed
    // prolongators' values formed into their patterns, then refresh(A)'s
    // work (the Chebyshev smoother's D^-1 and largest eigenvalue are those
    // the prolongator smoother uses). 1.2-1.5 refreshes where build() costs
    // 2.2-2.5 (docs/solvers.md). The aggregates of build() come from A's
    // strong couplings then: a fresh build() on a deformed body may group
    // differently (on a body turned rigidly it does not). Returns false
    // where a prolongator's value fell outside build()'s pattern (a block
    // build() found exactly zero): then it has built afresh. Another pattern
    // or positions of another size is an error that names it. Frees the
    // tentative prolongators and near-nullspace (as release_build_data()).
    bool rebuild(const SparseRows& A, const std::vector<double>& positions);
    // z = one V-cycle applied to r (n each, zero on constrained dofs);
    // fine(x, y): y = A x with constrained entries of y zero.
    void apply(const double* r, double* z, const std::function<void(const double*, double*)>& fine) const;
    // x += S (b - A_level x): one application of level's smoother (not on the
    // coarsest), the one the V-cycle runs before and after its correction.
    void smooth(int level, const double* b, double* x, const std::function<void(const double*, double*)>& fine) const;

    int levels() const;                                // including the finest
    // Whether the last build or refresh found the coarsest level's operator
    // indefinite (a negative pivot of its LDL^T): then A is indefinite too
    // (the Galerkin operator of a definite A is definite), and the V-cycle
    // is no SPD preconditioner for CG.
    bool coarsest_indefinite() const;
    index_t dofs(int level) const;
    const SparseRows& tentative(int level) const;      // level -> level + 1, before smoothing
    SparseRows prolongator(int level) const;           // as apply() uses it (float values)
    const Eigen::MatrixXd& near_nullspace(int level) const;  // dofs(level) x 6
    SparseRows matrix(int level) const;                // 1 <= level < levels() - 1 (level 0: the caller's; the coarsest: factorised)
    // Frees what only build() and the accessors above need (the tentative
    // prolongators, the near-nullspace): refresh(), rebuild() and apply() go
    // on (rebuild() keeps each level's aggregates and build()'s free dofs:
    // 4 bytes a node and 1 a dof).
    void release_build_data();
    std::size_t bytes() const;                         // what is held (after release_build_data(): what apply() and refresh() need)
    // One V-cycle's work in products with the finest level's matrix (its
    // entries on and above the diagonal, as the per-edge K holds them): the
    // finest level's own products (2 x smoothing_steps) and the entries the
    // coarser levels' products, the transfers and the coarsest solve read,
    // over the finest level's. A count of the hierarchy, the same on any
    // machine: the auto preconditioner's cost model (docs/solvers.md).
    double cycle_cost() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The six rigid-body modes of points (3 coordinates each) about their
// centroid: translations x, y, z, rotations about x, y, z (3 #points x 6).
Eigen::MatrixXd rigid_body_modes(const std::vector<double>& points);

}  // namespace edgefem
