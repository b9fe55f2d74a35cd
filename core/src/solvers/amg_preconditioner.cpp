// The AMG preconditioner: SmoothedAggregation (smoothed_aggregation.hpp) on
// A = c_m M + c_k K (+ c_b K0). The hierarchy (aggregates, prolongators) is
// built at the first set-up from the body's positions there and the edge
// graph, and kept until a refresh no longer brings the iterations per decade
// back within kRebuild of those after the build (then rebuilt on the
// positions of the K being set up: SmoothedAggregation::rebuild, the first
// build's aggregates and patterns, the prolongators' values anew);
// a refresh assembles A into its fixed pattern (SystemMatrix, whose values
// are freed again afterwards) and recomputes the Galerkin operators,
// smoothers and the coarsest factorisation: at every
// amg_refresh_interval-th K, or (0) lagged while CG's iterations per decade
// of residual reduction stay within 1.5x (+ 2 iterations) of those after
// the last refresh; under either, also where the coefficients (the step
// size) changed or the coarsest level was indefinite (an indefinite
// one is reported as negative curvature: Preconditioner::indefinite). A
// refresh that is stale in the very next solve (K changes that fast: soft
// material, long steps) makes the next kEagerSetups set-ups refresh
// without waiting for a stale solve, then one is skipped again to see
// whether K has settled (the probe). The
// finest level's products are the LinearSystem's
// matrix-free ones (the per-edge K on the back-end's executor). A
// whole-vector preconditioner: one V-cycle per CG iteration. On the host,
// on the back-end's executor (Backend::executor()) when it has one.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "edgefem/core/smoothed_aggregation.hpp"
#include "solvers/preconditioner.hpp"
#include "solvers/system_matrix.hpp"
#include "solvers/tangent_point.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class Amg final : public Preconditioner<S> {
public:
    explicit Amg(const SimState<S>& state) : s_(state), ex_(state.backend->executor()), matrix_(state) {
        for (std::size_t i = 0; i < s_.free_host.size(); ++i)
            if (!s_.free_host[i]) fixed_.push_back(i);
        matrix_.keep(false, true);
        amg_.set_executor(ex_);  // the back-end's threads, bitwise as serial
    }

    void setup(LinearSystem<S>& A) override {
        A_ = &A;
        const int interval = s_.scene.solver.amg_refresh_interval;
        const std::array<double, 3> c{A.c_m(), A.c_k(), A.c_b()};
        ++age_;
        // Under any interval, refreshed at the next set-up where the coarsest
        // level was indefinite (that set-up is the definite K the step falls
        // back to) or where the coefficients changed (another step size, or
        // BDF2's first step after its backward Euler one): a smoother made
        // for c_m M + K is no smoother for 2.25 c_m M + K. D^-1 A's spectrum
        // then reaches past the Chebyshev bound, the V-cycle is indefinite
        // and CG stalled (r.z < 0 from its first iteration; 2,000 iterations
        // at a relative residual of 3e-4).
        const bool due = amg_.coarsest_indefinite() || c != c_ ||
                         (interval > 0 ? age_ >= interval : stale_ || eager_ > 0);
        if (eager_ > 0) --eager_;
        if (built_ && !due) return;
        // Built again (on the positions now) where a refresh no longer brings
        // the iterations back to those after the build: the body has moved or
        // deformed far from where the prolongators were made.
        refresh(A, c, !built_ || rebuild_ || (built_rate_ > 0 && fresh_rate_ > kRebuild * built_rate_));
    }

    bool indefinite() const override { return amg_.coarsest_indefinite(); }
    double iteration_cost() const override { return 1 + amg_.cycle_cost(); }
    int refreshes() const override { return refreshes_; }
    int rebuilds() const override { return builds_; }

    // A lagged AMG's solve that has gone far past the iterations after its
    // last refresh (3x + 10) refreshes on the A being solved and goes on
    // from its iterate: a hierarchy made stale by a large change of K can
    // need hundreds of times the iterations (a soft beam folding at 33 ms
    // steps: 728 and 4,022 where a fresh one takes 11). Before a fresh
    // solve has been measured (`auto`'s first AMG solve after its switch,
    // which continued a block-Jacobi solve) on a hierarchy older than this
    // set-up, past solver.auto_amg_iterations: the count at which
    // block-Jacobi is deemed too slow, where a fresh AMG takes 4-19 (a
    // released beam of 2.5 mm cells at 2 ms: 464 iterations on the
    // hierarchy of the step before, 42 refreshed). A hierarchy made for
    // this A is never refreshed part way.
    int switch_after() const override {
        if (s_.scene.solver.amg_refresh_interval != 0 || age_ == 0) return 0;
        return fresh_its_ > 0 ? 3 * fresh_its_ + 10 : s_.scene.solver.auto_amg_iterations;
    }
    void switch_now(LinearSystem<S>& A, double /*residual*/) override {
        const bool young = age_ == 1;  // stale one set-up after a refresh: K changes that fast
        refresh(A, {A.c_m(), A.c_k(), A.c_b()}, false);
        skip_ = true;  // the rest of this solve starts from its iterate: no fresh rate
        if (young) eager_ = kEagerSetups;
    }

    // Per decade of the residual reduction reached, so that Newton's
    // solves, whose tolerances change from one iteration to the next (the
    // forcing term), do not look stale whenever one asks for more digits
    // than the solve after the refresh did (which refreshed at nearly every
    // Newton iteration). A semi-implicit step's solves all ask for the same
    // tolerance: for them it is the iteration count as before.
    void solved(int iterations, double residual) override {
        if (skip_) {
            skip_ = false;
            return;
        }
        const double decades = residual_decades(residual);
        // The solve right after a set-up's refresh (or, with none measured
        // yet, the first whole solve since).
        if (measure_ && (age_ == 0 || fresh_rate_ < 0)) {
            measure_ = false;
            fresh_rate_ = iterations / decades;
            fresh_its_ = iterations;
            if (built_rate_ < 0) built_rate_ = fresh_rate_;  // the first since the build
        } else if (fresh_rate_ >= 0 && iterations > 1.5 * fresh_rate_ * decades + 2) {
            stale_ = true;
            if (age_ == 1) eager_ = kEagerSetups;  // the refresh lived one set-up
        }
    }

    // Built again at the next set-up, on the positions there: the body has
    // moved on while block-Jacobi served ("auto"), and a refresh alone would
    // keep rigid-body modes and aggregates of where it was (a soft beam
    // folding at 33 ms steps: 23-29 iterations per step after such a
    // refresh, 15-16 rebuilt; a rebuild costs about 1.2 refreshes).
    void invalidate() override { stale_ = rebuild_ = true; }

    // The hierarchy and the last refresh are rebuilt from the points they
    // were made at (the matrices would take ~100x the space).
    void save(CheckpointWriter& w) const override {
        w.value(built_);
        w.value(c_);
        w.value(age_);
        w.value(stale_);
        w.value(fresh_rate_);
        w.value(eager_);
        w.value(fresh_its_);
        w.value(measure_);
        w.value(skip_);
        w.value(built_rate_);
        w.value(builds_);
        w.value(rebuild_);
        built_at_.save(w);
        rebuilt_at_.save(w);
        refreshed_at_.save(w);
    }
    void load(CheckpointReader& r, LinearSystem<S>& A) override {
        built_ = r.value<bool>("AMG built");
        c_ = r.value<std::array<double, 3>>("AMG coefficients");
        age_ = r.value<int>("AMG age");
        stale_ = r.value<bool>("AMG stale");
        fresh_rate_ = r.value<double>("AMG iterations per decade");
        eager_ = r.value<int>("AMG eager set-ups");
        if (eager_ < 0 || eager_ > kEagerSetups) r.fail("AMG", "eager set-ups out of range");
        fresh_its_ = r.value<int>("AMG iterations after the refresh");
        measure_ = r.value<bool>("AMG measure flag");
        skip_ = r.value<bool>("AMG skip flag");
        built_rate_ = r.value<double>("AMG iterations per decade after the build");
        builds_ = r.value<int>("AMG builds");
        rebuild_ = r.value<bool>("AMG rebuild flag");
        built_at_.load(r, s_.n());
        rebuilt_at_.load(r, s_.n());
        refreshed_at_.load(r, s_.n());
        if (built_ != built_at_.valid) r.fail("AMG", "built without its point");
        if (rebuilt_at_.valid && !built_) r.fail("AMG", "rebuilt but not built");
        A_ = &A;
        if (!built_) return;
        std::unique_ptr<ElasticOperator<S>> k0;
        built_at_.rebuild(s_, A, k0);
        matrix_.assemble(A);
        amg_.build(matrix_.projected(), positions(built_at_), s_.free_host, s_.scene.solver.amg);
        amg_.release_build_data();
        matrix_.release();
        if (rebuilt_at_.valid) {
            rebuilt_at_.rebuild(s_, A, k0);
            matrix_.assemble(A);
            amg_.rebuild(matrix_.projected(), positions(rebuilt_at_));
            matrix_.release();
        }
        if (!refreshed_at_.valid) return;
        refreshed_at_.rebuild(s_, A, k0);
        matrix_.assemble(A);
        amg_.refresh(matrix_.projected());
        matrix_.release();
    }

    bool whole_vector() const override { return true; }

    void apply(std::size_t lo, std::size_t hi, const double* r, double* z) const override {
        if (lo != 0 || hi != s_.n()) throw InvalidArgument("AMG preconditioner: applies to the whole vector only");
        amg_.apply(r, z, [&](const double* x, double* y) {
            A_->apply(x, y);
            for (const std::size_t i : fixed_) y[i] = 0;  // the hierarchy's rows of fixed dofs are zero
        });
    }

    std::size_t bytes() const override { return amg_.bytes() + matrix_.bytes(); }

