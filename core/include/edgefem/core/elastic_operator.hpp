// The elastic model's kernels, declared once: forces (and the energy),
// the tangent stiffness K, K x, K's diagonal blocks, for the edge-based FE,
// the edge-based SN or the per-tet method. Every back-end implements them
// (the reference back-end: core/src/reference/, plain loops over the
// formulas of edgefem/physics/; the CPU back-end: parallel/src/cpu/, lanes,
// tiles and threads), so the integrators and solvers never know which runs.
// Each virtual call is a whole-mesh kernel.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"

namespace edgefem {

enum class Method { Edge, Tet };

template <class S>
class ElasticOperator {
public:
    virtual ~ElasticOperator() = default;
    virtual index_t num_vertices() const = 0;
    // f = dW/du at displacement u (3 #V, overwritten). Returns W when
    // `energy`, else 0. Remembers u for build_stiffness.
    virtual double forces(const S* u, S* f, bool energy) = 0;
    // W at u, without forces.
    virtual double energy(const S* u) = 0;
    // A hint: whether a build_stiffness() may follow forces() (true until
    // told otherwise). A caller that never builds K (explicit steps, a force
    // benchmark) says false, and an operator may then skip storing the
    // state K would be built from; build_stiffness() stays correct either
    // way (it recomputes what it lacks).
    virtual void keep_state(bool /*keep*/) {}
    // K at the configuration of the last forces() call. `definite` clamps
    // g(E) at zero inside K (edge method only): K becomes positive
    // semi-definite, the forces are unchanged.
    virtual void build_stiffness(bool definite) = 0;
    // y = K x with the K of the last build_stiffness (3 #V, overwritten).
    // One call at a time per operator, like every other member: the kernels
    // keep scratch in the operator (padded copies, spill windows), const or
    // not.
    virtual void multiply(const S* x, S* y) const = 0;
    // The 3x3 diagonal blocks of K (9 #V, row-major, overwritten).
    virtual void diagonal_blocks(S* D) const = 0;
    // Every nonzero 3x3 block of K: (row vertex, column vertex, block), the
    // diagonal blocks included, each (i, j) pair once per contribution.
    virtual void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const = 0;
    // Number of tets with non-positive volume at the last forces() call.
    virtual index_t inverted_tets(const S* u) const = 0;
    // Whether forces() takes g(E) from the tet-local form rather than the
    // TSEP list: which arrays a force call streams (stream_bandwidth.hpp).
    virtual bool forces_from_tet_local_form() const { return false; }
    // Whether the last forces() call stored its per-edge state (p~, zeta,
    // g) in mesh-wide arrays, i.e. wrote it to memory on a large mesh
    // (stream_bandwidth.hpp counts those bytes only then).
    virtual bool forces_stored_state() const { return true; }
};

}  // namespace edgefem
