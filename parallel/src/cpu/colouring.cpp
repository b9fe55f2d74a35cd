#include "cpu/colouring.hpp"

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "edgefem/core/error.hpp"

namespace edgefem {

namespace {

struct CsrBuild {
    std::vector<index_t> first, items;
};

// unit -> resources (deduplicated, ascending).
CsrBuild unit_resources(const Colouring& col, index_t num_units, const ResourceFn& resources) {
    CsrBuild c;
    c.first.assign(std::size_t(num_units) + 1, 0);
    std::vector<index_t> buf;
    for (index_t u = 0; u < num_units; ++u) {
        buf.clear();
        const index_t b = col.unit_begin(u), e = col.unit_end(u);
        for (index_t i = b; i < e; ++i) resources(i, buf);
        std::sort(buf.begin(), buf.end());
        buf.erase(std::unique(buf.begin(), buf.end()), buf.end());
        c.items.insert(c.items.end(), buf.begin(), buf.end());
        c.first[u + 1] = index_t(c.items.size());
    }
    return c;
}

CsrBuild transpose(const CsrBuild& a, index_t num_cols) {
    CsrBuild t;
    t.first.assign(std::size_t(num_cols) + 1, 0);
    for (index_t r : a.items) ++t.first[r + 1];
    std::partial_sum(t.first.begin(), t.first.end(), t.first.begin());
    t.items.resize(a.items.size());
    std::vector<index_t> pos(t.first.begin(), t.first.end() - 1);
    const index_t rows = index_t(a.first.size() - 1);
    for (index_t u = 0; u < rows; ++u)
        for (index_t k = a.first[u]; k < a.first[u + 1]; ++k) t.items[pos[a.items[k]]++] = u;
    return t;
}

// unit_first tiles [0, num_items): starts at 0, non-decreasing, ends at num_items.
bool tiles(const std::vector<index_t>& unit_first, index_t num_items) {
    if (unit_first.empty() || unit_first.front() != 0 || unit_first.back() != num_items) return false;
    for (std::size_t u = 1; u < unit_first.size(); ++u)
        if (unit_first[u] < unit_first[u - 1]) return false;
    return true;
}

}  // namespace

Colouring colour_items(index_t num_items, index_t num_resources, const ResourceFn& resources,
                       const ColouringOptions& opts) {
    Colouring out;
    out.num_items = num_items;
    const bool variable = !opts.unit_first.empty();
    if (variable) {
        if (!tiles(opts.unit_first, num_items))
            throw InvalidArgument("ColouringOptions::unit_first must run from 0 to " + std::to_string(num_items) +
                                  " (the number of items), non-decreasing");
        out.block = 0;
        out.unit_first = opts.unit_first;
    } else {
        out.block = std::max<index_t>(1, opts.block);
    }
    const index_t B = out.block;
    const index_t nu = out.num_units();
    const CsrBuild ur = unit_resources(out, nu, resources);
    const CsrBuild ru = transpose(ur, num_resources);

    std::vector<int> colour(nu, -1);
    std::vector<index_t> stamp;  // stamp[c] == u + 1: colour c is forbidden for unit u
    auto forbid = [&](index_t u) {
        for (index_t k = ur.first[u]; k < ur.first[u + 1]; ++k) {
            const index_t r = ur.items[k];
            for (index_t j = ru.first[r]; j < ru.first[r + 1]; ++j) {
                const index_t w = ru.items[j];
                if (w != u && colour[w] >= 0) stamp[colour[w]] = u + 1;
            }
        }
    };
    // First fit.
    int ncol = 0;
    for (index_t u = 0; u < nu; ++u) {
        forbid(u);
        int c = 0;
        while (c < ncol && stamp[c] == u + 1) ++c;
        if (c == ncol) {
            ++ncol;
            stamp.push_back(0);
        }
        colour[u] = c;
    }
    // Balancing: move units out of colours above the mean size into the
    // smallest permitted colour below it.
    if (opts.balance && ncol > 1) {
        std::vector<index_t> size(ncol, 0);
        for (int c : colour) ++size[c];
        const index_t target = (nu + ncol - 1) / ncol;
        for (index_t u = 0; u < nu; ++u) {
            if (size[colour[u]] <= target) continue;
            forbid(u);
            int best = -1;
            for (int c = 0; c < ncol; ++c)
                if (stamp[c] != u + 1 && size[c] < target && (best < 0 || size[c] < size[best])) best = c;
            if (best >= 0) {
                --size[colour[u]];
                ++size[best];
                colour[u] = best;
            }
        }
    }
    // Colour -> units (ascending: a counting sort keeps unit order).
    out.colour_first.assign(ncol + 1, 0);
    for (int c : colour) ++out.colour_first[c + 1];
    std::partial_sum(out.colour_first.begin(), out.colour_first.end(), out.colour_first.begin());
    out.units.resize(nu);
    std::vector<index_t> pos(out.colour_first.begin(), out.colour_first.end() - 1);
    for (index_t u = 0; u < nu; ++u) out.units[pos[colour[u]]++] = u;
    // Chunks: a function of the colour size only.
    out.chunk_first.assign(ncol + 1, 0);
    out.chunk_units.assign(ncol, 1);
    for (int c = 0; c < ncol; ++c) {
        const index_t units = out.colour_first[c + 1] - out.colour_first[c];
        index_t items = units * B;
        if (variable) {
            items = 0;
            for (index_t x = out.colour_first[c]; x < out.colour_first[c + 1]; ++x)
                items += out.unit_end(out.units[x]) - out.unit_begin(out.units[x]);
        }
        index_t per = std::max<index_t>(1, items / std::max<index_t>(1, opts.chunks_per_colour));
        per = std::clamp(per, std::max<index_t>(1, opts.min_chunk_items), std::max<index_t>(1, opts.max_chunk_items));
        // Units per chunk: by the block size, or by the colour's mean unit size.
        const index_t unit_items = variable ? std::max<index_t>(1, items / std::max<index_t>(1, units)) : B;
        const index_t cu = std::max<index_t>(1, per / unit_items);
        out.chunk_units[c] = cu;
        out.chunk_first[c + 1] = out.chunk_first[c] + (units + cu - 1) / cu;
    }
    return out;
}

ColouringStats Colouring::stats() const {
    ColouringStats s;
    s.colours = colours();
    s.items = num_items;
    s.block = block;
    s.units = index_t(units.size());
    s.chunks = num_chunks();
    if (s.colours == 0) return s;
    s.min_units = units.size();
    s.min_items = num_items;
    for (int c = 0; c < s.colours; ++c) {
        const index_t n = colour_first[c + 1] - colour_first[c];
        s.min_units = std::min(s.min_units, n);
        s.max_units = std::max(s.max_units, n);
        index_t items = 0;
        for (index_t x = colour_first[c]; x < colour_first[c + 1]; ++x) items += unit_end(units[x]) - unit_begin(units[x]);
        s.min_items = std::min(s.min_items, items);
        s.max_items = std::max(s.max_items, items);
    }
    s.mean_units = double(units.size()) / s.colours;
    return s;
}

std::string ColouringStats::describe() const {
    char buf[240];
    if (block > 0)
        std::snprintf(buf, sizeof buf, "%d colours (block %d), units per colour min/mean/max = %d/%.1f/%d, %d chunks",
                      colours, int(block), int(min_units), mean_units, int(max_units), int(chunks));
    else
        std::snprintf(buf, sizeof buf,
                      "%d colours (%d units of %.1f items), units per colour min/mean/max = %d/%.1f/%d, "
                      "items per colour min/max = %d/%d, %d chunks",
                      colours, int(units), units > 0 ? double(items) / units : 0.0, int(min_units), mean_units,
                      int(max_units), int(min_items), int(max_items), int(chunks));
    return buf;
}

long colouring_conflicts(const Colouring& c, index_t num_resources, const ResourceFn& resources) {
    if (!c.unit_first.empty() ? !tiles(c.unit_first, c.num_items) : c.block <= 0) return -1;
    const index_t nu = c.num_units();
    if (index_t(c.units.size()) != nu) return -1;
    std::vector<char> seen(nu, 0);
    for (index_t u : c.units) {
        if (u < 0 || u >= nu || seen[u]) return -1;
        seen[u] = 1;
    }
    long conflicts = 0;
    std::vector<index_t> owner(num_resources, -1);  // unit that wrote r in the current colour
    std::vector<index_t> buf;
    for (int col = 0; col < c.colours(); ++col) {
        std::vector<index_t> touched;
        for (index_t k = c.colour_first[col]; k < c.colour_first[col + 1]; ++k) {
            const index_t u = c.units[k];
            buf.clear();
            for (index_t i = c.unit_begin(u); i < c.unit_end(u); ++i) resources(i, buf);
            for (index_t r : buf) {
                if (owner[r] == -1) {
                    owner[r] = u;
                    touched.push_back(r);
                } else if (owner[r] != u) {
                    ++conflicts;
                }
            }
        }
        for (index_t r : touched) owner[r] = -1;
    }
    return conflicts;
}

template <class S>
ResourceFn edge_scatter_resources(const EdgeModel<S>& m) {
    return [&m](index_t e, std::vector<index_t>& out) {
        out.push_back(m.edge[e][0]);
        out.push_back(m.edge[e][1]);
    };
}

template <class S>
ResourceFn vertex_segment_resources(const EdgeModel<S>& m) {
    return [&m](index_t a, std::vector<index_t>& out) {
        out.push_back(a);
        for (index_t e = m.edge_first[a]; e < m.edge_first[a + 1]; ++e) out.push_back(m.edge[e][1]);
    };
}

template <class S>
ResourceFn tsep_strain_resources(const EdgeModel<S>& m) {
    return [&m](index_t e0, std::vector<index_t>& out) {
        out.push_back(e0);
        for (index_t P = m.tsep_first[e0]; P < m.tsep_first[e0 + 1]; ++P) out.push_back(m.tsep_other[P]);
    };
}

template <class S>
ResourceFn tsep_stiffness_resources(const EdgeModel<S>& m) {
    return [&m](index_t e0, std::vector<index_t>& out) {
        const index_t ne = m.num_edges();
        for (index_t P = m.tsep_first[e0]; P < m.tsep_first[e0 + 1]; ++P)
            for (int k = 0; k < 4; ++k) {
                const index_t t = m.target[P][k] >> 1;
                if (t < ne) out.push_back(t);
            }
    };
}

template <class S>
ResourceFn tet_scatter_resources(const TetModel<S>& m) {
    return [&m](index_t t, std::vector<index_t>& out) {
        for (int k = 0; k < 4; ++k) out.push_back(m.tet[t][k]);
    };
}

template <class S>
ResourceFn tet_batch_scatter_resources(const BatchedTetModel<S>& m) {
    return [&m](index_t b, std::vector<index_t>& out) {
        for (int k = 0; k < 4; ++k)
            for (int l = 0; l < kTetBatchLanes; ++l) out.push_back(m.batches[b].v[k][l]);
    };
}

std::vector<index_t> units_from_vertex_parts(std::span<const index_t> item_first, std::span<const index_t> part_first) {
    if (item_first.empty() || item_first.front() != 0)
        throw InvalidArgument("units_from_vertex_parts: item offsets must start at 0");
    const index_t nv = index_t(item_first.size() - 1);
    if (part_first.empty() || part_first.front() != 0 || part_first.back() != nv)
        throw InvalidArgument("units_from_vertex_parts: part_first must run from 0 to " + std::to_string(nv) +
                              " (the number of vertices)");
    std::vector<index_t> unit_first{0};
    for (std::size_t p = 1; p < part_first.size(); ++p) {
        if (part_first[p] < part_first[p - 1]) throw InvalidArgument("units_from_vertex_parts: part_first decreases");
        const index_t end = item_first[part_first[p]];
        if (end < unit_first.back()) throw InvalidArgument("units_from_vertex_parts: item offsets decrease");
        if (end > unit_first.back()) unit_first.push_back(end);
    }
    return unit_first;  // {0} when there are no items: no units
}

template ResourceFn edge_scatter_resources(const EdgeModel<double>&);
template ResourceFn edge_scatter_resources(const EdgeModel<float>&);
template ResourceFn vertex_segment_resources(const EdgeModel<double>&);
template ResourceFn vertex_segment_resources(const EdgeModel<float>&);
template ResourceFn tsep_strain_resources(const EdgeModel<double>&);
template ResourceFn tsep_strain_resources(const EdgeModel<float>&);
template ResourceFn tsep_stiffness_resources(const EdgeModel<double>&);
template ResourceFn tsep_stiffness_resources(const EdgeModel<float>&);
template ResourceFn tet_scatter_resources(const TetModel<double>&);
template ResourceFn tet_scatter_resources(const TetModel<float>&);
template ResourceFn tet_batch_scatter_resources(const BatchedTetModel<double>&);
template ResourceFn tet_batch_scatter_resources(const BatchedTetModel<float>&);

}  // namespace edgefem
