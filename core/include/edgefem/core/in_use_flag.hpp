// One caller at a time: a simulator's step(), solve_static() and energies()
// claim its flag for their duration, and a second claim while it is held
// (another thread calling into the same simulator) throws InvalidArgument
// instead of racing on the state. One atomic exchange per call; distinct
// simulators have distinct flags and stay independent. It catches two
// overlapping calls, not every race: reading or writing the views while
// another thread steps is still the caller's to avoid (docs/api.md).
#pragma once

#include <atomic>
#include <string>

#include "edgefem/core/error.hpp"

namespace edgefem {

class InUseFlag {
public:
    InUseFlag() = default;
    // A moved or copied simulator starts idle.
    InUseFlag(const InUseFlag&) noexcept {}
    InUseFlag& operator=(const InUseFlag&) noexcept { return *this; }

    // Holds the flag until destroyed.
    class Claim {
    public:
        Claim(InUseFlag& flag, const char* call) : flag_(flag) {
            if (flag_.busy_.exchange(true, std::memory_order_acquire))
                throw InvalidArgument(std::string(call) +
                                      ": the simulator is inside another call (step, solve_static or energies) on "
                                      "another thread; a simulator may be used by one thread at a time");
        }
        ~Claim() { flag_.busy_.store(false, std::memory_order_release); }
        Claim(const Claim&) = delete;
        Claim& operator=(const Claim&) = delete;

    private:
        InUseFlag& flag_;
    };

private:
    std::atomic<bool> busy_{false};
};

}  // namespace edgefem
