// Partition-aware colouring (issue #5): on meshes renumbered by the `metis`
// ordering, the edges whose first vertex lies in one METIS part form a
// contiguous range, and those ranges are the colouring's units for the edge
// scatter (forces, K x, diagonal blocks) and the TSEP segments (g, K).
// Checked here: the parts are what the ordering numbers contiguously, the
// part-unit colourings are conflict-free against write sets built from the
// Topology and cover every item once, and the colour variant with part
// units matches core's serial kernels to 1e-12 and is bitwise identical for
// 1-4 threads (OpenMP and TBB). Variable units equal to fixed blocks give the
// blocked colouring.
#include <gtest/gtest.h>

#include <cstring>

#include "lab/deformations.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/parallel/executors.hpp"
#include "executor_kinds.hpp"
#include "cpu/parallel_edge_kernels.hpp"
#include "cpu/cpu_operator.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"
#include "models.hpp"
#include "test_meshes.hpp"
#include "write_sets.hpp"

using namespace edgefem;
using edgefem::test::rel_diff;

namespace {

// A mesh renumbered by the metis ordering, with its parts.
struct PartMesh {
    std::string name;
    Mesh mesh;
    std::vector<index_t> part_first;
};

// Each test mesh (up to 20000 tets) in metis order with the default parts
// (sized for L2: one part on box-1200, 3 on bunny-4k, 5 on armadillo-7k) and
// with 32 KiB parts (about 27 vertices: many parts, so that colours hold
// several concurrent units even on the small meshes).
const std::vector<PartMesh>& part_meshes() {
    static const auto list = [] {
        std::vector<PartMesh> v;
        for (const auto& nm : test::test_meshes(20000))
            for (std::size_t bytes : {std::size_t(512 * 1024), std::size_t(32 * 1024)}) {
                OrderingOptions o;
                o.part_bytes = bytes;
                PartitionedOrdering po = vertex_ordering_with_parts(nm.mesh, Ordering::MetisKway, o);
                v.push_back({nm.name + "/parts-" + std::to_string(bytes / 1024) + "k", permute_mesh(nm.mesh, po.new_of_old),
                             std::move(po.part_first)});
            }
        return v;
    }();
    return list;
}

using test::bitwise_equal;

// Every item of [0, n) exactly once over all colours.
bool covers_once(const Colouring& c, index_t n) {
    std::vector<int> seen(n, 0);
    for (int col = 0; col < c.colours(); ++col)
        for (index_t x = c.colour_first[col]; x < c.colour_first[col + 1]; ++x)
            for (index_t i = c.unit_begin(c.units[x]); i < c.unit_end(c.units[x]); ++i) {
                if (i < 0 || i >= n) return false;
                ++seen[i];
            }
    return std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; });
}

struct Outputs {
    std::vector<double> f, g, K, y, D;
};

Outputs run_core(const EdgeModel<double>& m, const std::vector<double>& u, const std::vector<double>& x) {
    Outputs o;
    o.f.resize(u.size());
    o.y.resize(u.size());
    o.D.resize(3 * u.size());
    EdgeState<double> st;
    edge_forces<ModelKind::FE, false>(m, u.data(), o.f.data(), st);
    o.g = st.g;
    EdgeStiffness<double> K;
    edge_stiffness_all<ModelKind::FE>(m, st, K);
    o.K.assign(K.K.begin(), K.K.end() - 9);
    edge_multiply(m, K, x.data(), o.y.data());
    edge_diagonal_blocks(m, K, o.D.data());
    return o;
}

// The colour variant with TSEP-list stiffness, so that the segment units
// drive the g pass and the stiffness pass.
Outputs run_parallel(const EdgeModel<double>& m, std::shared_ptr<const Executor> ex, const PlanOptions& opts,
                     const std::vector<double>& u, const std::vector<double>& x) {
    const ParallelEdgeKernels<double> k(m, std::move(ex), Variant::Colour, opts);
    Outputs o;
    o.f.assign(u.size(), 7.0);  // garbage: the kernels overwrite
    o.y.assign(u.size(), 7.0);
    o.D.assign(3 * u.size(), 7.0);
    EdgeState<double> st;
    k.forces<ModelKind::FE, false>(u.data(), o.f.data(), st);
    o.g = st.g;
    EdgeStiffness<double> K;
    k.stiffness<ModelKind::FE>(st, K);
    o.K.assign(K.K.begin(), K.K.begin() + 9 * std::size_t(m.num_edges()));
    k.multiply(K, x.data(), o.y.data());
    k.diagonal_blocks(K, o.D.data());
    return o;
}

