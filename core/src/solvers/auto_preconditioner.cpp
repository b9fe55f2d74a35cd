// The automatic choice (SolverSettings::preconditioner Auto, the default):
// block-Jacobi until one of its solves needs more than a threshold of CG
// iterations (at first SolverSettings::auto_amg_iterations); that solve goes
// on from its iterate under AMG (set up on the same K). Where block-Jacobi
// needs few iterations (small steps, soft or small meshes) an iteration of it
// is ~6-11x cheaper than an AMG one and it wins; past the threshold AMG's
// 7-17 iterations win (docs/solvers.md, "Which preconditioner by default").
// So a step too large for block-Jacobi's iteration limit does not fail on it.
//
// AMG then stays while it costs less than block-Jacobi. Costs are counted,
// not timed, in block-Jacobi CG iterations per decade of residual
// reduction: an AMG iteration as many as its V-cycle's products with the
// finest level's matrix, plus one (Preconditioner::iteration_cost, from the
// hierarchy's sizes: 6.9 on box-1200, 9.2-10.9 on the beam, bunny-4k and
// bunny-50k, within 0.8-1.2x of the measured ratios), a refresh of its
// operators kRefresh (350: a tuned value; docs/solvers.md), a rebuild of its
// hierarchy kBuild (the first build is the switch's set-up: not counted). Where K changes
// so much from step to step that the AMG refreshes at nearly every step
// (soft material, long steps), or where its iterations grow (a body folded
// far from its rest shape), a solve under AMG can cost more than one under
// block-Jacobi. Block-Jacobi's cost is known from its last whole solve; of
// the solve it gave up, only its rate up to the threshold (the iterations
// extrapolated to the solve's decades, kept within 1-3x the threshold). When the AMG's
// cost over its last kWindow solves exceeds that (or, before there are
// that many, as soon as two or more cost kMargin x that: a trial should
// cost a few solves, not a window's), the next set-up goes back to
// block-Jacobi, whose threshold becomes the AMG's cost per solve (with a
// margin): a block-Jacobi solve that stays under it was the cheaper one, one
// that goes past it changes to AMG again (built again on the body as it is
// if block-Jacobi served more than one set-up), which then has the higher
// bound to beat.
// That bound comes from solves that may have been the body's early
// transient, when the lagged AMG refreshes at every step (a soft beam
// folding under long steps: 500-800 units per solve in its first 15 steps,
// 250 after, against block-Jacobi's 360). So after kHold block-Jacobi
// set-ups the threshold goes back to the first one, and AMG is tried again
// if its last stint was a transient, its cost per solve at least
// kTransient x its cheapest solve's (refreshes, stale solves: a K that
// changed fast), and that cheapest solve cost less than block-Jacobi's
// last. Where the AMG's cost was steady and still dearer (bunny-50k at
// 1e4 Pa and 4 ms: 8-13 iterations per solve, no refresh, 1.0-1.6x
// block-Jacobi's 90), or where even its cheapest solve was dearer (few
// block-Jacobi iterations), no trial is paid. Each going back
// doubles the wait, so where the trials fail they cost a few per cent of a
// run, at most log2(steps / kHold) of them.
// Counts and residuals are the same for any thread count, so is every switch
// and the run. Never AMG with a fixed CG budget (cg_fixed_iterations: a
// haptic loop's iteration costs must stay block-Jacobi's) or off the host
// (AMG runs there).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "solvers/preconditioner.hpp"

namespace edgefem::sim {

namespace {

// block-Jacobi iterations per AMG refresh: measured 230-430 when it was
// chosen, 105-210 since the Galerkin product went block by block
// (2026-11-28); 175 made `auto` 1.21-1.29x the best in two cells of
// docs/solvers.md's table where 350 gives 1.02-1.11 (bunny-4k at 1e6 Pa
// and 4 ms, bunny-50k at 1e4 Pa and 33 ms; lab/2026-11-28-coarsest-solve.md):
// kept as a tuned value
constexpr double kRefresh = 350;
constexpr double kBuild = 420;        // and per rebuild of its hierarchy (SmoothedAggregation::rebuild: measured
                                      // 1.13-1.36 refreshes then, 1.24-1.47 now; the first, whole build, 1.7-1.8
                                      // then, 2.2-2.5 now, is paid at the switch)
constexpr int kWindow = 8;            // AMG solves its cost is judged over
constexpr double kMargin = 1.25;      // block-Jacobi's new threshold: this times the AMG's cost per solve
constexpr int kHold = 8;              // block-Jacobi set-ups after the first going back before AMG may be tried again
constexpr int kMaxHold = 1 << 24;     // doubled at each going back up to this (a driven 300-step Newton run went
                                      // back 28 times: 8 x 2^28 overflowed an int)
constexpr double kTransient = 1.5;    // a stint's cost per solve over its cheapest one's that may be a transient

template <class S>
class AutoPreconditioner final : public Preconditioner<S> {
public:
    explicit AutoPreconditioner(const SimState<S>& state)
        : s_(state), bj_(make_block_jacobi(state)), active_(bj_.get()),
          allowed_(state.scene.solver.cg_fixed_iterations == 0 &&
                   state.backend->memory().space() == MemorySpace::Host),
          threshold_(state.scene.solver.auto_amg_iterations) {}

