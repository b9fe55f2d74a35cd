#include "solvers/tangent_point.hpp"

namespace edgefem::sim {

template <class S>
void TangentPoint<S>::record(const SimState<S>& s, const LinearSystem<S>& A) {
    u.resize(s.n());
    s.u.read(u);
    if (A.c_b() != 0) {
        u0.resize(s.n());
        s.damping_u.read(u0);
    } else {
        u0.clear();
    }
    definite = A.definite();
    c_m = A.c_m();
    c_k = A.c_k();
    c_b = A.c_b();
    valid = true;
}

template <class S>
void TangentPoint<S>::rebuild(const SimState<S>& s, LinearSystem<S>& A, std::unique_ptr<ElasticOperator<S>>& k0) const {
    const std::size_t n = s.n();
    BackendVector<S> x = s.template vector<S>(n), f = s.template vector<S>(n);
    if (c_b != 0) {
        if (!k0) k0 = s.backend->make_operator(s.scene.mesh, s.scene.materials, s.scene.model, s.scene.method);
        x.write(u0);
        k0->forces(x.data(), f.data(), false);
        k0->build_stiffness(s.scene.solver.definite_stiffness);
    }
    x.write(u);
    s.op->forces(x.data(), f.data(), false);
    s.op->build_stiffness(definite);
    A.set(c_m, c_k, c_b, c_b != 0 ? k0.get() : nullptr, definite);
}

template <class S>
void TangentPoint<S>::save(CheckpointWriter& w) const {
    w.value(valid);
    if (!valid) return;
    w.vector(u);
    w.vector(u0);
    w.value(definite);
    w.value(c_m);
    w.value(c_k);
    w.value(c_b);
}

template <class S>
void TangentPoint<S>::load(CheckpointReader& r, std::size_t n) {
    valid = r.value<bool>("tangent point");
    if (!valid) return;
    u = r.vector<S>("tangent point u", n);
    u0 = r.vector<S>("tangent point u0");
    definite = r.value<bool>("tangent point definite");
    c_m = r.value<double>("tangent point c_m");
    c_k = r.value<double>("tangent point c_k");
    c_b = r.value<double>("tangent point c_b");
    if (c_b != 0 && u0.size() != n) r.fail("tangent point u0", "missing");
}

template struct TangentPoint<double>;
template struct TangentPoint<float>;

}  // namespace edgefem::sim