PlanOptions part_plan(const EdgeModel<double>& m, const std::vector<index_t>& part_first) {
    PlanOptions o;
    o.vertex_colouring = part_vertex_colouring(part_first, blocked_vertex_colouring());
    o.segment_colouring = part_colouring(m, part_first, blocked_colouring());
    return o;
}

}  // namespace

TEST(PartitionOrdering, PartsAreContiguousBalancedAndMatchTheOrdering) {
    const Mesh mesh = make_box(20, 10, 10);
    OrderingOptions opt;
    opt.part_bytes = 64 * 1024;  // 2541 vertices * 1200 B / 64 KiB -> 47 parts
    const PartitionedOrdering po = vertex_ordering_with_parts(mesh, Ordering::MetisKway, opt);
    const index_t nv = mesh.num_vertices();
    EXPECT_EQ(po.new_of_old, vertex_ordering(mesh, Ordering::MetisKway, opt));
    ASSERT_GE(po.num_parts(), 2);
    EXPECT_LE(po.num_parts(), index_t(std::ceil(nv * opt.bytes_per_vertex / double(opt.part_bytes))));
    EXPECT_EQ(po.part_first.front(), 0);
    EXPECT_EQ(po.part_first.back(), nv);
    for (index_t p = 0; p < po.num_parts(); ++p) {
        EXPECT_LT(po.part_first[p], po.part_first[p + 1]);  // no empty part
        // METIS balances to about 3 %; allow 10 % over the mean.
        EXPECT_LE(po.part_first[p + 1] - po.part_first[p], 1.1 * nv / po.num_parts() + 1);
    }
    // vertex_parts agrees with part_first, and the parts are METIS-like: far
    // fewer graph edges cross parts than cross the same number of equal
    // ranges of a shuffled numbering (~ all of them).
    const std::vector<index_t> part = vertex_parts(po.part_first);
    ASSERT_EQ(index_t(part.size()), nv);
    for (index_t p = 0; p < po.num_parts(); ++p) {
        EXPECT_EQ(part[po.part_first[p]], p);
        EXPECT_EQ(part[po.part_first[p + 1] - 1], p);
    }
    std::vector<index_t> off, adj;
    vertex_graph(mesh, off, adj);
    std::size_t cut = 0;
    for (index_t v = 0; v < nv; ++v)
        for (index_t k = off[v]; k < off[v + 1]; ++k) cut += part[po.new_of_old[v]] != part[po.new_of_old[adj[k]]];
    EXPECT_LT(double(cut) / adj.size(), 0.35);
    // The other orderings, and a mesh small enough for one part: one part.
    for (Ordering o : {Ordering::Input, Ordering::RCM, Ordering::Morton}) {
        const PartitionedOrdering one = vertex_ordering_with_parts(mesh, o);
        EXPECT_EQ(one.part_first, (std::vector<index_t>{0, nv}));
        EXPECT_EQ(one.new_of_old, vertex_ordering(mesh, o));
    }
    const Mesh small = make_box(3, 3, 3);
    EXPECT_EQ(vertex_ordering_with_parts(small, Ordering::MetisKway).num_parts(), 1);
    EXPECT_THROW(vertex_parts({1, 2}), InvalidArgument);
}

TEST(PartitionColouring, UnitsAreThePartsEdgeRanges) {
    for (const auto& pm : part_meshes()) {
        SCOPED_TRACE(pm.name);
        const Topology topo = build_topology(pm.mesh);
        const std::vector<index_t> units = units_from_vertex_parts(topo.first_edge, pm.part_first);
        ASSERT_GE(units.size(), 2u);
        EXPECT_EQ(units.front(), 0);
        EXPECT_EQ(units.back(), topo.num_edges());
        // Unit boundaries are exactly the first edges of the parts (those
        // that own edges), and every edge of a unit has its V0 in one part.
        const std::vector<index_t> part = vertex_parts(pm.part_first);
        for (std::size_t k = 0; k + 1 < units.size(); ++k) {
            ASSERT_LT(units[k], units[k + 1]);
            const index_t p = part[topo.edges[units[k]][0]];
            EXPECT_EQ(units[k], topo.first_edge[pm.part_first[p]]);
            for (index_t e = units[k]; e < units[k + 1]; ++e) ASSERT_EQ(part[topo.edges[e][0]], p);
        }
    }
    // Validation.
    const std::vector<index_t> first_edge{0, 2, 2, 5};  // 3 vertices, 5 items; vertex 1 owns none
    EXPECT_EQ(units_from_vertex_parts(first_edge, std::vector<index_t>{0, 1, 2, 3}), (std::vector<index_t>{0, 2, 5}));
    EXPECT_THROW(units_from_vertex_parts(first_edge, std::vector<index_t>{0, 2}), InvalidArgument);
    EXPECT_THROW(units_from_vertex_parts(first_edge, std::vector<index_t>{0, 2, 1, 3}), InvalidArgument);
    ColouringOptions bad;
    bad.unit_first = {0, 3, 2, 5};
    const ResourceFn none = [](index_t, std::vector<index_t>&) {};
    EXPECT_THROW(colour_items(5, 1, none, bad), InvalidArgument);
    bad.unit_first = {0, 4};
    EXPECT_THROW(colour_items(5, 1, none, bad), InvalidArgument);
}

