#include "edgefem/parallel/async_tangent.hpp"

#include "edgefem/parallel/cpu_backend.hpp"

#include <condition_variable>
#include <mutex>
#include <thread>

namespace edgefem {

namespace {

template <class S>
class AsyncTangentOperator final : public ElasticOperator<S> {
public:
    AsyncTangentOperator(std::unique_ptr<ElasticOperator<S>> fg, std::unique_ptr<ElasticOperator<S>> t0,
                         std::unique_ptr<ElasticOperator<S>> t1)
        : fg_(std::move(fg)), tan_{std::move(t0), std::move(t1)} {
        const std::size_t n = 3 * std::size_t(fg_->num_vertices());
        u_last_.assign(n, S(0));
        u_snap_.assign(n, S(0));
        f_fg_scratch_.assign(n, S(0));
        f_bg_scratch_.assign(n, S(0));
        D_[0].assign(3 * n, S(0));
        D_[1].assign(3 * n, S(0));
        worker_ = std::thread([this] { work(); });
    }
    ~AsyncTangentOperator() override {
        {
            std::lock_guard<std::mutex> lock(m_);
            stop_ = true;
        }
        cv_.notify_all();
        worker_.join();
    }

    index_t num_vertices() const override { return fg_->num_vertices(); }
    double forces(const S* u, S* f, bool energy) override {
        std::copy(u, u + u_last_.size(), u_last_.begin());
        return fg_->forces(u, f, energy);
    }
    double energy(const S* u) override { return fg_->energy(u); }

    void build_stiffness(bool definite) override {
        if (!have_front_ || (definite && !front_definite_)) {
            // First K, or a definite K asked for (the simulator's retry after
            // negative curvature): build it now, on this thread.
            wait_idle();
            build(*tan_[front_], u_last_.data(), f_fg_scratch_.data(), definite, D_[front_]);
            have_front_ = true;
            front_definite_ = definite;
        } else {
            std::lock_guard<std::mutex> lock(m_);
            if (state_ == State::Done) {
                front_ = building_;
                front_definite_ = building_definite_;
                state_ = State::Idle;
            }
        }
        std::unique_lock<std::mutex> lock(m_);
        if (state_ != State::Idle) return;  // a build is running: keep the current K
        std::copy(u_last_.begin(), u_last_.end(), u_snap_.begin());
        building_ = 1 - front_;
        building_definite_ = definite;
        state_ = State::Requested;
        lock.unlock();
        cv_.notify_all();
    }

    void multiply(const S* x, S* y) const override { tan_[front_]->multiply(x, y); }
    void diagonal_blocks(S* D) const override { std::copy(D_[front_].begin(), D_[front_].end(), D); }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        tan_[front_]->for_each_block(visit, ctx);
    }
    index_t inverted_tets(const S* u) const override { return fg_->inverted_tets(u); }

private:
    enum class State { Idle, Requested, Done };

    // K at u, and its diagonal blocks (the simulator's preconditioner reads
    // them right after every swap: computed off the loop's thread too).
    static void build(ElasticOperator<S>& op, const S* u, S* f, bool definite, std::vector<S>& D) {
        op.forces(u, f, false);
        op.build_stiffness(definite);
        op.diagonal_blocks(D.data());
    }
    void wait_idle() {
        std::unique_lock<std::mutex> lock(m_);
        cv_.wait(lock, [&] { return state_ != State::Requested; });
        state_ = State::Idle;  // a finished build is dropped: the caller builds a newer one
    }
    void work() {
        std::unique_lock<std::mutex> lock(m_);
        for (;;) {
            cv_.wait(lock, [&] { return stop_ || state_ == State::Requested; });
            if (stop_) return;
            const int target = building_;
            const bool definite = building_definite_;
            lock.unlock();
            build(*tan_[target], u_snap_.data(), f_bg_scratch_.data(), definite, D_[target]);
            lock.lock();
            state_ = State::Done;
            cv_.notify_all();
        }
    }

    std::unique_ptr<ElasticOperator<S>> fg_;
    std::unique_ptr<ElasticOperator<S>> tan_[2];
    std::vector<S> u_last_, u_snap_, f_fg_scratch_, f_bg_scratch_;
    std::vector<S> D_[2];  // diagonal blocks of each tangent's K
    int front_ = 0;  // the tangent multiply() uses (main thread only)
    bool have_front_ = false, front_definite_ = false;
    // Shared with the worker, under m_: the build request and its result.
    std::mutex m_;
    std::condition_variable cv_;
    State state_ = State::Idle;
    int building_ = 1;
    bool building_definite_ = false;
    bool stop_ = false;
    std::thread worker_;
};

}  // namespace

template <class S>
OperatorFactory<S> async_tangent_factory(OperatorFactory<S> inner) {
    if (!inner)
        inner = [](const Mesh& m, const Materials& mat, ModelKind k, Method me) {
            return make_cpu_operator<S>(m, mat, k, me);
        };
    return [inner](const Mesh& m, const Materials& mat, ModelKind k, Method me) -> std::unique_ptr<ElasticOperator<S>> {
        return std::make_unique<AsyncTangentOperator<S>>(inner(m, mat, k, me), inner(m, mat, k, me), inner(m, mat, k, me));
    };
}

template OperatorFactory<double> async_tangent_factory<double>(OperatorFactory<double>);
template OperatorFactory<float> async_tangent_factory<float>(OperatorFactory<float>);

}  // namespace edgefem
