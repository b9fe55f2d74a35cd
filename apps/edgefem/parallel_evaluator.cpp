// Evaluators whose kernels run on a parallel back-end (parallel/): the same
// interface as the serial ones in common.cpp, for `forces` and `bench`.
#include <memory>

#include "common.hpp"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/topology.hpp"
#include "edgefem/parallel/executors.hpp"
#include "edgefem/parallel/parallel_edge_kernels.hpp"
#include "edgefem/parallel/parallel_operator.hpp"
#include "edgefem/parallel/parallel_tet_kernels.hpp"

namespace edgefem::cli {

namespace {

inline void escape(const void* p) { asm volatile("" : : "g"(p) : "memory"); }

template <class From, class To>
void cast_into(const std::vector<From>& in, std::vector<To>& out) {
    out.assign(in.begin(), in.end());
}

template <class S>
EdgeModel<S> edge_model(const Mesh& mesh, const Materials& mat) {
    const Topology topo = build_topology(mesh);
    return make_edge_model<S>(topo, compute_coefficients(mesh, topo, mat));
}

template <class S, ModelKind Kind>
class ParallelEdgeEvaluator final : public Evaluator {
public:
    ParallelEdgeEvaluator(const Mesh& mesh, const Materials& mat, std::shared_ptr<const Executor> ex, Variant v)
        : k_(edge_model<S>(mesh, mat), std::move(ex), v) {
        const std::size_t n = 3 * std::size_t(k_.model().num_vertices);
        u_.assign(n, S(0));
        f_.assign(n, S(0));
        x_.assign(n, S(0));
        y_.assign(n, S(0));
        k_.resize(K_);
    }
    void set_displacement(const std::vector<double>& u) override { cast_into(u, u_); }
    double energy_forces(std::vector<double>& f) override {
        const double W = k_.template forces<Kind, true>(u_.data(), f_.data(), state_);
        cast_into(f_, f);
        return W;
    }
    void stiffness_times(const std::vector<double>& x, std::vector<double>& y) override {
        prepare(Kernel::Kx, x);
        run(Kernel::Kx);
        cast_into(y_, y);
    }
    void prepare(Kernel kernel, const std::vector<double>& x) override {
        cast_into(x, x_);
        if (kernel == Kernel::Stiffness || kernel == Kernel::Kx)
            k_.template forces<Kind, false>(u_.data(), f_.data(), state_);
        if (kernel == Kernel::Kx) k_.template stiffness<Kind>(state_, K_);
    }
    void run(Kernel kernel) override {
        switch (kernel) {
            case Kernel::Force: k_.template forces<Kind, false>(u_.data(), f_.data(), state_); break;
            case Kernel::Stiffness: k_.template stiffness<Kind>(state_, K_); break;
            case Kernel::ForceStiffness:
                k_.template forces<Kind, false>(u_.data(), f_.data(), state_);
                k_.template stiffness<Kind>(state_, K_);
                break;
            case Kernel::Kx: k_.multiply(K_, x_.data(), y_.data()); break;
        }
    }
    void consume() override {
        escape(f_.data());
        escape(K_.K.data());
        escape(y_.data());
    }

private:
    ParallelEdgeKernels<S> k_;
    EdgeState<S> state_;
    EdgeStiffness<S> K_;
    std::vector<S> u_, f_, x_, y_;
};

template <class S>
class ParallelTetEvaluator final : public Evaluator {
public:
    ParallelTetEvaluator(const Mesh& mesh, const Materials& mat, std::shared_ptr<const Executor> ex, Variant v)
        : k_(make_tet_model<S>(mesh, mat), std::move(ex), v) {
        const std::size_t n = 3 * std::size_t(k_.model().num_vertices);
        u_.assign(n, S(0));
        f_.assign(n, S(0));
        x_.assign(n, S(0));
        y_.assign(n, S(0));
    }
    void set_displacement(const std::vector<double>& u) override { cast_into(u, u_); }
    double energy_forces(std::vector<double>& f) override {
        const double W = k_.template forces<true>(u_.data(), f_.data());
        cast_into(f_, f);
        return W;
    }
    void stiffness_times(const std::vector<double>& x, std::vector<double>& y) override {
        prepare(Kernel::Kx, x);
        run(Kernel::Kx);
        cast_into(y_, y);
    }
    void prepare(Kernel kernel, const std::vector<double>& x) override {
        cast_into(x, x_);
        if (kernel == Kernel::Kx) k_.stiffness(u_.data(), K_);
    }
    void run(Kernel kernel) override {
        switch (kernel) {
            case Kernel::Force: k_.template forces<false>(u_.data(), f_.data()); break;
            case Kernel::Stiffness: k_.stiffness(u_.data(), K_); break;
            case Kernel::ForceStiffness:
                k_.template forces<false>(u_.data(), f_.data());
                k_.stiffness(u_.data(), K_);
                break;
            case Kernel::Kx: k_.multiply(K_, x_.data(), y_.data()); break;
        }
    }
    void consume() override {
        escape(f_.data());
        escape(K_.K.data());
        escape(y_.data());
    }

private:
    ParallelTetKernels<S> k_;
    TetStiffness<S> K_;
    std::vector<S> u_, f_, x_, y_;
};

template <class S>
std::unique_ptr<Evaluator> make_parallel_as(const Mesh& mesh, const ModelOptions& opts, const ExecOptions& exec) {
    const Materials mat(opts.material);
    const auto ex = exec.executor();
    const Variant v = parse_variant(exec.variant);
    if (opts.method_kind() == Method::Tet) return std::make_unique<ParallelTetEvaluator<S>>(mesh, mat, ex, v);
    if (opts.kind() == ModelKind::SN) return std::make_unique<ParallelEdgeEvaluator<S, ModelKind::SN>>(mesh, mat, ex, v);
    return std::make_unique<ParallelEdgeEvaluator<S, ModelKind::FE>>(mesh, mat, ex, v);
}

}  // namespace

std::unique_ptr<Evaluator> make_evaluator(const Mesh& mesh, const ModelOptions& opts, const ExecOptions& exec) {
    if (!exec.parallel_kernels()) return make_evaluator(mesh, opts);
    if (opts.precision_kind() == Precision::Float) return make_parallel_as<float>(mesh, opts, exec);
    return make_parallel_as<double>(mesh, opts, exec);
}

template <class S>
OperatorFactory<S> operator_factory(const ExecOptions& exec, const std::shared_ptr<const Executor>& executor) {
    if (!exec.parallel_kernels()) return {};
    return parallel_operator_factory<S>(executor, parse_variant(exec.variant));
}

template OperatorFactory<double> operator_factory<double>(const ExecOptions&, const std::shared_ptr<const Executor>&);
template OperatorFactory<float> operator_factory<float>(const ExecOptions&, const std::shared_ptr<const Executor>&);

}  // namespace edgefem::cli
