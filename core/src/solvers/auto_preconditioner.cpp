// The automatic choice (SolverSettings::preconditioner Auto, the default):
// block-Jacobi until one of its solves needs more than
// SolverSettings::auto_amg_iterations CG iterations; that solve goes on from
// its iterate under AMG (set up on the same K), and AMG stays to the end of
// the run. So a step too large for block-Jacobi's iteration limit does not
// fail on it. Where block-Jacobi needs few iterations (small
// steps, soft or small meshes) an iteration of it is ~16-19x cheaper than an
// AMG one and it wins; past the threshold AMG's 7-17 iterations win
// (docs/solvers.md, "Which preconditioner by default"). The switch depends on
// iteration counts only, which are the same for any thread count: so is the
// run. Never AMG with a fixed CG budget (cg_fixed_iterations: a haptic loop's
// iteration costs must stay block-Jacobi's) or off the host (AMG runs there).
#include "solvers/preconditioner.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class AutoPreconditioner final : public Preconditioner<S> {
public:
    explicit AutoPreconditioner(const SimState<S>& state)
        : s_(state), active_(make_block_jacobi(state)),
          allowed_(state.scene.solver.cg_fixed_iterations == 0 &&
                   state.backend->memory().space() == MemorySpace::Host) {}

    void setup(LinearSystem<S>& A) override { active_->setup(A); }
    void solved(int iterations, double residual) override { active_->solved(iterations, residual); }
    int switch_after() const override { return amg_ || !allowed_ ? 0 : s_.scene.solver.auto_amg_iterations; }
    void switch_now(LinearSystem<S>& A) override {
        active_ = make_amg(s_);
        amg_ = true;
        active_->setup(A);
    }
    void save(CheckpointWriter& w) const override {
        w.value(amg_);
        active_->save(w);
    }
    void load(CheckpointReader& r, LinearSystem<S>& A) override {
        const bool amg = r.value<bool>("auto preconditioner: AMG active");
        if (amg && !allowed_) r.fail("auto preconditioner", "AMG active where it cannot run");
        if (amg != amg_) active_ = amg ? make_amg(s_) : make_block_jacobi(s_);
        amg_ = amg;
        active_->load(r, A);
    }
    std::size_t bytes() const override { return active_->bytes(); }
    bool indefinite() const override { return active_->indefinite(); }
    int refreshes() const override { return active_->refreshes(); }
    void apply(std::size_t lo, std::size_t hi, const double* r, double* z) const override { active_->apply(lo, hi, r, z); }
    bool whole_vector() const override { return active_->whole_vector(); }

private:
    const SimState<S>& s_;
    std::unique_ptr<Preconditioner<S>> active_;
    const bool allowed_;
    bool amg_ = false;  // AMG has taken over
};

}  // namespace

template <class S>
std::unique_ptr<Preconditioner<S>> make_auto_preconditioner(const SimState<S>& state) {
    return std::make_unique<AutoPreconditioner<S>>(state);
}

template std::unique_ptr<Preconditioner<double>> make_auto_preconditioner(const SimState<double>&);
template std::unique_ptr<Preconditioner<float>> make_auto_preconditioner(const SimState<float>&);

}  // namespace edgefem::sim
