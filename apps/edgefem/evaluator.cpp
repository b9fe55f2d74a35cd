// The one Evaluator of `forces` and `bench`: any elastic model through its
// ElasticOperator, on core's serial kernels or a parallel back-end.
#include <memory>

#include "common.hpp"
#include "timing.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/cpu_operator.hpp"

namespace edgefem::cli {

namespace {

// Any elastic model (edge FE/SN or per-tet; serial or parallel kernels)
// through its ElasticOperator; doubles at the interface, the kernel's scalar
// inside, converted once outside the timed calls.
template <class S>
class OperatorEvaluator final : public Evaluator {
public:
    explicit OperatorEvaluator(std::unique_ptr<ElasticOperator<S>> op)
        : op_(std::move(op)), u_(3 * std::size_t(op_->num_vertices()), S(0)), f_(u_.size()), x_(u_.size()), y_(u_.size()) {}

    void set_displacement(const std::vector<double>& u) override { u_.assign(u.begin(), u.end()); }
    double energy_forces(std::vector<double>& f) override {
        const double W = op_->forces(u_.data(), f_.data(), true);
        f.assign(f_.begin(), f_.end());
        return W;
    }
    void stiffness_times(const std::vector<double>& x, std::vector<double>& y) override {
        prepare(Kernel::Kx, x);
        run(Kernel::Kx);
        y.assign(y_.begin(), y_.end());
    }
    // stiffness and kx start from the state of a force call; kx also from a
    // precomputed K.
    void prepare(Kernel kernel, const std::vector<double>& x) override {
        x_.assign(x.begin(), x.end());
        op_->keep_state(kernel != Kernel::Force);  // a force-only loop builds no K
        if (kernel == Kernel::Stiffness || kernel == Kernel::Kx) op_->forces(u_.data(), f_.data(), false);
        if (kernel == Kernel::Kx) op_->build_stiffness(false);
    }
    void run(Kernel kernel) override {
        switch (kernel) {
            case Kernel::Force: op_->forces(u_.data(), f_.data(), false); break;
            case Kernel::Stiffness: op_->build_stiffness(false); break;
            case Kernel::ForceStiffness:
                op_->forces(u_.data(), f_.data(), false);
                op_->build_stiffness(false);
                break;
            case Kernel::Kx: op_->multiply(x_.data(), y_.data()); break;
        }
    }
    void consume() override {
        escape(f_.data());
        escape(y_.data());
    }
    bool forces_from_tet_local_form() const override { return op_->forces_from_tet_local_form(); }
    bool forces_stored_state() const override { return op_->forces_stored_state(); }

private:
    std::unique_ptr<ElasticOperator<S>> op_;
    std::vector<S> u_, f_, x_, y_;
};

template <class S>
std::unique_ptr<Evaluator> make_evaluator_as(const Mesh& mesh, const ModelOptions& opts, const ExecOptions& exec) {
    const edgefem::Method method = opts.method_kind() == Method::Tet ? edgefem::Method::Tet : edgefem::Method::Edge;
    const OperatorFactory<S> factory = operator_factory<S>(exec, exec.executor(), opts.layout_kind());
    return std::make_unique<OperatorEvaluator<S>>(factory(mesh, opts.material, opts.kind(), method));
}

}  // namespace

std::unique_ptr<Evaluator> make_evaluator(const Mesh& mesh, const ModelOptions& opts, const ExecOptions& exec) {
    if (opts.precision_kind() == Precision::Float) return make_evaluator_as<float>(mesh, opts, exec);
    return make_evaluator_as<double>(mesh, opts, exec);
}

template <class S>
OperatorFactory<S> operator_factory(const ExecOptions& exec, const std::shared_ptr<const Executor>& executor,
                                    StiffnessLayout layout) {
    // The serial loops unless a threaded back-end or a variant is asked for.
    return cpu_operator_factory<S>({exec.parallel_kernels() ? executor : nullptr, parse_variant(exec.variant), layout});
}

template OperatorFactory<double> operator_factory<double>(const ExecOptions&, const std::shared_ptr<const Executor>&,
                                                          StiffnessLayout);
template OperatorFactory<float> operator_factory<float>(const ExecOptions&, const std::shared_ptr<const Executor>&,
                                                        StiffnessLayout);

}  // namespace edgefem::cli
