#include "cpu/forward_spill.hpp"

#include <algorithm>
#include <string>

#include "edgefem/core/error.hpp"

namespace edgefem {

ForwardSpill make_forward_spill(index_t n, std::span<const index_t> part_first,
                                const std::function<index_t(index_t)>& last_target) {
    if (part_first.size() < 2 || part_first.front() != 0 || part_first.back() != n)
        throw InvalidArgument("forward spill: part offsets must run from 0 to " + std::to_string(n));
    ForwardSpill fs;
    fs.part_first.assign(part_first.begin(), part_first.end());
    const index_t P = fs.parts();
    fs.window_end.resize(P);
    fs.window_first.assign(std::size_t(P) + 1, 0);
    for (index_t p = 0; p < P; ++p) {
        const index_t begin = fs.part_first[p], end = fs.part_first[p + 1];
        if (end < begin) throw InvalidArgument("forward spill: part offsets decrease at part " + std::to_string(p));
        index_t reach = end;
        for (index_t i = begin; i < end; ++i) {
            const index_t t = last_target(i);
            if (t < i || t >= n)
                throw InvalidArgument("forward spill: item " + std::to_string(i) + " writes target " +
                                      std::to_string(t) + ", outside [" + std::to_string(i) + ", " +
                                      std::to_string(n) + ")");
            reach = std::max(reach, t + 1);
        }
        fs.window_end[p] = reach;
        fs.window_first[p + 1] = fs.window_first[p] + std::size_t(reach - end);
    }
    // Consumers: part q reads the windows of the parts p < q reaching past q's start.
    fs.in_first.assign(std::size_t(P) + 1, 0);
    for (index_t q = 0; q < P; ++q) {
        for (index_t p = 0; p < q; ++p)
            if (fs.window_end[p] > fs.part_first[q] && fs.part_first[q + 1] > fs.part_first[q] &&
                fs.window_end[p] > fs.part_first[p + 1])
                fs.in_part.push_back(p);
        fs.in_first[q + 1] = index_t(fs.in_part.size());
    }
    return fs;
}

namespace {
void check_parts(PhaseLinks& links, const ForwardSpill& fs) {
    if (links.parts != 0 && links.parts != fs.parts())
        throw InvalidArgument("phase links: " + std::to_string(fs.parts()) + " parts where earlier phases have " +
                              std::to_string(links.parts));
    links.parts = fs.parts();
}
}  // namespace

void link_window_reads(PhaseLinks& links, const ForwardSpill& fs) {
    check_parts(links, fs);
    for (index_t q = 0; q < fs.parts(); ++q) {
        index_t last = q;
        if (fs.window_end[q] > fs.part_first[q + 1]) {
            // The part holding the window's last target: the last part starting at or before it.
            const auto it = std::upper_bound(fs.part_first.begin(), fs.part_first.end(), fs.window_end[q] - 1);
            last = std::max(q, index_t(it - fs.part_first.begin()) - 1);
        }
        links.first.push_back(q);
        links.last.push_back(last);
    }
}

void link_incoming_adds(PhaseLinks& links, const ForwardSpill& fs) {
    check_parts(links, fs);
    for (index_t q = 0; q < fs.parts(); ++q) {
        links.first.push_back(fs.in_first[q] < fs.in_first[q + 1] ? fs.in_part[fs.in_first[q]] : q);
        links.last.push_back(q);
    }
}

std::vector<index_t> balanced_parts(std::span<const index_t> weight_first, index_t parts) {
    if (weight_first.empty()) throw InvalidArgument("balanced_parts: empty weight offsets");
    const index_t n = index_t(weight_first.size() - 1);
    parts = std::max<index_t>(1, parts);
    const double total = double(weight_first.back() - weight_first.front());
    std::vector<index_t> first(std::size_t(parts) + 1, n);
    first[0] = 0;
    index_t i = 0;
    for (index_t p = 1; p < parts; ++p) {
        // First item whose cumulative weight reaches p / parts of the total
        // (by item count when there is no weight), at least one item further.
        const double goal = total * double(p) / double(parts);
        if (total > 0)
            while (i < n && double(weight_first[i] - weight_first.front()) < goal) ++i;
        else
            i = index_t((long long)(n) * p / parts);
        i = std::clamp<index_t>(i, std::min<index_t>(n, first[p - 1] + 1), n);
        first[p] = i;
    }
    return first;
}

}  // namespace edgefem