    void setup(LinearSystem<S>& A) override {
        if (back_) {  // decided by the last solve; here, so that block-Jacobi is set up before it is used
            back_ = false;
            active_ = bj_.get();
            bj_setups_ = 0;
        }
        if (!on_amg()) {
            ++bj_setups_;
            // The wait after a going back is over: AMG may be tried again
            // (the next solve past the first threshold) if it could win.
            if (wait_ > 0 && --wait_ == 0 && bj_rate_ > floor_) threshold_ = s_.scene.solver.auto_amg_iterations;
        }
        active_->setup(A);
    }

    int switch_after() const override { return on_amg() ? amg_->switch_after() : allowed_ ? threshold_ : 0; }

    void switch_now(LinearSystem<S>& A, double residual) override {
        if (on_amg()) return amg_->switch_now(A, residual);  // its refresh part way
        switch_decades_ = residual_decades(residual, 0.05);
        if (!amg_) amg_ = make_amg(s_);
        else if (bj_setups_ > 1) amg_->invalidate();  // its hierarchy is that of an older K and body
        active_ = amg_.get();
        active_->setup(A);
        seen_ = amg_->refreshes();
        seen_builds_ = amg_->rebuilds();
        count_ = 0;
        floor_ = std::numeric_limits<double>::infinity();
        stint_cost_ = stint_decades_ = 0;
        wait_ = 0;
        just_switched_ = true;
    }

    void solved(int iterations, double residual) override {
        const double d = residual_decades(residual);
        if (!on_amg()) {
            bj_->solved(iterations, residual);
            bj_rate_ = iterations / d;
            return;
        }
        const int refreshed = amg_->refreshes() - seen_, built = amg_->rebuilds() - seen_builds_;
        seen_ = amg_->refreshes();
        seen_builds_ = amg_->rebuilds();
        if (just_switched_) {
            // Block-Jacobi would have needed more than its threshold: at its
            // rate so far, threshold x (the decades reached) / (those it had
            // reached), taken between 1x and 3x the threshold (CG's residual
            // is not monotone: a stalled start would extrapolate to any
            // count). Of this solve's AMG part, its set-up is paid, and the
            // AMG is not told it: it started from block-Jacobi's iterate, so
            // its few iterations are no rate for the lagged AMG's staleness
            // test to compare later solves with. Block-Jacobi's last whole
            // solve (one before a trial after a going back) is a rate known,
            // not extrapolated: at least that.
            just_switched_ = false;
            bj_rate_ = std::max(bj_rate_,
                                std::clamp(threshold_ * d / switch_decades_, double(threshold_), 3.0 * threshold_) / d);
            return;
        }
        amg_->solved(iterations, residual);
        const double per_iteration = amg_->iteration_cost() / bj_->iteration_cost();
        const double solve_cost = iterations * per_iteration + (refreshed - built) * kRefresh + built * kBuild;
        floor_ = std::min(floor_, solve_cost / d);
        stint_cost_ += solve_cost;
        stint_decades_ += d;
        window_[std::size_t(count_ % kWindow)] = {solve_cost, d};
        ++count_;
        // Over the last kWindow solves; before there are that many, as soon
        // as the ones so far cost more than block-Jacobi's rate would over
        // the whole window (the rest counted at this solve's decades, free),
        // or, from two on, kMargin x more than it would over them.
        const int n = std::min(count_, kWindow);
        double cost = 0, seen = 0;
        for (int i = 0; i < n; ++i) {
            cost += window_[std::size_t(i)][0];
            seen += window_[std::size_t(i)][1];
        }
        const bool dear = cost > bj_rate_ * (seen + (kWindow - n) * d) ||
                          (n >= 2 && n < kWindow && cost > kMargin * bj_rate_ * seen);
        if (!dear) return;
        back_ = true;
        const double per_solve = kMargin * cost / n;
        const int cap = s_.scene.solver.cg_max_iterations * 4 / 5;
        threshold_ = std::max(s_.scene.solver.auto_amg_iterations, int(std::min<double>(cap, std::ceil(per_solve))));
        hold_ = hold_ == 0 ? kHold : 2 * std::min(hold_, kMaxHold / 2);
        wait_ = hold_;
        if (stint_cost_ < kTransient * floor_ * stint_decades_) floor_ = std::numeric_limits<double>::infinity();
    }

