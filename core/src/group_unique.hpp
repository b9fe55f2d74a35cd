// Internal: deduplicate (bucket, value) keys given per slot with a counting
// sort on the bucket and short sorts inside each bucket — O(n) passes for the
// short buckets topology produces (edges per vertex, TSEPs per edge).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/mesh.hpp"

namespace edgefem::detail {

struct Grouped {
    std::vector<index_t> first;    // #buckets + 1: unique keys of bucket b are [first[b], first[b+1])
    std::vector<index_t> value;    // value of each unique key, ascending inside a bucket
    std::vector<index_t> slot_id;  // slot -> id of its unique key
};

// key(slot) returns {bucket, value}; slots are 0 .. num_slots-1.
template <class KeyOf>
Grouped group_unique(index_t num_buckets, std::int64_t num_slots, KeyOf key) {
    if (num_slots >= (std::int64_t{1} << 32))
        throw InvalidArgument("mesh too large: more than 2^32 topology slots");
    std::vector<std::int64_t> start(static_cast<std::size_t>(num_buckets) + 1, 0);
    for (std::int64_t s = 0; s < num_slots; ++s) ++start[key(s).first + 1];
    for (index_t b = 0; b < num_buckets; ++b) start[b + 1] += start[b];

    // Entry = value << 32 | slot, so a plain integer sort orders by value,
    // then slot (deterministic).
    std::vector<std::uint64_t> entry(static_cast<std::size_t>(num_slots));
    {
        std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
        for (std::int64_t s = 0; s < num_slots; ++s) {
            const auto [b, v] = key(s);
            entry[fill[b]++] = (static_cast<std::uint64_t>(v) << 32) | static_cast<std::uint64_t>(s);
        }
    }

    Grouped out;
    out.first.assign(static_cast<std::size_t>(num_buckets) + 1, 0);
    out.slot_id.resize(static_cast<std::size_t>(num_slots));
    out.value.reserve(static_cast<std::size_t>(num_slots / 2));
    for (index_t b = 0; b < num_buckets; ++b) {
        std::uint64_t* lo = entry.data() + start[b];
        std::uint64_t* hi = entry.data() + start[b + 1];
        std::sort(lo, hi);
        std::uint64_t prev = ~std::uint64_t{0};
        for (std::uint64_t* it = lo; it != hi; ++it) {
            const std::uint64_t v = *it >> 32;
            if (v != prev) {
                if (out.value.size() >= static_cast<std::size_t>(INT32_MAX))
                    throw InvalidArgument("mesh too large: more than 2^31-1 topology items");
                out.value.push_back(static_cast<index_t>(v));
                prev = v;
            }
            out.slot_id[*it & 0xffffffffu] = static_cast<index_t>(out.value.size() - 1);
        }
        out.first[b + 1] = static_cast<index_t>(out.value.size());
    }
    return out;
}

// Row r lists, ascending, the items i with r in rows_of(i) (each item names
// `arity` rows).
template <int arity, class RowsOf>
void build_csr(index_t num_rows, index_t num_items, RowsOf rows_of, std::vector<index_t>& offsets,
               std::vector<index_t>& items) {
    offsets.assign(static_cast<std::size_t>(num_rows) + 1, 0);
    for (index_t i = 0; i < num_items; ++i) {
        const auto rows = rows_of(i);
        for (int k = 0; k < arity; ++k) ++offsets[rows[k] + 1];
    }
    for (index_t r = 0; r < num_rows; ++r) offsets[r + 1] += offsets[r];
    items.resize(static_cast<std::size_t>(offsets[num_rows]));
    std::vector<index_t> fill(offsets.begin(), offsets.end() - 1);
    for (index_t i = 0; i < num_items; ++i) {
        const auto rows = rows_of(i);
        for (int k = 0; k < arity; ++k) items[fill[rows[k]]++] = i;
    }
}

}  // namespace edgefem::detail
