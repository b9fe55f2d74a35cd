#include "edgefem/partition/ordering.hpp"

#include <metis.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "edgefem/core/error.hpp"
#include "edgefem/core/topology.hpp"

namespace edgefem {

Ordering parse_ordering(const std::string& name) {
    for (Ordering o : all_orderings())
        if (name == to_string(o)) return o;
    throw InvalidArgument("unknown ordering '" + name + "' (expected input, random, rcm, morton, nd or metis)");
}

const char* to_string(Ordering o) {
    switch (o) {
        case Ordering::Input: return "input";
        case Ordering::Random: return "random";
        case Ordering::RCM: return "rcm";
        case Ordering::Morton: return "morton";
        case Ordering::NestedDissection: return "nd";
        default: return "metis";
    }
}

std::vector<Ordering> all_orderings() {
    return {Ordering::Input, Ordering::Random, Ordering::RCM, Ordering::Morton, Ordering::NestedDissection,
            Ordering::MetisKway};
}

void vertex_graph(const Mesh& mesh, std::vector<index_t>& offsets, std::vector<index_t>& adjacency) {
    const index_t nv = mesh.num_vertices();
    std::vector<index_t> count(std::size_t(nv) + 1, 0);
    for (index_t t = 0; t < mesh.num_tets(); ++t)
        for (const auto& e : kTetEdge) {
            ++count[mesh.tets[4 * std::size_t(t) + e[0]] + 1];
            ++count[mesh.tets[4 * std::size_t(t) + e[1]] + 1];
        }
    for (index_t v = 0; v < nv; ++v) count[v + 1] += count[v];
    std::vector<index_t> all(count[nv]);
    std::vector<index_t> fill(count.begin(), count.end() - 1);
    for (index_t t = 0; t < mesh.num_tets(); ++t)
        for (const auto& e : kTetEdge) {
            const index_t a = mesh.tets[4 * std::size_t(t) + e[0]], b = mesh.tets[4 * std::size_t(t) + e[1]];
            all[fill[a]++] = b;
            all[fill[b]++] = a;
        }
    offsets.assign(std::size_t(nv) + 1, 0);
    adjacency.clear();
    adjacency.reserve(all.size() / 4);
    for (index_t v = 0; v < nv; ++v) {
        auto lo = all.begin() + count[v], hi = all.begin() + count[v + 1];
        std::sort(lo, hi);
        hi = std::unique(lo, hi);
        adjacency.insert(adjacency.end(), lo, hi);
        offsets[v + 1] = static_cast<index_t>(adjacency.size());
    }
}

namespace {

std::vector<index_t> identity(index_t n) {
    std::vector<index_t> p(n);
    std::iota(p.begin(), p.end(), 0);
    return p;
}

// new_of_old from a visiting order (order[k] = the vertex numbered k).
std::vector<index_t> from_order(const std::vector<index_t>& order) {
    std::vector<index_t> p(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) p[order[k]] = static_cast<index_t>(k);
    return p;
}

// Breadth-first from `start` over unvisited vertices, neighbours by
// increasing degree; appends to `order`, returns the last level's start.
std::size_t bfs(index_t start, const std::vector<index_t>& off, const std::vector<index_t>& adj,
                std::vector<char>& visited, std::vector<index_t>& order) {
    const std::size_t first = order.size();
    order.push_back(start);
    visited[start] = 1;
    std::size_t head = first, level_start = first, level_end = first + 1;
    std::vector<index_t> next;
    while (head < order.size()) {
        if (head == level_end) {
            level_start = level_end;
            level_end = order.size();
        }
        const index_t v = order[head++];
        next.clear();
        for (index_t k = off[v]; k < off[v + 1]; ++k)
            if (!visited[adj[k]]) {
                visited[adj[k]] = 1;
                next.push_back(adj[k]);
            }
        std::sort(next.begin(), next.end(), [&](index_t a, index_t b) {
            const index_t da = off[a + 1] - off[a], db = off[b + 1] - off[b];
            return da != db ? da < db : a < b;
        });
        order.insert(order.end(), next.begin(), next.end());
    }
    return level_start;
}

std::vector<index_t> rcm(const Mesh& mesh) {
    std::vector<index_t> off, adj;
    vertex_graph(mesh, off, adj);
    const index_t nv = mesh.num_vertices();
    std::vector<index_t> by_degree = identity(nv);
    std::stable_sort(by_degree.begin(), by_degree.end(),
                     [&](index_t a, index_t b) { return off[a + 1] - off[a] < off[b + 1] - off[b]; });
    std::vector<char> visited(nv, 0), scratch(nv, 0);
    std::vector<index_t> order, probe;
    order.reserve(nv);
    for (index_t s : by_degree) {
        if (visited[s]) continue;
        // Pseudo-peripheral start: two sweeps, each restarting from a
        // minimum-degree vertex of the deepest level.
        index_t start = s;
        for (int sweep = 0; sweep < 2; ++sweep) {
            probe.clear();
            std::fill(scratch.begin(), scratch.end(), 0);
            for (index_t v = 0; v < nv; ++v) scratch[v] = visited[v];
            const std::size_t last = bfs(start, off, adj, scratch, probe);
            index_t best = probe[last];
            for (std::size_t k = last; k < probe.size(); ++k)
                if (off[probe[k] + 1] - off[probe[k]] < off[best + 1] - off[best]) best = probe[k];
            start = best;
        }
        bfs(start, off, adj, visited, order);
    }
    std::reverse(order.begin(), order.end());
    return from_order(order);
}

std::vector<index_t> morton(const Mesh& mesh) {
    const index_t nv = mesh.num_vertices();
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (index_t v = 0; v < nv; ++v)
        for (int r = 0; r < 3; ++r) {
            lo[r] = std::min(lo[r], mesh.X[3 * std::size_t(v) + r]);
            hi[r] = std::max(hi[r], mesh.X[3 * std::size_t(v) + r]);
        }
    const double span = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
    auto spread = [](std::uint64_t x) {  // 21 bits -> every third bit
        x &= 0x1fffff;
        x = (x | x << 32) & 0x1f00000000ffffULL;
        x = (x | x << 16) & 0x1f0000ff0000ffULL;
        x = (x | x << 8) & 0x100f00f00f00f00fULL;
        x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
        x = (x | x << 2) & 0x1249249249249249ULL;
        return x;
    };
    std::vector<std::pair<std::uint64_t, index_t>> key(nv);
    for (index_t v = 0; v < nv; ++v) {
        std::uint64_t k = 0;
        for (int r = 0; r < 3; ++r) {
            const double t = (mesh.X[3 * std::size_t(v) + r] - lo[r]) / span;
            k |= spread(static_cast<std::uint64_t>(std::min(t, 1.0) * 2097151.0)) << r;
        }
        key[v] = {k, v};
    }
    std::sort(key.begin(), key.end());
    std::vector<index_t> order(nv);
    for (index_t k = 0; k < nv; ++k) order[k] = key[k].second;
    return from_order(order);
}

void check_metis(int status, const char* what) {
    if (status != METIS_OK) throw Error(std::string("METIS ") + what + " failed (status " + std::to_string(status) + ")");
}

std::vector<index_t> nested_dissection(const Mesh& mesh) {
    std::vector<index_t> off, adj;
    vertex_graph(mesh, off, adj);
    idx_t nv = mesh.num_vertices();
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    std::vector<idx_t> xadj(off.begin(), off.end()), adjncy(adj.begin(), adj.end()), perm(nv), iperm(nv);
    check_metis(METIS_NodeND(&nv, xadj.data(), adjncy.data(), nullptr, options, perm.data(), iperm.data()), "NodeND");
    return std::vector<index_t>(iperm.begin(), iperm.end());  // iperm[old] = new
}

PartitionedOrdering one_part(std::vector<index_t> new_of_old) {
    PartitionedOrdering r;
    r.part_first = {0, static_cast<index_t>(new_of_old.size())};
    r.new_of_old = std::move(new_of_old);
    return r;
}

PartitionedOrdering metis_kway(const Mesh& mesh, const OrderingOptions& opt) {
    const index_t nv = mesh.num_vertices();
    const double parts = std::ceil(nv * opt.bytes_per_vertex / double(opt.part_bytes));
    std::vector<index_t> inner = rcm(mesh);
    if (parts < 2) return one_part(std::move(inner));
    std::vector<index_t> off, adj;
    vertex_graph(mesh, off, adj);
    idx_t n = nv, ncon = 1, nparts = static_cast<idx_t>(parts), objval = 0;
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    std::vector<idx_t> xadj(off.begin(), off.end()), adjncy(adj.begin(), adj.end()), part(nv);
    check_metis(METIS_PartGraphKway(&n, &ncon, xadj.data(), adjncy.data(), nullptr, nullptr, nullptr, &nparts, nullptr,
                                    nullptr, options, &objval, part.data()),
                "PartGraphKway");
    // Parts in the order of their vertices' mean RCM rank (neighbouring parts
    // stay close); inside a part, the RCM order.
    std::vector<double> mean(nparts, 0.0);
    std::vector<index_t> size(nparts, 0);
    for (index_t v = 0; v < nv; ++v) {
        mean[part[v]] += inner[v];
        ++size[part[v]];
    }
    for (idx_t p = 0; p < nparts; ++p) mean[p] = size[p] ? mean[p] / size[p] : 0.0;
    std::vector<index_t> order = identity(nv);
    std::sort(order.begin(), order.end(), [&](index_t a, index_t b) {
        if (part[a] != part[b]) return mean[part[a]] != mean[part[b]] ? mean[part[a]] < mean[part[b]] : part[a] < part[b];
        return inner[a] < inner[b];
    });
    PartitionedOrdering r;
    r.part_first.push_back(0);
    for (index_t k = 1; k < nv; ++k)
        if (part[order[k]] != part[order[k - 1]]) r.part_first.push_back(k);
    r.part_first.push_back(nv);
    r.new_of_old = from_order(order);
    return r;
}

}  // namespace

std::vector<index_t> vertex_ordering(const Mesh& mesh, Ordering kind, const OrderingOptions& options) {
    switch (kind) {
        case Ordering::Input: return identity(mesh.num_vertices());
        case Ordering::Random: {
            std::vector<index_t> order = identity(mesh.num_vertices());
            std::shuffle(order.begin(), order.end(), std::mt19937_64(options.seed));
            return from_order(order);
        }
        case Ordering::RCM: return rcm(mesh);
        case Ordering::Morton: return morton(mesh);
        case Ordering::NestedDissection: return nested_dissection(mesh);
        default: return metis_kway(mesh, options).new_of_old;
    }
}

PartitionedOrdering vertex_ordering_with_parts(const Mesh& mesh, Ordering kind, const OrderingOptions& options) {
    if (kind == Ordering::MetisKway) return metis_kway(mesh, options);
    return one_part(vertex_ordering(mesh, kind, options));
}

std::vector<index_t> vertex_parts(const std::vector<index_t>& part_first) {
    if (part_first.empty() || part_first.front() != 0) throw InvalidArgument("vertex_parts: part_first must start at 0");
    std::vector<index_t> out(std::size_t(part_first.back()));
    for (std::size_t p = 0; p + 1 < part_first.size(); ++p) {
        if (part_first[p + 1] < part_first[p]) throw InvalidArgument("vertex_parts: part_first decreases");
        std::fill(out.begin() + part_first[p], out.begin() + part_first[p + 1], static_cast<index_t>(p));
    }
    return out;
}

Bandwidth ordering_bandwidth(const Mesh& mesh, const std::vector<index_t>& new_of_old, index_t window) {
    std::vector<index_t> off, adj;
    vertex_graph(mesh, off, adj);
    Bandwidth b;
    double sum = 0;
    std::size_t near = 0;
    for (index_t v = 0; v < mesh.num_vertices(); ++v)
        for (index_t k = off[v]; k < off[v + 1]; ++k) {
            const index_t d = std::abs(new_of_old[v] - new_of_old[adj[k]]);
            sum += d;
            near += d <= window;
            b.max = std::max(b.max, d);
        }
    b.mean = adj.empty() ? 0.0 : sum / adj.size();
    b.near = adj.empty() ? 0.0 : double(near) / adj.size();
    return b;
}

}  // namespace edgefem
