#include "simulator/state.hpp"

#include <algorithm>
#include <cmath>

#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/surface_load.hpp"
#include "simulator/checkpoint_stream.hpp"
#include "simulator/instability_advice.hpp"
#include "simulator/timing.hpp"

namespace edgefem::sim {

template <class S>
SimState<S>::SimState(Scene s, std::shared_ptr<const Backend<S>> back)
    : scene((s.validate(), std::move(s))),
      backend(back ? std::move(back) : make_cpu_backend<S>()),
      kernels(backend->kernels()) {
    const Mesh& mesh = scene.mesh;
    op = backend->make_operator(mesh, scene.materials, scene.model, scene.method);
    mass_host = edgefem::lumped_mass(mesh, scene.materials);
    const std::size_t nv = mass_host.size(), nd = 3 * nv;
    std::vector<double> per_dof(nd);
    for (std::size_t i = 0; i < nd; ++i) per_dof[i] = mass_host[i / 3];
    mass = vector<double>(nv);
    mass.write(mass_host);
    mass_dof = vector<double>(nd);
    mass_dof.write(per_dof);
    u = vector<S>(nd);
    v = vector<S>(nd);
    fext = vector<S>(nd);
    f = vector<S>(nd);
    std::vector<index_t> cv;
    std::vector<double> cd;
    for (index_t vtx : scene.fixed) {
        cv.push_back(vtx);
        cd.insert(cd.end(), {0.0, 0.0, 0.0});
    }
    for (const auto& p : scene.prescribed) {
        cv.push_back(p.vertex);
        for (int r = 0; r < 3; ++r) cd.push_back(p.target[r] - mesh.X[3 * std::size_t(p.vertex) + r]);
    }
    free_host.assign(nd, 1);
    for (index_t vtx : cv)
        for (int r = 0; r < 3; ++r) free_host[3 * std::size_t(vtx) + r] = 0;
    free_dof = vector<std::uint8_t>(nd);
    free_dof.write(free_host);
    con_vertex = vector<index_t>(cv.size());
    con_vertex.write(cv);
    con_disp = vector<double>(cd.size());
    con_disp.write(cd);
    for (std::size_t i = 0; i < nv; ++i)
        if (!(mass_host[i] > 0))
            throw InvalidArgument("scene: vertex " + std::to_string(i) + " has no mass (unreferenced vertex?)");
    h = vector<double>(nd);
    x = vector<double>(nd);
    b = vector<double>(nd);
    // Loads with the same keyframes are one group (the usual case: one).
    const auto group = [&](const std::vector<Keyframe>& keys) -> std::vector<double>& {
        for (LoadGroup& g : load_groups)
            if (std::equal(g.keys.begin(), g.keys.end(), keys.begin(), keys.end(),
                           [](const Keyframe& a, const Keyframe& b) { return a.time == b.time && a.value == b.value; }))
                return g.force;
        load_groups.push_back({keys, std::vector<double>(nd, 0.0)});
        return load_groups.back().force;
    };
    if (!scene.load.empty()) {
        std::vector<double>& f = group(scene.load_keyframes);
        for (std::size_t i = 0; i < nd; ++i) f[i] += scene.load[i];
    }
    for (const SurfaceLoad& sl : scene.surface_loads) add_surface_load_forces(mesh.X, sl, 1.0, group(sl.keyframes));
    scene_load = vector<double>(load_groups.empty() ? 0 : nd);
    if (!load_groups.empty()) {
        if (load_groups.size() == 1) scene_load.write(load_groups[0].force);
        fext_step = vector<S>(nd);
    }
    const auto initial = [&](BackendVector<S>& dst, const std::vector<double>& src) {
        if (src.empty()) return;
        std::vector<S> tmp(src.begin(), src.end());
        dst.write(tmp);
    };
    initial(u, scene.initial_displacement);
    initial(v, scene.initial_velocity);
}

template <class S>
void SimState<S>::copy_state(BackendVector<S>& dst, const BackendVector<S>& src) const {
    dst.resize(src.size());
    kernels.copy_state(dst.data(), src.data(), src.size());
}

template <class S>
void SimState<S>::copy_history(History<S>& dst, const History<S>& src) const {
    dst.vectors.resize(src.vectors.size());
    for (std::size_t k = 0; k < src.vectors.size(); ++k) {
        if (dst.vectors[k].size() != src.vectors[k].size()) dst.vectors[k] = vector<double>(src.vectors[k].size());
        kernels.copy(dst.vectors[k].data(), src.vectors[k].data(), src.vectors[k].size());
    }
    if (dst.u_end.size() != src.u_end.size()) dst.u_end = vector<S>(0);
    if (dst.v_end.size() != src.v_end.size()) dst.v_end = vector<S>(0);
    copy_state(dst.u_end, src.u_end);
    copy_state(dst.v_end, src.v_end);
    dst.dt = src.dt;
    dst.valid = src.valid;
}

template <class S>
double* SimState<S>::history_vector(std::size_t k) {
    while (history.vectors.size() <= k) history.vectors.push_back(vector<double>(n()));
    return history.vectors[k].data();
}

template <class S>
bool SimState<S>::history_current() const {
    return history.valid && kernels.count_differences(u.data(), history.u_end.data(), n()) == 0 &&
           kernels.count_differences(v.data(), history.v_end.data(), n()) == 0;
}

template <class S>
void SimState<S>::history_done(double dt) {
    if (history.u_end.size() != n()) history.u_end = vector<S>(0), history.v_end = vector<S>(0);
    copy_state(history.u_end, u);
    copy_state(history.v_end, v);
    history.dt = dt;
    history.valid = true;
}

template <class S>
void SimState<S>::build_damping_tangent(std::unique_ptr<ElasticOperator<S>>& op_damp) {
    if (!op_damp) op_damp = backend->make_operator(scene.mesh, scene.materials, scene.model, scene.method);
    BackendVector<S> scratch = vector<S>(n());
    op_damp->forces(u.data(), scratch.data(), false);
    op_damp->build_stiffness(scene.solver.definite_stiffness);
    if (damping_u.size() != n()) damping_u = vector<S>(n());
    copy_state(damping_u, u);
}

template <class S>
void SimState<S>::multiply(const ElasticOperator<S>& op, const double* in, double* out) {
    if constexpr (std::is_same_v<S, double>) {
        op.multiply(in, out);
    } else {
        if (product_in.size() != n()) product_in = vector<S>(n());
        if (product_out.size() != n()) product_out = vector<S>(n());
        kernels.to_state(product_in.data(), in, n());
        op.multiply(product_in.data(), product_out.data());
        kernels.from_state(out, product_out.data(), n());
    }
}

template <class S>
void SimState<S>::save(CheckpointWriter& w) const {
    w.vector(u);
    w.vector(v);
    w.vector(fext);
    w.vector(f);
    w.value(step);
    w.value(time);
    w.value(ramp_floor);
    const bool current = history_current();
    w.value(current);
    w.value(std::uint64_t(current ? history.vectors.size() : 0));
    if (current)
        for (const auto& h : history.vectors) w.vector(h);
    w.value(history.dt);
}

template <class S>
void SimState<S>::load(CheckpointReader& r) {
    r.vector(u, "displacement");
    r.vector(v, "velocity");
    r.vector(fext, "external forces");
    r.vector(f, "forces");
    step = r.value<long>("step");
    time = r.value<double>("time");
    ramp_floor = r.value<double>("ramp floor");
    const bool current = r.value<bool>("history flag");
    const auto count = r.value<std::uint64_t>("history count");
    if (count > 8) r.fail("history count", std::to_string(count));
    history.vectors.clear();
    for (std::uint64_t k = 0; k < count; ++k) {
        history.vectors.push_back(vector<double>(n()));
        r.vector(history.vectors.back(), "history vector");
    }
    history.dt = r.value<double>("history step size");
    history.valid = false;
    if (current) history_done(history.dt);
    forces_current = false;
}

template <class S>
void SimState<S>::external(double load) {
    kernels.external_load(h.data(), fext_now(), mass.data(), scene.gravity, load, n());
}

template <class S>
void SimState<S>::update_load(double t) {
    if (!scene_load.size()) return;
    b.resize(n());
    kernels.from_state(b.data(), fext.data(), n());  // b: scratch until the step's solve writes it
    double scale = 1;
    if (load_groups.size() == 1) {
        scale = keyframe_value(load_groups[0].keys, t);
    } else {  // several keyframe sets: their sum at t, on the host
        std::vector<double> sum(n(), 0.0);
        for (const LoadGroup& g : load_groups) {
            const double s = keyframe_value(g.keys, t);
            for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += s * g.force[i];
        }
        scene_load.write(sum);
    }
    kernels.line_search_point(fext_step.data(), b.data(), scene_load.data(), scale, n());
}

template <class S>
double SimState<S>::ramp(double t) const {
    if (!scene.prescribed_keyframes.empty()) return keyframe_value(scene.prescribed_keyframes, t);
    return std::max(ramp_floor, std::min(1.0, t / (scene.prescribed_steps * scene.dt) * (1 + 1e-12)));
}

template <class S>
void SimState<S>::constrained_velocities(double T, double t_end, double* vel) const {
    kernels.constrained_velocities(vel, u.data(), constraints(), ramp(t_end), T);
}

template <class S>
void SimState<S>::take_velocity(double T) {
    kernels.take_velocity(u.data(), v.data(), x.data(), T, n());
}

template <class S>
void SimState<S>::hold_constraints(double fraction) {
    kernels.hold_constraints(u.data(), constraints(), fraction);
}

template <class S>
double SimState<S>::forces(bool energy) {
    const auto t0 = Clock::now();
    const double W = op->forces(u.data(), f.data(), energy);
    stats.force_ms += ms_since(t0);
    return W;
}

template <class S>
void SimState<S>::build_stiffness() {
    const auto t0 = Clock::now();
    op->build_stiffness(scene.solver.definite_stiffness);
    stats.stiffness_ms += ms_since(t0);
}

template <class S>
void SimState<S>::start_forces() {
    if (!forces_current) forces(false);
    forces_current = false;
}

template <class S>
void SimState<S>::check_finite(long step_no) const {
    const std::size_t i = kernels.first_non_finite(u.data(), v.data(), n());
    if (i < n()) {
        std::vector<S> scratch;
        const bool u_finite = std::isfinite(double(u.read_host(scratch)[i]));
        throw StepFailure{"step " + std::to_string(step_no) + ": non-finite " +
                              (u_finite ? "velocity" : "displacement") + " at vertex " + std::to_string(i / 3) +
                              " (" + instability_advice(scene.integrator) + ")",
                          index_t(i / 3)};
    }
}

template <class S>
index_t SimState<S>::fastest_vertex() const {
    std::vector<S> scratch;
    const std::span<const S> vel = v.read_host(scratch);
    index_t best = 0;
    double top = -1;
    for (std::size_t vtx = 0; vtx < mass_host.size(); ++vtx) {
        const double s2 = double(vel[3 * vtx]) * double(vel[3 * vtx]) +
                          double(vel[3 * vtx + 1]) * double(vel[3 * vtx + 1]) +
                          double(vel[3 * vtx + 2]) * double(vel[3 * vtx + 2]);
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