TEST(PartitionColouring, ConflictFreeAndCoverEveryItemOnce) {
    for (const auto& pm : part_meshes()) {
        SCOPED_TRACE(pm.name);
        const auto models = test::make_models<double>(pm.mesh);
        const auto& m = models.edge;
        const Topology& topo = models.topo;
        // Independent write sets, from the topology rather than the model.
        const ResourceFn edge_w = test::edge_write_set(topo);
        const ResourceFn seg_w = test::vertex_segment_write_set(topo);
        const ResourceFn tsep_w = test::tsep_strain_write_set(topo);
        const ResourceFn stiff_w = test::tsep_stiffness_write_set(topo);
        for (bool balance : {true, false}) {
            ColouringOptions base;
            base.balance = balance;
            const ColouringOptions o = part_colouring(m, pm.part_first, base);
            // The parts themselves as units of vertex segments.
            const Colouring cv = colour_vertex_segments(m, part_vertex_colouring(pm.part_first, base));
            EXPECT_EQ(colouring_conflicts(cv, m.num_vertices, seg_w), 0);
            EXPECT_TRUE(covers_once(cv, m.num_vertices));
            EXPECT_EQ(cv.num_units(), index_t(pm.part_first.size() - 1));
            const Colouring ce = colour_edges(m, o), ct = colour_tsep_strain(m, o), cs = colour_tsep_stiffness(m, o);
            EXPECT_EQ(colouring_conflicts(ce, m.num_vertices, edge_w), 0);
            EXPECT_EQ(colouring_conflicts(ct, m.num_edges(), tsep_w), 0);
            EXPECT_EQ(colouring_conflicts(cs, m.num_edges(), stiff_w), 0);
            for (const Colouring* c : {&ce, &ct, &cs}) {
                EXPECT_TRUE(covers_once(*c, m.num_edges()));
                EXPECT_EQ(c->unit_first, o.unit_first);
                EXPECT_EQ(c->block, 0);
                EXPECT_EQ(c->num_units(), index_t(o.unit_first.size() - 1));
                // Whole parts per chunk: a part (hundreds of edges or more) is
                // at least the chunk size, so each chunk is one part.
                const ColouringStats s = c->stats();
                EXPECT_EQ(s.units, c->num_units()) << s.describe();
                EXPECT_LE(s.min_items, s.max_items);
            }
            // Fewer colours than units once there are many parts.
            if (ce.num_units() >= 40) {
                EXPECT_LT(ce.colours(), ce.num_units() / 2) << ce.stats().describe();
            }
        }
        // The checker catches a colouring that runs adjacent parts together.
        const ColouringOptions o = part_colouring(m, pm.part_first);
        Colouring bad = colour_edges(m, o);
        if (bad.num_units() > 1) {
            bad.colour_first = {0, index_t(bad.units.size())};
            bad.chunk_first = {0, 1};
            bad.chunk_units = {index_t(bad.units.size())};
            EXPECT_GT(colouring_conflicts(bad, m.num_vertices, edge_w), 0);
            Colouring gap = colour_edges(m, o);  // unit ranges that miss the last item
            gap.unit_first.back() -= 1;
            EXPECT_EQ(colouring_conflicts(gap, m.num_vertices, edge_w), -1);
        }
    }
}

// Variable units that happen to be fixed blocks colour exactly like blocks
// (same units, same colours): the unit_first path changes only where the
// unit boundaries come from.
TEST(PartitionColouring, VariableUnitsEqualToBlocksColourLikeBlocks) {
    const auto& pm = part_meshes().back();
    const auto models = test::make_models<double>(pm.mesh);
    const auto& m = models.edge;
    for (index_t block : {1, 7, 64}) {
        ColouringOptions fixed;
        fixed.block = block;
        ColouringOptions var;
        for (index_t b = 0; b < m.num_edges(); b += block) var.unit_first.push_back(b);
        var.unit_first.push_back(m.num_edges());
        const Colouring a = colour_edges(m, fixed), b = colour_edges(m, var);
        EXPECT_EQ(a.colour_first, b.colour_first) << block;
        EXPECT_EQ(a.units, b.units) << block;
        EXPECT_EQ(a.block, block);
        EXPECT_TRUE(a.unit_first.empty());
        for (index_t u = 0; u < a.num_units(); ++u) {
            ASSERT_EQ(a.unit_begin(u), b.unit_begin(u));
            ASSERT_EQ(a.unit_end(u), b.unit_end(u));
        }
    }
}