    void save(CheckpointWriter& w) const override {
        w.value(on_amg());
        w.value(bool(amg_));
        w.value(back_);
        w.value(just_switched_);
        w.value(threshold_);
        w.value(bj_rate_);
        w.value(seen_);
        w.value(seen_builds_);
        w.value(count_);
        w.value(bj_setups_);
        w.value(hold_);
        w.value(wait_);
        w.value(floor_);
        w.value(stint_cost_);
        w.value(stint_decades_);
        for (const auto& [c, e] : window_) {
            w.value(c);
            w.value(e);
        }
        bj_->save(w);
        if (amg_) amg_->save(w);
    }
    void load(CheckpointReader& r, LinearSystem<S>& A) override {
        const bool on_amg = r.value<bool>("auto preconditioner: AMG active");
        const bool has_amg = r.value<bool>("auto preconditioner: AMG made");
        if ((on_amg || has_amg) && !allowed_) r.fail("auto preconditioner", "AMG where it cannot run");
        if (on_amg && !has_amg) r.fail("auto preconditioner", "AMG active but not made");
        back_ = r.value<bool>("auto preconditioner: going back");
        just_switched_ = r.value<bool>("auto preconditioner: just switched");
        threshold_ = r.value<int>("auto preconditioner: threshold");
        if (threshold_ < 1) r.fail("auto preconditioner", "threshold below 1");
        bj_rate_ = r.value<double>("auto preconditioner: block-Jacobi rate");
        seen_ = r.value<int>("auto preconditioner: refreshes seen");
        seen_builds_ = r.value<int>("auto preconditioner: builds seen");
        count_ = r.value<int>("auto preconditioner: AMG solves");
        if (count_ < 0) r.fail("auto preconditioner", "negative AMG solve count");
        bj_setups_ = r.value<int>("auto preconditioner: block-Jacobi set-ups");
        hold_ = r.value<int>("auto preconditioner: hold");
        wait_ = r.value<int>("auto preconditioner: wait");
        if (hold_ < 0 || hold_ > kMaxHold || wait_ < 0 || wait_ > hold_)
            r.fail("auto preconditioner", "hold or wait out of range");
        floor_ = r.value<double>("auto preconditioner: AMG floor");
        stint_cost_ = r.value<double>("auto preconditioner: AMG stint cost");
        stint_decades_ = r.value<double>("auto preconditioner: AMG stint decades");
        if (!(floor_ >= 0) || !(stint_cost_ >= 0) || !(stint_decades_ >= 0) || std::isinf(stint_cost_) ||
            std::isinf(stint_decades_))
            r.fail("auto preconditioner", "AMG floor or stint out of range");
        for (auto& [c, e] : window_) {
            c = r.value<double>("auto preconditioner: AMG cost");
            e = r.value<double>("auto preconditioner: AMG decades");
        }
        bj_->load(r, A);
        if (has_amg) {
            if (!amg_) amg_ = make_amg(s_);
            amg_->load(r, A);
        } else {
            amg_.reset();
        }
        active_ = on_amg ? amg_.get() : bj_.get();
    }

    std::size_t bytes() const override { return bj_->bytes() + (amg_ ? amg_->bytes() : 0); }
    bool indefinite() const override { return active_->indefinite(); }
    int refreshes() const override { return amg_ ? amg_->refreshes() : 0; }
    void apply(std::size_t lo, std::size_t hi, const double* r, double* z) const override { active_->apply(lo, hi, r, z); }
    bool whole_vector() const override { return active_->whole_vector(); }

private:
    bool on_amg() const { return active_ == amg_.get(); }

    const SimState<S>& s_;
    std::unique_ptr<Preconditioner<S>> bj_, amg_;  // the AMG made at the first switch, kept (its hierarchy) after it
    Preconditioner<S>* active_;
    const bool allowed_;
    int threshold_;              // block-Jacobi iterations of one solve after which AMG takes over
    double bj_rate_ = 0;         // block-Jacobi's iterations per decade: its last whole solve, or a lower bound
    bool back_ = false;          // the next set-up goes back to block-Jacobi
    bool just_switched_ = false; // the solve under way changed to AMG
    double switch_decades_ = 1;  // the decades block-Jacobi had reached in it (not saved: within a solve)
    int seen_ = 0, seen_builds_ = 0;  // the AMG's refreshes and builds counted so far
    int count_ = 0;              // AMG solves since it took over (but the first)
    int bj_setups_ = 0;          // set-ups block-Jacobi served since it took over
    int hold_ = 0;               // block-Jacobi set-ups after the last going back before AMG may be tried again
    int wait_ = 0;               // of those, the ones still to come
    double floor_ = std::numeric_limits<double>::infinity();  // the AMG's cheapest solve since the switch, per
                                                              // decade (infinite after a steady stint: no trial)
    double stint_cost_ = 0, stint_decades_ = 0;  // the AMG's cost and decades since the switch (but its first solve)
    std::array<std::array<double, 2>, kWindow> window_{};  // the last ones' cost and decades
};

}  // namespace

template <class S>
std::unique_ptr<Preconditioner<S>> make_auto_preconditioner(const SimState<S>& state) {
    return std::make_unique<AutoPreconditioner<S>>(state);
}

template std::unique_ptr<Preconditioner<double>> make_auto_preconditioner(const SimState<double>&);
template std::unique_ptr<Preconditioner<float>> make_auto_preconditioner(const SimState<float>&);

}  // namespace edgefem::sim
