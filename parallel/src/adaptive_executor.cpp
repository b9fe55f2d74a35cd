#include "edgefem/parallel/adaptive_executor.hpp"

#include <algorithm>
#include <chrono>
#include <cxxabi.h>
#include <cstdio>
#include <cstdlib>

#include "edgefem/core/error.hpp"
#include "team_loops.hpp"

namespace edgefem {

namespace {

std::string demangle(const char* name) {
    int status = 0;
    char* s = abi::__cxa_demangle(name, nullptr, nullptr, &status);
    std::string out = status == 0 && s ? s : name;
    std::free(s);
    return out;
}

const char* kind_name(int k) {
    static const char* const names[] = {"chunks", "phases", "uniform chunks", "uniform phases", "linked phases"};
    return names[k];
}

}  // namespace

AdaptiveExecutor::AdaptiveExecutor(std::shared_ptr<const Executor> inner, int trials, std::int64_t retrial)
    : inner_(std::move(inner)), trials_(trials), next_trials_(retrial) {
    if (retrial < 1) throw InvalidArgument("AdaptiveExecutor: retrial must be at least 1 call, got " + std::to_string(retrial));
    if (!inner_) throw InvalidArgument("AdaptiveExecutor: no executor to wrap");
    if (trials_ < 1) throw InvalidArgument("AdaptiveExecutor: trials must be at least 1, got " + std::to_string(trials));
}

std::size_t AdaptiveExecutor::KeyHash::operator()(const Key& k) const {
    std::size_t h = k.type.hash_code();
    h ^= std::hash<std::int64_t>()(std::int64_t(k.chunks) * 8 + int(k.kind)) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h ^= std::hash<int>()(k.phases) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    return h;
}

// Sites recorded at most; a simulation has a few dozen.
constexpr std::size_t kMaxSites = 4096;

// Trial calls alternate parallel, serial, parallel, ... until each mode has
// `trials_` timed calls; then the site runs in the mode of all decided sites.
int AdaptiveExecutor::pick(const Key& key, bool& time) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (++since_trials_ > next_trials_) {  // another round of trials for every site
        since_trials_ = 0;
        next_trials_ = std::max(next_trials_, std::min(2 * next_trials_, std::int64_t(1) << 22));
        for (auto& [k, st] : stats_) {
            st.decided = false;
            st.timed[0] = st.timed[1] = 0;
        }
    }
    auto it = stats_.find(key);
    if (it == stats_.end()) {
        if (stats_.size() >= kMaxSites) {  // a caller whose chunk counts never repeat: no more records
            time = false;
            return mode_;
        }
        it = stats_.emplace(key, Stats{}).first;
    }
    Stats& s = it->second;
    ++s.calls;
    time = !s.decided;
    if (s.decided) return mode_;
    return s.timed[1] <= s.timed[0] ? 1 : 0;
}

void AdaptiveExecutor::weighted_totals(double (&total)[2], int& decided, int& faster_serial) const {
    total[0] = total[1] = 0;
    decided = faster_serial = 0;
    for (const auto& [k, s] : stats_) {
        if (!s.decided) continue;
        ++decided;
        faster_serial += s.best[0] < s.best[1];
        for (int m : {0, 1}) total[m] += double(s.calls) * s.best[m];
    }
}

void AdaptiveExecutor::record(const Key& key, int mode, double seconds) const {
    std::lock_guard<std::mutex> lock(mutex_);
    Stats& s = stats_[key];
    if (s.decided) return;  // another caller of the same site finished its trials meanwhile
    if (s.timed[mode] == 0 || seconds < s.best[mode]) s.best[mode] = seconds;
    ++s.timed[mode];
    if (s.timed[0] < trials_ || s.timed[1] < trials_) return;
    s.decided = true;
    ++s.rounds;
    double total[2];
    int decided, faster_serial;
    weighted_totals(total, decided, faster_serial);
    mode_ = total[0] < total[1] ? 0 : 1;
}