TEST(PartitionColouring, KernelsMatchCoreAndAreBitwiseEqualAcrossThreads) {
    std::vector<std::pair<std::string, std::shared_ptr<const Executor>>> executors;
    for (ExecutorKind b : test::threaded_executor_kinds())
        for (int t : {1, 2, 3, 4}) executors.emplace_back(std::string(to_string(b)) + "-" + std::to_string(t), make_executor(b, t));
    for (const auto& pm : part_meshes()) {
        const auto models = test::make_models<double>(pm.mesh);
        const auto& m = models.edge;
        const auto u = deformation_displacement(pm.mesh, Deformation::Twist);
        const auto x = deformation_displacement(pm.mesh, Deformation::Random);
        const Outputs core = run_core(m, u, x);
        const PlanOptions opts = part_plan(m, pm.part_first);
        const Outputs serial = run_parallel(m, std::make_shared<SerialExecutor>(), opts, u, x);
        EXPECT_LE(rel_diff(serial.f, core.f), 1e-12) << pm.name;
        EXPECT_LE(rel_diff(serial.g, core.g), 1e-12) << pm.name;
        EXPECT_LE(rel_diff(serial.K, core.K), 1e-12) << pm.name;
        EXPECT_LE(rel_diff(serial.y, core.y), 1e-12) << pm.name;
        EXPECT_LE(rel_diff(serial.D, core.D), 1e-12) << pm.name;
        for (const auto& [name, ex] : executors) {
            const std::string tag = pm.name + "/" + name;
            const Outputs par = run_parallel(m, ex, opts, u, x);
            EXPECT_TRUE(bitwise_equal(par.f, serial.f)) << tag << ": forces " << rel_diff(par.f, serial.f);
            EXPECT_TRUE(bitwise_equal(par.g, serial.g)) << tag << ": g " << rel_diff(par.g, serial.g);
            EXPECT_TRUE(bitwise_equal(par.K, serial.K)) << tag << ": K " << rel_diff(par.K, serial.K);
            EXPECT_TRUE(bitwise_equal(par.y, serial.y)) << tag << ": K x " << rel_diff(par.y, serial.y);
            EXPECT_TRUE(bitwise_equal(par.D, serial.D)) << tag << ": diagonal " << rel_diff(par.D, serial.D);
        }
    }
}

// The hook an application uses: part units passed through PlanOptions to
// the parallel operator (which builds its own model from the mesh).
TEST(PartitionColouring, ParallelOperatorTakesPartUnitsThroughPlanOptions) {
    const auto& pm = part_meshes().back();
    const auto models = test::make_models<double>(pm.mesh);
    const PlanOptions opts = part_plan(models.edge, pm.part_first);
    const Material mat{1e5, 0.3, 1000};
    const auto u = deformation_displacement(pm.mesh, Deformation::Twist);
    std::vector<double> f_ref(u.size()), f(u.size()), y_ref(u.size()), y(u.size());
    auto ref = make_cpu_operator<double>(pm.mesh, mat, ModelKind::FE, Method::Edge);
    ref->forces(u.data(), f_ref.data(), false);
    ref->build_stiffness(false);
    ref->multiply(u.data(), y_ref.data());
    for (int threads : {1, 2}) {
        auto op = make_cpu_operator<double>(pm.mesh, mat, ModelKind::FE, Method::Edge, CpuOptions{make_executor(ExecutorKind::OpenMP, threads), Variant::Colour}, opts);
        op->forces(u.data(), f.data(), false);
        op->build_stiffness(false);
        op->multiply(u.data(), y.data());
        EXPECT_LE(rel_diff(f, f_ref), 1e-12) << threads;
        EXPECT_LE(rel_diff(y, y_ref), 1e-12) << threads;
    }
    // Parts of another mesh do not fit: rejected when the plan is built.
    PlanOptions wrong = opts;
    wrong.vertex_colouring.unit_first.back() += 1;
    EXPECT_THROW(make_cpu_operator<double>(pm.mesh, mat, ModelKind::FE, Method::Edge, CpuOptions{make_executor(ExecutorKind::OpenMP, 1), Variant::Colour}, wrong),
                 InvalidArgument);
}
