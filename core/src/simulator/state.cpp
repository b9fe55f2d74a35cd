#include "simulator/state.hpp"

#include <algorithm>
#include <cmath>

#include "edgefem/core/coefficients.hpp"
#include "simulator/timing.hpp"

namespace edgefem::sim {

template <class S>
SimState<S>::SimState(Scene s, std::shared_ptr<const Executor> e, OperatorFactory<S> make_op)
    : scene(std::move(s)), exec(std::move(e)), factory(std::move(make_op)) {
    scene.validate();
    if (!exec) exec = std::make_shared<SerialExecutor>();
    if (!factory) factory = [](const Mesh& m, const Materials& mat, ModelKind k, Method me) {
        return make_elastic_operator<S>(m, mat, k, me);
    };
    const Mesh& mesh = scene.mesh;
    op = factory(mesh, scene.materials, scene.model, scene.method);
    mass = edgefem::lumped_mass(mesh, scene.materials);
    mass_dof.resize(3 * mass.size());
    for (std::size_t i = 0; i < mass_dof.size(); ++i) mass_dof[i] = mass[i / 3];
    const std::size_t nd = 3 * std::size_t(mesh.num_vertices());
    u.assign(nd, S(0));
    v.assign(nd, S(0));
    fext.assign(nd, S(0));
    f.assign(nd, S(0));
    free_dof.assign(nd, 1);
    for (index_t vtx : scene.fixed) {
        con_vertex.push_back(vtx);
        con_disp.push_back({0, 0, 0});
    }
    for (const auto& p : scene.prescribed) {
        con_vertex.push_back(p.vertex);
        con_disp.push_back({p.target[0] - mesh.X[3 * std::size_t(p.vertex)],
                            p.target[1] - mesh.X[3 * std::size_t(p.vertex) + 1],
                            p.target[2] - mesh.X[3 * std::size_t(p.vertex) + 2]});
    }
    for (index_t vtx : con_vertex)
        for (int r = 0; r < 3; ++r) free_dof[3 * std::size_t(vtx) + r] = 0;
    for (std::size_t i = 0; i < mass.size(); ++i)
        if (!(mass[i] > 0))
            throw InvalidArgument("scene: vertex " + std::to_string(i) + " has no mass (unreferenced vertex?)");
    h.resize(nd);
    x.resize(nd);
    b.resize(nd);
}

template <class S>
void SimState<S>::external(double load) {
    each([&](std::size_t i) { h[i] = load * (mass[i / 3] * scene.gravity[i % 3] + double(fext[i])); });
}

template <class S>
double SimState<S>::ramp(double t) const {
    return std::max(ramp_floor, std::min(1.0, t / (scene.prescribed_steps * scene.dt) * (1 + 1e-12)));
}

template <class S>
void SimState<S>::constrained_velocities(double T, double t_end, double* vel) const {
    const double s = ramp(t_end);
    for (std::size_t k = 0; k < con_vertex.size(); ++k)
        for (int r = 0; r < 3; ++r) {
            const std::size_t i = 3 * std::size_t(con_vertex[k]) + r;
            vel[i] = (s * con_disp[k][r] - double(u[i])) / T;
        }
}

template <class S>
void SimState<S>::take_velocity(double T) {
    each([&](std::size_t i) {
        v[i] = S(x[i]);
        u[i] += S(T * x[i]);
    });
}

template <class S>
void SimState<S>::hold_constraints(double fraction) {
    for (std::size_t k = 0; k < con_vertex.size(); ++k)
        for (int r = 0; r < 3; ++r) u[3 * std::size_t(con_vertex[k]) + r] = S(fraction * con_disp[k][r]);
}

template <class S>
double SimState<S>::forces(bool energy) {
    const auto t0 = Clock::now();
    const double W = op->forces(u.data(), f.data(), energy);
    stats.force_ms += ms_since(t0);
    return W;
}

template <class S>
void SimState<S>::start_forces() {
    if (!forces_current) forces(false);
    forces_current = false;
}

template <class S>
void SimState<S>::check_finite(long step_no) const {
    // First non-finite dof, found block-parallel.
    const std::size_t chunks = vector_blocks(n());
    std::vector<std::size_t> first(chunks, n());
    for_blocks(*exec, n(), [&](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i)
            if (!std::isfinite(double(u[i])) || !std::isfinite(double(v[i]))) {
                first[lo / kVectorBlock] = i;
                break;
            }
    });
    const std::size_t bad = *std::min_element(first.begin(), first.end());
    if (bad < n()) {
        const std::size_t i = bad;
        throw StepFailure{"step " + std::to_string(step_no) + ": non-finite " +
                              (std::isfinite(double(u[i])) ? "velocity" : "displacement") + " at vertex " +
                              std::to_string(i / 3) + " (unstable: reduce dt or use an implicit integrator)",
                          index_t(i / 3)};
    }
}

template <class S>
index_t SimState<S>::fastest_vertex() const {
    index_t best = 0;
    double top = -1;
    for (std::size_t vtx = 0; vtx < mass.size(); ++vtx) {
        const double s2 = double(v[3 * vtx]) * double(v[3 * vtx]) + double(v[3 * vtx + 1]) * double(v[3 * vtx + 1]) +
                          double(v[3 * vtx + 2]) * double(v[3 * vtx + 2]);
        if (s2 > top) {
            top = s2;
            best = index_t(vtx);
        }
    }
    return best;
}

template struct SimState<double>;
template struct SimState<float>;

}  // namespace edgefem::sim
