// Preconditioned conjugate gradients on a projected system: constrained
// degrees of freedom keep the value they have in x on entry, the others solve
// P A P x = P b. Matrix-free: A and the preconditioner are applied by the
// caller. Declared once as a vector kernel (VectorKernels::cg); the scalar
// steps and the iteration loop are written here once for every
// implementation (CgControl, cg_iterations), and conjugate_gradient below is
// the fused form the CPU back-end runs: the vector updates as fixed blocks
// on the executor, dot products summed per block in a fixed order, bitwise
// the same for any thread count.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "edgefem/core/backend_vector.hpp"
#include "edgefem/core/executor.hpp"
#include "edgefem/physics/host_device.hpp"

namespace edgefem {

struct CgResult {
    int iterations = 0;
    double residual = 0;  // |P(b - A x)| / |P(b - A x_c)| at exit, x_c: x's constrained values (0 denominator: absolute)
    bool converged = false;
    bool negative_curvature = false;  // met p^T A p <= 0: stopped at the last good iterate
};

struct CgSettings {
    double tolerance = 1e-6;
    int max_iterations = 500;
    int fixed_iterations = 0;  // > 0: exactly this many iterations (unless the residual vanishes), no tolerance
};

// Work vectors, in the memory they are constructed with (host memory by
// default).
struct CgWork {
    CgWork() = default;
    explicit CgWork(const VectorMemory& memory)
        : r(memory, 0), z(memory, 0), p(memory, 0), Ap(memory, 0), keep(memory, 0), partial(memory, 0) {}
    BackendVector<double> r, z, p, Ap;  // double: the iteration's recurrences stay accurate for float A
    BackendVector<double> keep;         // 1 on unknowns, 0 on constrained dofs
    BackendVector<double> partial;      // per-block partial sums (4 per block: p.Ap, r.r, r.z, b.b)
};

// A as the cg kernel applies it, in two parts: products(x, y) overwrites y
// with the whole-vector part (a stiffness product, free to run its own
// parallel loops), then finish(lo, hi, x, y) completes y on [lo, hi)
// (diagonal terms: mass, scaling), on the calling thread.
class CgSystem {
public:
    virtual ~CgSystem() = default;
    virtual void products(const double* x, double* y) = 0;
    virtual void finish(std::size_t lo, std::size_t hi, const double* x, double* y) const = 0;
};

// z = M^-1 r on [lo, hi) from r on [lo, hi) only, on the calling thread;
// lo and hi are multiples of 3 (whole vertices) or n. A whole-vector
// preconditioner (a multigrid cycle) needs all of r: it is applied once
// per iteration as apply(0, n, r, z), between the cg kernel's passes, and
// may run its own parallel loops.
class CgPreconditioner {
public:
    virtual ~CgPreconditioner() = default;
    virtual void apply(std::size_t lo, std::size_t hi, const double* r, double* z) const = 0;
    virtual bool whole_vector() const { return false; }
};

// CG's scalar steps. bnorm: |P(b - A x_c)|, the norm residuals are
// relative to (1 when it is 0).
class CgControl {
public:
    CgControl(const CgSettings& settings, double bnorm) : s_(settings), scale_(bnorm > 0 ? bnorm : 1.0) {}
    double residual(double rr) const { return relative(rr, scale_); }
    double scale() const { return scale_; }
    EDGEFEM_HOST_DEVICE static double relative(double rr, double scale) { return std::sqrt(rr) / scale; }
    bool converged(double residual) const { return s_.fixed_iterations == 0 && residual <= s_.tolerance; }
    int limit() const { return s_.fixed_iterations > 0 ? s_.fixed_iterations : s_.max_iterations; }
    double tolerance() const { return s_.tolerance; }
    // False for p.Ap <= 0 and NaN: x stays at the last good iterate.
    EDGEFEM_HOST_DEVICE static bool positive_curvature(double pAp) { return pAp > 0; }
    EDGEFEM_HOST_DEVICE static double alpha(double rz, double pAp) { return rz / pAp; }
    EDGEFEM_HOST_DEVICE static double beta(double rz_new, double rz) { return rz_new / rz; }

private:
    CgSettings s_;
    double scale_;
};

// The sums one iteration ends with: p.Ap, and r.r, r.z after its update.
struct CgSums {
    double pAp = 0, rr = 0, rz = 0;
};

// CG's iteration loop, after a start pass left r = P(b - A x), z = M^-1 r,
// p = z with r.r = rr and r.z = rz. iterate(rz) runs one iteration: A p,
// p.Ap; when CgControl::positive_curvature(p.Ap), alpha, x and r updated,
// z = M^-1 r; unless then converged, beta and p updated; and returns its
// sums (rr and rz unused after a non-positive p.Ap).
template <class Iterate>
CgResult cg_iterations(const CgControl& c, double rr, double rz, Iterate&& iterate) {
    CgResult res;
    res.residual = c.residual(rr);
    if (c.converged(res.residual)) {
        res.converged = true;
        return res;
    }
    for (int it = 0; it < c.limit(); ++it) {
        if (res.residual == 0) break;
        const CgSums s = iterate(rz);
        if (!CgControl::positive_curvature(s.pAp)) {
            res.negative_curvature = true;
            break;
        }
        ++res.iterations;
        res.residual = c.residual(s.rr);
        if (c.converged(res.residual)) break;
        rz = s.rz;
    }
    res.converged = !res.negative_curvature && res.residual <= c.tolerance();
    return res;
}

// n scalars; free_dof[i] != 0 for unknowns. The system matrix is applied in
// two parts: apply_A(const double* x, double* y) overwrites y with the
// whole-vector part (a stiffness product, free to run its own parallel
// loops), then finish_A(lo, hi, x, y) completes y on the block [lo, hi)
// (diagonal terms: mass, scaling; may do nothing). apply_M(lo, hi, r, z)
// overwrites z = M^-1 r on [lo, hi) from r on [lo, hi) only. Block bounds
// are multiples of kVectorBlock (a multiple of 3: whole vertices) or n.
// `fixed_iterations` > 0 runs exactly that many iterations (unless the
// residual vanishes), ignoring the tolerance. `whole_M`: apply_M needs the
// whole vector (CgPreconditioner::whole_vector): it is called as
// apply_M(0, n, r, z) once per iteration between two parallel regions (the
// three phases become phases 0-1, M, then r.z and p's update).
//
// Between two products an iteration is one pass of three phases over the
// blocks, one parallel region with two barriers: (0) finish A p, partials
// of p.Ap; (1) alpha, x and r updated, partials of r.r, z = M^-1 r,
// partials of r.z; (2) beta, p updated. Every group sums the partials in
// one fixed order itself (partials_total), so no serial section sits
// between the phases and the sums are the same for any thread count. (On
// armadillo-7k a step's CG vector work ran as ~7 whole-vector passes on one
// thread: its 6558 dofs were one block.)
template <class ApplyA, class FinishA, class ApplyM>
CgResult conjugate_gradient(const Executor& ex, std::size_t n, const std::uint8_t* free_dof, ApplyA&& apply_A,
                            FinishA&& finish_A, ApplyM&& apply_M, const double* b, double* x, double tolerance,
                            int max_iterations, int fixed_iterations, CgWork& w, bool whole_M = false) {
    w.r.resize(n);
    w.z.resize(n);
    w.p.resize(n);
    w.Ap.resize(n);
    w.keep.resize(n);
    const std::size_t nb = vector_blocks(n);
    w.partial.resize(4 * nb);
    std::fill(w.partial.data(), w.partial.data() + 4 * nb, 0.0);
    // The projection multiplies by keep (1 or 0) inside the passes: g++ 12
    // vectorises none of these loops with a select on free_dof in them.
    // A p is not projected in a pass of its own (p is zero on constrained
    // dofs: p.Ap takes keep in its terms and r in its update), nor is z (r
    // is zero there: r.z takes keep, and p in its update). Scalars by value
    // and arrays through local restrict pointers, so that the loops
    // vectorise; within a block the updates and the sums are separate loops
    // (an update inside block_sum's terms does not vectorise), the block
    // still in cache for the second.
    double* __restrict r = w.r.data();
    double* __restrict z = w.z.data();
    double* __restrict p = w.p.data();
    double* __restrict Ap = w.Ap.data();
    double* __restrict keep = w.keep.data();
    double* __restrict xs = x;
    double* const pap_part = w.partial.data();
    double* const rr_part = pap_part + nb;
    double* const rz_part = rr_part + nb;
    double* const bb_part = rz_part + nb;
    const auto total = [nb](const double* part) { return partials_total(part, nb); };
    const index_t groups = block_groups(ex, nb);
    const index_t phase_first[4] = {0, groups, 2 * groups, 3 * groups};
    // blocks(g, body): body(lo, hi, k) over the blocks k of group g.
    const auto blocks = [&](index_t g, auto&& body) {
        for_group_blocks(g, groups, n, [&](std::size_t lo, std::size_t hi) { body(lo, hi, lo / kVectorBlock); });
    };

    // The residual is relative to |P(b - A x_c)|, x_c = x's constrained
    // values: the right-hand side the free dofs actually see. With moving
    // constraints (a prescribed ramp, the only load) P b alone is zero, and
    // dividing by 1 instead made the tolerance absolute: on a soft body
    // CG stopped after 0 iterations with the free vertices unmoved. The
    // extra product runs only when a constrained value is non-zero.
    // The scan runs on the executor's blocks, as every pass over the dofs
    // (a count: the same for any thread count).
    const bool moving_constraints = blocked_sum(ex, n, [=](std::size_t i) {
                                        return double(int(free_dof[i] == 0) & int(x[i] != 0));
                                    }) > 0;
    double bnorm = 0;
    if (moving_constraints) {
        for_blocks(ex, n, [=](std::size_t lo, std::size_t hi) {
            for (std::size_t i = lo; i < hi; ++i) z[i] = free_dof[i] ? 0.0 : x[i];
        });
        apply_A(z, Ap);
        ex.for_uniform_phases(1, phase_first, [&](int, index_t g) {
            blocks(g, [&](std::size_t lo, std::size_t hi, std::size_t k) {
                finish_A(lo, hi, z, Ap);
                bb_part[k] = block_sum(lo, hi, [=](std::size_t i) {
                    const double d = (b[i] - Ap[i]) * (free_dof[i] ? 1.0 : 0.0);
                    return d * d;
                });
            });
        });
        bnorm = std::sqrt(total(bb_part));
    }
    apply_A(x, Ap);
    ex.for_uniform_phases(1, phase_first, [&](int, index_t g) {
        blocks(g, [&](std::size_t lo, std::size_t hi, std::size_t k) {
            for (std::size_t i = lo; i < hi; ++i) keep[i] = free_dof[i] ? 1.0 : 0.0;
            finish_A(lo, hi, x, Ap);
            for (std::size_t i = lo; i < hi; ++i) r[i] = (b[i] - Ap[i]) * keep[i];
            bb_part[k] = block_sum(lo, hi, [=](std::size_t i) { return b[i] * b[i] * keep[i]; });
            rr_part[k] = block_sum(lo, hi, [=](std::size_t i) { return r[i] * r[i]; });
            if (whole_M) return;
            apply_M(lo, hi, r, z);
            for (std::size_t i = lo; i < hi; ++i) p[i] = z[i] * keep[i];
            rz_part[k] = block_sum(lo, hi, [=](std::size_t i) { return r[i] * p[i]; });
        });
    });
    // r.z of the updated r and z (a whole-vector M's second region).
    const auto rz_sums = [&](std::size_t lo, std::size_t hi, std::size_t k) {
        rz_part[k] = block_sum(lo, hi, [=](std::size_t i) { return r[i] * z[i] * keep[i]; });
    };
    if (whole_M) {
        apply_M(0, n, r, z);
        ex.for_uniform_phases(1, phase_first, [&](int, index_t g) {
            blocks(g, [&](std::size_t lo, std::size_t hi, std::size_t k) {
                for (std::size_t i = lo; i < hi; ++i) p[i] = z[i] * keep[i];
                rz_sums(lo, hi, k);
            });
        });
    }
    if (!moving_constraints) bnorm = std::sqrt(total(bb_part));
    const CgControl control({tolerance, max_iterations, fixed_iterations}, bnorm);
    return cg_iterations(control, total(rr_part), total(rz_part), [&](double rz) {
        const auto update_p = [&](index_t g) {
            if (control.converged(control.residual(total(rr_part)))) return;
            const double beta = CgControl::beta(total(rz_part), rz);
            blocks(g, [&](std::size_t lo, std::size_t hi, std::size_t) {
                for (std::size_t i = lo; i < hi; ++i) p[i] = (z[i] + beta * p[i]) * keep[i];
            });
        };
        apply_A(p, Ap);
        // Each group sums the partials it needs once, in a fixed order (partials_total).
        ex.for_uniform_phases(whole_M ? 2 : 3, phase_first, [&, rz](int phase, index_t g) {
            if (phase == 0) {
                blocks(g, [&](std::size_t lo, std::size_t hi, std::size_t k) {
                    finish_A(lo, hi, p, Ap);
                    pap_part[k] = block_sum(lo, hi, [=](std::size_t i) { return p[i] * Ap[i] * keep[i]; });
                });
                return;
            }
            const double pAp = total(pap_part);
            if (!CgControl::positive_curvature(pAp)) return;
            if (phase == 1) {
                const double alpha = CgControl::alpha(rz, pAp);
                blocks(g, [&](std::size_t lo, std::size_t hi, std::size_t k) {
                    for (std::size_t i = lo; i < hi; ++i) {
                        xs[i] += alpha * p[i];
                        r[i] = (r[i] - alpha * Ap[i]) * keep[i];
                    }
                    rr_part[k] = block_sum(lo, hi, [=](std::size_t i) { return r[i] * r[i]; });
                    if (whole_M) return;
                    apply_M(lo, hi, r, z);
                    rz_sums(lo, hi, k);
                });
                return;
            }
            update_p(g);
        });
        if (whole_M && CgControl::positive_curvature(total(pap_part)) &&
            !control.converged(control.residual(total(rr_part)))) {
            apply_M(0, n, r, z);
            ex.for_uniform_phases(2, phase_first, [&](int phase, index_t g) {
                if (phase == 0) blocks(g, rz_sums);
                else update_p(g);
            });
        }
        return CgSums{total(pap_part), total(rr_part), total(rz_part)};
    });
}

}  // namespace edgefem
