#include "edgefem/parallel/adaptive_executor.hpp"

#include <chrono>
#include <cxxabi.h>
#include <cstdlib>

#include "edgefem/core/error.hpp"

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
    static const char* const names[] = {"chunks", "phases", "uniform chunks", "uniform phases"};
    return names[k];
}

}  // namespace

AdaptiveExecutor::AdaptiveExecutor(std::shared_ptr<const Executor> inner, int trials)
    : inner_(std::move(inner)), trials_(trials) {
    if (!inner_) throw InvalidArgument("AdaptiveExecutor: no executor to wrap");
    if (trials_ < 1) throw InvalidArgument("AdaptiveExecutor: trials must be at least 1, got " + std::to_string(trials));
}

std::size_t AdaptiveExecutor::KeyHash::operator()(const Key& k) const {
    std::size_t h = k.type.hash_code();
    h ^= std::hash<std::int64_t>()(std::int64_t(k.chunks) * 8 + int(k.kind)) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h ^= std::hash<int>()(k.phases) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    return h;
}

// Trial calls alternate parallel, serial, parallel, ... until each mode has
// `trials_` timed calls; then the mode of the fastest call wins for good.
int AdaptiveExecutor::pick(const Key& key, bool& time) const {
    std::lock_guard<std::mutex> lock(mutex_);
    Stats& s = stats_[key];
    ++s.calls;
    if (s.choice >= 0) {
        time = false;
        return s.choice;
    }
    time = true;
    return s.timed[1] <= s.timed[0] ? 1 : 0;
}

void AdaptiveExecutor::record(const Key& key, int mode, double seconds) const {
    std::lock_guard<std::mutex> lock(mutex_);
    Stats& s = stats_[key];
    if (s.choice >= 0) return;  // another caller of the same site decided meanwhile
    if (s.timed[mode] == 0 || seconds < s.best[mode]) s.best[mode] = seconds;
    ++s.timed[mode];
    if (s.timed[0] >= trials_ && s.timed[1] >= trials_) s.choice = s.best[0] < s.best[1] ? 0 : 1;
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

namespace {
void run_phases_here(int phases, const index_t* chunk_first, const std::function<void(int, index_t)>& body) {
    for (int p = 0; p < phases; ++p)
        for (index_t c = 0; c < chunk_first[p + 1] - chunk_first[p]; ++c) body(p, c);
}
}  // namespace

void AdaptiveExecutor::for_phases(int phases, const index_t* chunk_first,
                                  const std::function<void(int, index_t)>& body) const {
    if (phases <= 0) return;
    dispatch(Key{body.target_type(), Kind::Phases, phases, chunk_first[phases] - chunk_first[0]}, [&](int parallel) {
        if (parallel) return inner_->for_phases(phases, chunk_first, body);
        run_phases_here(phases, chunk_first, body);
    });
}

void AdaptiveExecutor::for_uniform_phases(int phases, const index_t* chunk_first,
                                          const std::function<void(int, index_t)>& body) const {
    if (phases <= 0) return;
    dispatch(Key{body.target_type(), Kind::UniformPhases, phases, chunk_first[phases] - chunk_first[0]},
             [&](int parallel) {
                 if (parallel) return inner_->for_uniform_phases(phases, chunk_first, body);
                 run_phases_here(phases, chunk_first, body);
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
        site.serial_us = s.best[0] * 1e6;
        site.parallel_us = s.best[1] * 1e6;
        site.decided = s.choice >= 0;
        site.serial = s.choice == 0;
        out.push_back(std::move(site));
    }
    return out;
}

std::string AdaptiveExecutor::summary() const {
    int decided = 0, serial = 0;
    for (const Site& s : sites()) {
        decided += s.decided;
        serial += s.serial;
    }
    return std::to_string(serial) + " of " + std::to_string(decided) + " loops run serially";
}

std::shared_ptr<const Executor> make_adaptive(std::shared_ptr<const Executor> inner, int trials) {
    if (trials < 1) throw InvalidArgument("make_adaptive: trials must be at least 1, got " + std::to_string(trials));
    if (inner && inner->threads() <= 1) return inner;
    return std::make_shared<AdaptiveExecutor>(std::move(inner), trials);
}

}  // namespace edgefem
