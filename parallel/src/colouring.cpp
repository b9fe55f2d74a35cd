#include "edgefem/parallel/colouring.hpp"

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace edgefem {

namespace {

struct CsrBuild {
    std::vector<index_t> first, items;
};

// unit -> resources (deduplicated, ascending).
CsrBuild unit_resources(index_t num_items, index_t block, index_t num_units, const ResourceFn& resources) {
    CsrBuild c;
    c.first.assign(std::size_t(num_units) + 1, 0);
    std::vector<index_t> buf;
    for (index_t u = 0; u < num_units; ++u) {
        buf.clear();
        const index_t b = u * block, e = std::min(num_items, b + block);
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

}  // namespace

Colouring colour_items(index_t num_items, index_t num_resources, const ResourceFn& resources,
                       const ColouringOptions& opts) {
    Colouring out;
    out.num_items = num_items;
    out.block = std::max<index_t>(1, opts.block);
    const index_t B = out.block;
    const index_t nu = (num_items + B - 1) / B;
    const CsrBuild ur = unit_resources(num_items, B, nu, resources);
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
        const index_t items = units * B;
        index_t per = std::max<index_t>(1, items / std::max<index_t>(1, opts.chunks_per_colour));
        per = std::clamp(per, std::max<index_t>(1, opts.min_chunk_items), std::max<index_t>(1, opts.max_chunk_items));
        const index_t cu = std::max<index_t>(1, per / B);
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
    s.chunks = num_chunks();
    if (s.colours == 0) return s;
    s.min_units = units.size();
    for (int c = 0; c < s.colours; ++c) {
        const index_t n = colour_first[c + 1] - colour_first[c];
        s.min_units = std::min(s.min_units, n);
        s.max_units = std::max(s.max_units, n);
    }
    s.mean_units = double(units.size()) / s.colours;
    return s;
}

std::string ColouringStats::describe() const {
    char buf[200];
    std::snprintf(buf, sizeof buf, "%d colours (block %d), units per colour min/mean/max = %d/%.1f/%d, %d chunks",
                  colours, int(block), int(min_units), mean_units, int(max_units), int(chunks));
    return buf;
}

long colouring_conflicts(const Colouring& c, index_t num_resources, const ResourceFn& resources) {
    const index_t nu = (c.num_items + c.block - 1) / c.block;
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

template ResourceFn edge_scatter_resources(const EdgeModel<double>&);
template ResourceFn edge_scatter_resources(const EdgeModel<float>&);
template ResourceFn tsep_strain_resources(const EdgeModel<double>&);
template ResourceFn tsep_strain_resources(const EdgeModel<float>&);
template ResourceFn tsep_stiffness_resources(const EdgeModel<double>&);
template ResourceFn tsep_stiffness_resources(const EdgeModel<float>&);
template ResourceFn tet_scatter_resources(const TetModel<double>&);
template ResourceFn tet_scatter_resources(const TetModel<float>&);

}  // namespace edgefem