private:
    // Builds the hierarchy (on the positions now) or refreshes its
    // operators on A.
    void refresh(LinearSystem<S>& A, const std::array<double, 3>& c, bool build) {
        matrix_.assemble(A);
        if (build && !built_) {
            built_at_.record(s_, A);
            amg_.build(matrix_.projected(), positions(built_at_), s_.free_host, s_.scene.solver.amg);
            amg_.release_build_data();
            rebuilt_at_.valid = refreshed_at_.valid = false;
        } else if (build) {  // on the first build's aggregates and patterns: about a refresh's cost
            rebuilt_at_.record(s_, A);
            amg_.rebuild(matrix_.projected(), positions(rebuilt_at_));
            refreshed_at_.valid = false;
        } else {
            amg_.refresh(matrix_.projected());
            refreshed_at_.record(s_, A);
        }
        if (build) {
            built_rate_ = -1;
            ++builds_;
        }
        matrix_.release();  // assembled again at the next refresh
        ++refreshes_;
        built_ = true;
        c_ = c;
        age_ = 0;
        stale_ = rebuild_ = false;
        measure_ = true;
    }

    // The vertices' positions at a point: the rigid-body modes the
    // hierarchy is built on are those of the body as it is there (a body
    // rotated from its rest shape has its rest modes rotated too: about the
    // rest shape they are no near-nullspace of its K).
    std::vector<double> positions(const TangentPoint<S>& at) const {
        std::vector<double> x(s_.scene.mesh.X);
        for (std::size_t i = 0; i < x.size() && i < at.u.size(); ++i) x[i] += double(at.u[i]);
        return x;
    }

    static constexpr double kRebuild = 1.5;  // fresh iterations per decade over those after the build that rebuild
    static constexpr int kEagerSetups = 4;  // refreshes in a row after a one-set-up-old refresh was stale
    const SimState<S>& s_;
    std::shared_ptr<const Executor> ex_;  // the back-end's threads (null: serial)
    SystemMatrix<S> matrix_;
    SmoothedAggregation amg_;
    std::vector<std::size_t> fixed_;  // the dofs free_host marks fixed (the finest products zero them)
    LinearSystem<S>* A_ = nullptr;
    bool built_ = false;
    std::array<double, 3> c_{};  // c_m, c_k, c_b at the last refresh
    int age_ = 0;                // set-ups since the last refresh
    bool stale_ = false;         // the iterations grew: refresh at the next K
    bool rebuild_ = false;       // invalidated: build again at the next K
    // CG's iterations (per decade, and of the solve) right after the last
    // refresh that was followed by a whole solve (-1 and 0: none yet).
    double fresh_rate_ = -1;
    int fresh_its_ = 0;
    bool measure_ = false;       // the next solve after a set-up's refresh measures them
    int eager_ = 0;              // set-ups still to refresh without waiting for a stale solve
    bool skip_ = false;          // the solve under way refreshed part way: it measures nothing
    double built_rate_ = -1;     // the fresh rate measured after the last build (-1: not yet)
    int builds_ = 0;             // builds so far (the first and the rebuilds)
    int refreshes_ = 0;          // builds and refreshes so far
    // Where the hierarchy was built (its aggregates), last rebuilt (valid:
    // since the build) and last refreshed (checkpoints).
    TangentPoint<S> built_at_, rebuilt_at_, refreshed_at_;
};

}  // namespace

template <class S>
std::unique_ptr<Preconditioner<S>> make_amg(const SimState<S>& state) {
    // Its levels read and write r and z on the host.
    if (state.backend->memory().space() != MemorySpace::Host)
        throw InvalidArgument(std::string("solver.preconditioner: amg runs on the host; the ") + state.backend->name() +
                              " back-end's vectors are not in host memory (use block-jacobi)");
    return std::make_unique<Amg<S>>(state);
}

template std::unique_ptr<Preconditioner<double>> make_amg(const SimState<double>&);
template std::unique_ptr<Preconditioner<float>> make_amg(const SimState<float>&);

}  // namespace edgefem::sim