template <class Run>
void AdaptiveExecutor::dispatch(const Key& key, Run&& run) const {
    bool time = false;
    const int mode = pick(key, time);  // the lock is not held while the loop runs
    if (!time) {
        run(mode);
        return;
    }
    const auto t0 = std::chrono::steady_clock::now();
    run(mode);
    record(key, mode, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

void AdaptiveExecutor::for_chunks(index_t n, const std::function<void(index_t)>& body) const {
    if (n <= 1) return inner_->for_chunks(n, body);
    dispatch(Key{body.target_type(), Kind::Chunks, 0, n}, [&](int parallel) {
        if (parallel) return inner_->for_chunks(n, body);
        for (index_t c = 0; c < n; ++c) body(c);
    });
}

void AdaptiveExecutor::for_uniform_chunks(index_t n, const std::function<void(index_t)>& body) const {
    if (n <= 1) return inner_->for_uniform_chunks(n, body);
    dispatch(Key{body.target_type(), Kind::UniformChunks, 0, n}, [&](int parallel) {
        if (parallel) return inner_->for_uniform_chunks(n, body);
        for (index_t c = 0; c < n; ++c) body(c);
    });
}


void AdaptiveExecutor::for_phases(int phases, const index_t* chunk_first,
                                  const std::function<void(int, index_t)>& body) const {
    if (phases <= 0) return;
    dispatch(Key{body.target_type(), Kind::Phases, phases, chunk_first[phases] - chunk_first[0]}, [&](int parallel) {
        if (parallel) return inner_->for_phases(phases, chunk_first, body);
        team::run_phases_here(phases, chunk_first, body);
    });
}

void AdaptiveExecutor::for_uniform_phases(int phases, const index_t* chunk_first,
                                          const std::function<void(int, index_t)>& body) const {
    if (phases <= 0) return;
    dispatch(Key{body.target_type(), Kind::UniformPhases, phases, chunk_first[phases] - chunk_first[0]},
             [&](int parallel) {
                 if (parallel) return inner_->for_uniform_phases(phases, chunk_first, body);
                 team::run_phases_here(phases, chunk_first, body);
             });
}

void AdaptiveExecutor::for_linked_phases(int phases, index_t chunks, const index_t* need_first,
                                         const index_t* need_last,
                                         const std::function<void(int, index_t)>& body) const {
    if (phases <= 0 || chunks <= 0) return;
    dispatch(Key{body.target_type(), Kind::LinkedPhases, phases, index_t(phases) * chunks}, [&](int parallel) {
        if (parallel) return inner_->for_linked_phases(phases, chunks, need_first, need_last, body);
        team::run_linked_here(phases, chunks, body);
    });
}

std::vector<AdaptiveExecutor::Site> AdaptiveExecutor::sites() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Site> out;
    for (const auto& [k, s] : stats_) {
        Site site;
        site.loop = demangle(k.type.name());
        site.kind = kind_name(int(k.kind));
        site.chunks = k.chunks;
        site.phases = k.phases;
        site.calls = s.calls;
        site.rounds = s.rounds;
        site.serial_us = s.best[0] * 1e6;
        site.parallel_us = s.best[1] * 1e6;
        site.decided = s.decided;
        site.faster_serial = s.decided && s.best[0] < s.best[1];
        out.push_back(std::move(site));
    }
    return out;
}

bool AdaptiveExecutor::serial() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return mode_ == 0;
}

std::string AdaptiveExecutor::summary() const {
    std::lock_guard<std::mutex> lock(mutex_);
    double total[2];
    int decided, faster_serial;
    weighted_totals(total, decided, faster_serial);
    if (decided == 0) return "undecided (no loop past its trials)";
    char buf[200];
    std::snprintf(buf, sizeof buf, "%s (%d of %d loops faster serially; calls x fastest call: %.1f ms serial against %.1f on %d threads)",
                  mode_ == 0 ? "serial" : "threads", faster_serial, decided, total[0] * 1e3, total[1] * 1e3,
                  inner_->threads());
    return buf;
}

std::shared_ptr<const Executor> make_adaptive(std::shared_ptr<const Executor> inner, int trials) {
    if (trials < 1) throw InvalidArgument("make_adaptive: trials must be at least 1, got " + std::to_string(trials));
    if (inner && inner->threads() <= 1) return inner;
    return std::make_shared<AdaptiveExecutor>(std::move(inner), trials);
}

}  // namespace edgefem
