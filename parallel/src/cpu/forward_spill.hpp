// Owner-computes scatter without colouring, for the segment kernels whose
// items write their own target and forward targets only: vertex segment a
// writes a and V1(E) > a (edges have V0 < V1), TSEP segment e0 writes e0
// and E1 > e0. Items and targets share one index space.
//
// Items are cut into parts of consecutive items, fixed by the mesh (never by
// the thread count). Phase 1: every part runs its items, writing targets
// inside its own range directly (no other part writes there in this phase)
// and targets past its end into its own spill window [end, window_end).
// Phase 2 (after one barrier): every part adds, target by target, the
// windows of the earlier parts that reach into its range, in part order, and
// zeroes them for the next call. Each target's sum has a fixed order, so the
// result is bitwise independent of the thread count. With a locality
// ordering the windows are short (the vertex bandwidth), so phase 2 is a
// small fraction of phase 1.
#pragma once

#include <algorithm>
#include <functional>
#include <span>
#include <vector>

#include "cpu/edge_kernels.hpp"
#include "edgefem/core/executor.hpp"

namespace edgefem {

struct ForwardSpill {
    std::vector<index_t> part_first;      // #parts + 1 item offsets
    std::vector<index_t> window_end;      // #parts: one past the last target a part spills to
    std::vector<std::size_t> window_first;  // #parts + 1 offsets into the spill buffer, in targets
    // The parts whose windows reach into part q: in_part[in_first[q] .. in_first[q + 1]), ascending.
    std::vector<index_t> in_first, in_part;

    index_t parts() const { return part_first.empty() ? 0 : index_t(part_first.size() - 1); }
    index_t items() const { return part_first.empty() ? 0 : part_first.back(); }
    // Spill buffer length in targets (multiply by the values per target).
    std::size_t spill_targets() const { return window_first.empty() ? 0 : window_first.back(); }
};

// What each phase of an owner scatter over a ForwardSpill's parts needs of
// the phase before, for Executor::for_linked_phases: per phase after the
// first, the range of parts [first, last] whose previous phase part q
// waits for (besides its own). With barriers every part waits for all.
struct PhaseLinks {
    index_t parts = 0;
    std::vector<index_t> first, last;  // (phases - 1) * parts
    int phases() const { return parts > 0 ? int(first.size() / std::size_t(parts)) + 1 : 0; }
};

// Appends a phase whose part q reads the targets of its window, which the
// parts holding them (q's successors) wrote in the phase before.
void link_window_reads(PhaseLinks& links, const ForwardSpill& fs);
// Appends a phase whose part q adds the windows of the earlier parts that
// reach into its range, which they wrote in the phase before.
void link_incoming_adds(PhaseLinks& links, const ForwardSpill& fs);
// Builds links phase by phase: linked(fs, link_window_reads, ...).
template <class... Steps>
PhaseLinks linked(const ForwardSpill& fs, Steps... steps) {
    PhaseLinks links;
    (steps(links, fs), ...);
    return links;
}

// body(phase, part) for every phase of `links` and every part, on `ex`.
template <class Body>
void run_linked(const Executor& ex, const PhaseLinks& links, Body&& body) {
    ex.for_linked_phases(links.phases(), links.parts, links.first.data(), links.last.data(), body);
}

// `last_target(i)`: the largest target item i writes (i itself when none is
// larger). Throws InvalidArgument when part_first does not run from 0 to n
// in non-decreasing steps or a target lies outside [i, n).
ForwardSpill make_forward_spill(index_t n, std::span<const index_t> part_first,
                                const std::function<index_t(index_t)>& last_target);

// part_first for `parts` parts of [0, n) with about equal weight, where
// weight_first (n + 1 non-decreasing offsets) gives item i the weight
// weight_first[i + 1] - weight_first[i] (e.g. EdgeModel::edge_first: a
// vertex's segment length). Parts may be empty only when n < parts.
std::vector<index_t> balanced_parts(std::span<const index_t> weight_first, index_t parts);

// Phase 2 of part p on its own: adds the windows of the earlier parts that
// reach into its range to `out`, in part order, and zeroes them.
template <int W, class T>
void add_incoming_spills(const ForwardSpill& fs, index_t p, T* out, std::vector<T>& spill) {
    const index_t begin = fs.part_first[p], end = fs.part_first[p + 1];
    for (index_t k = fs.in_first[p]; k < fs.in_first[p + 1]; ++k) {
        const index_t q = fs.in_part[k];
        const index_t qend = fs.part_first[q + 1];
        T* const window = spill.data() + W * fs.window_first[q];
        const index_t lo = std::max(begin, qend), hi = std::min(end, fs.window_end[q]);
        for (std::size_t i = W * std::size_t(lo); i < W * std::size_t(hi); ++i) {
            T& s = window[i - W * std::size_t(qend)];
            out[i] += s;
            s = T(0);
        }
    }
}

// The same for one target t of part p (W = 1): the sum, in part order, of
// what the earlier parts' windows hold for t, which are zeroed.
template <class T>
T take_incoming_spill(const ForwardSpill& fs, index_t p, index_t t, std::vector<T>& spill) {
    T sum = T(0);
    for (index_t k = fs.in_first[p]; k < fs.in_first[p + 1]; ++k) {
        const index_t q = fs.in_part[k];
        if (t < fs.window_end[q]) {
            T& s = spill[fs.window_first[q] + std::size_t(t - fs.part_first[q + 1])];
            sum += s;
            s = T(0);
        }
    }
    return sum;
}

// Runs one owner-computes scatter with W values per target: body(part,
// begin, end, fwd) runs items [begin, end) of the part, writing its own
// targets in `out` and its forward targets through the kernel::ForwardOut
// `fwd` (targets past `end` land in the part's window). `spill` must hold
// fs.spill_targets() * W zeros; it is left zeroed. `links`:
// linked(fs, link_incoming_adds), kept by the caller.
template <int W, class T, class Body>
void run_forward_spill(const Executor& ex, const ForwardSpill& fs, const PhaseLinks& links, T* out,
                       std::vector<T>& spill, Body&& body) {
    run_linked(ex, links, [&](int phase, index_t p) {
        const index_t begin = fs.part_first[p], end = fs.part_first[p + 1];
        if (phase == 0)
            body(p, begin, end, kernel::ForwardOut<T>{out, spill.data() + W * fs.window_first[p], end});
        else
            add_incoming_spills<W>(fs, p, out, spill);
    });
}

}  // namespace edgefem
