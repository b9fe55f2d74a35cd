// Parallel back-ends: every kernel (forces + energy, stiffness, K x,
// diagonal blocks) under OpenMP and TBB at 1, 2, 3, 4 and 8 threads (and the cores present, above 8).
// Colour and gather: bitwise equal across thread counts and to the
// SerialExecutor run of the same variant. Atomic and private: within 1e-12
// of it. Every variant: within 1e-12 of core's serial kernels. The same
// with the FE stiffness from the tet-local form. Colourings: conflict-free.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "lab/deformations.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/parallel/executors.hpp"
#include "executor_kinds.hpp"
#include "cpu/parallel_edge_kernels.hpp"
#include "cpu/parallel_tet_kernels.hpp"
#include "models.hpp"
#include "test_meshes.hpp"
#include "test_threads.hpp"
#include "write_sets.hpp"

using namespace edgefem;
using edgefem::test::rel_diff;

namespace {

constexpr long kMaxTets = 5000;
// Above this size no more threads than cores run (test_threads.hpp;
// correctness is covered by the smaller meshes at every count).
constexpr long kOversubscribeMaxTets = 1500;  // generated boxes and box-1200

const std::vector<edgefem::test::NamedMesh>& meshes() {
    static const auto m = edgefem::test::test_meshes(kMaxTets);
    return m;
}

struct NamedExecutor {
    std::string name;
    std::shared_ptr<const Executor> ex;
};

const std::vector<NamedExecutor>& executors() {
    static const auto list = [] {
        std::vector<NamedExecutor> v;
        for (ExecutorKind b : test::threaded_executor_kinds())
            for (int t : edgefem::test::test_thread_counts())
                for (Schedule s : {Schedule::Dynamic, Schedule::Static}) {
                    if (s == Schedule::Static && t != 3) continue;  // one static run per backend
                    v.push_back({std::string(to_string(b)) + "-" + std::to_string(t) + "-" + to_string(s),
                                 make_executor(b, t, s)});
                }
        return v;
    }();
    return list;
}

using test::bitwise_equal;

// The outputs of one run of every kernel.
template <class S>
struct Outputs {
    double W = 0;
    std::vector<S> f, K, Kdef, y, D;
    std::vector<double> g;
};

template <ModelKind Kind, class S>
Outputs<S> run_parallel(const EdgeModel<S>& model, std::shared_ptr<const Executor> ex, Variant v,
                        const std::vector<S>& u, const std::vector<S>& x, const PlanOptions& opts = {},
                        const TetEdgeForm<S>& form = {}) {
    ParallelEdgeKernels<S> k(model, std::move(ex), v, opts, form);
    Outputs<S> o;
    o.f.assign(u.size(), S(7));  // garbage: the kernels overwrite
    o.y.assign(u.size(), S(7));
    o.D.assign(3 * u.size(), S(7));
    EdgeState<S> st;
    o.W = k.template forces<Kind, true>(u.data(), o.f.data(), st);
    // A second call on the same object must give the same (buffers reset).
    std::vector<S> f2(u.size());
    const double W2 = k.template forces<Kind, true>(u.data(), f2.data(), st);
    if (is_deterministic(v)) {
        EXPECT_EQ(W2, o.W);
        EXPECT_TRUE(bitwise_equal(f2, o.f));
    } else {
        EXPECT_LE(rel_diff(f2, o.f), (std::is_same_v<S, double> ? 1e-12 : 1e-5));
    }
    o.g = st.g;
    EdgeStiffness<S> Kd;
    k.template stiffness<Kind, true>(st, Kd);
    o.Kdef.assign(Kd.K.begin(), Kd.K.begin() + 9 * std::size_t(model.num_edges()));
    EdgeStiffness<S> K;
    k.template stiffness<Kind, false>(st, K);
    k.template stiffness<Kind, false>(st, K);
    o.K.assign(K.K.begin(), K.K.begin() + 9 * std::size_t(model.num_edges()));
    k.multiply(K, x.data(), o.y.data());
    k.diagonal_blocks(K, o.D.data());
    return o;
}

template <ModelKind Kind, class S>
Outputs<S> run_core(const EdgeModel<S>& m, const std::vector<S>& u, const std::vector<S>& x) {
    Outputs<S> o;
    o.f.resize(u.size());
    o.y.resize(u.size());
    o.D.resize(3 * u.size());
    EdgeState<S> st;
    o.W = edge_forces<Kind, true>(m, u.data(), o.f.data(), st);
    o.g = st.g;
    EdgeStiffness<S> K;
    edge_stiffness_all<Kind, true>(m, st, K);
    o.Kdef.assign(K.K.begin(), K.K.end() - 9);
    edge_stiffness_all<Kind, false>(m, st, K);
    o.K.assign(K.K.begin(), K.K.end() - 9);
    edge_multiply(m, K, x.data(), o.y.data());
    edge_diagonal_blocks(m, K, o.D.data());
    return o;
}

template <class S>
void expect_bitwise(const Outputs<S>& a, const Outputs<S>& b, const std::string& what) {
    EXPECT_EQ(a.W, b.W) << what;
    EXPECT_TRUE(bitwise_equal(a.f, b.f)) << what << ": forces " << rel_diff(a.f, b.f);
    EXPECT_TRUE(bitwise_equal(a.g, b.g)) << what << ": g " << rel_diff(a.g, b.g);
    EXPECT_TRUE(bitwise_equal(a.K, b.K)) << what << ": K " << rel_diff(a.K, b.K);
    EXPECT_TRUE(bitwise_equal(a.Kdef, b.Kdef)) << what << ": definite K " << rel_diff(a.Kdef, b.Kdef);
    EXPECT_TRUE(bitwise_equal(a.y, b.y)) << what << ": K x " << rel_diff(a.y, b.y);
    EXPECT_TRUE(bitwise_equal(a.D, b.D)) << what << ": diagonal " << rel_diff(a.D, b.D);
}

template <class S>
void expect_close(const Outputs<S>& a, const Outputs<S>& b, double tol, const std::string& what) {
    EXPECT_LE(std::abs(a.W - b.W), tol * std::abs(b.W)) << what;
    EXPECT_LE(rel_diff(a.f, b.f), tol) << what << ": forces";
    EXPECT_LE(rel_diff(a.g, b.g), tol) << what << ": g";
    EXPECT_LE(rel_diff(a.K, b.K), tol) << what << ": K";
    EXPECT_LE(rel_diff(a.Kdef, b.Kdef), tol) << what << ": definite K";
    EXPECT_LE(rel_diff(a.y, b.y), tol) << what << ": K x";
    EXPECT_LE(rel_diff(a.D, b.D), tol) << what << ": diagonal";
}

template <ModelKind Kind, class S>
void check_edge_kernels(double core_tol) {
    for (const auto& nm : meshes()) {
        const auto models = edgefem::test::make_models<S>(nm.mesh);
        const auto ud = deformation_displacement(nm.mesh, Deformation::Twist);
        const auto xd = deformation_displacement(nm.mesh, Deformation::Random);
        const std::vector<S> u(ud.begin(), ud.end()), x(xd.begin(), xd.end());
        const Outputs<S> core = run_core<Kind>(models.edge, u, x);
        TetEdgeForm<S> form;
        if (Kind == ModelKind::FE) form = make_tet_edge_form<S>(nm.mesh, models.topo, Materials(Material{1e5, 0.3, 1000}));
        for (bool tet_local : {false, true}) {
            if (tet_local && Kind != ModelKind::FE) continue;
            for (Variant v : kAllVariants) {
                const std::string tag = nm.name + "/" + to_string(v) + (tet_local ? "/tet-local" : "");
                const TetEdgeForm<S>& fm = tet_local ? form : TetEdgeForm<S>{};
                const Outputs<S> serial = run_parallel<Kind>(models.edge, std::make_shared<SerialExecutor>(), v, u, x, {}, fm);
                expect_close(serial, core, core_tol, tag + "/serial vs core");
                for (const auto& ne : executors()) {
                    if (edgefem::test::skip_oversubscribed(nm.mesh.num_tets(), ne.ex->threads(), kOversubscribeMaxTets)) continue;
                    const Outputs<S> par = run_parallel<Kind>(models.edge, ne.ex, v, u, x, {}, fm);
                    if (is_deterministic(v))
                        expect_bitwise(par, serial, tag + "/" + ne.name);
                    else
                        expect_close(par, serial, (std::is_same_v<S, double> ? 1e-12 : core_tol), tag + "/" + ne.name);
                }
            }
        }
    }
}

}  // namespace

TEST(ParallelEdgeKernels, FEDouble) { check_edge_kernels<ModelKind::FE, double>(1e-12); }
TEST(ParallelEdgeKernels, SNDouble) { check_edge_kernels<ModelKind::SN, double>(1e-12); }
// Float: the same determinism; against core only to float round-off.
TEST(ParallelEdgeKernels, FEFloat) { check_edge_kernels<ModelKind::FE, float>(2e-5); }

// Blocked colourings (units of several consecutive items) are as exact.
TEST(ParallelEdgeKernels, BlockedColouringsDeterministic) {
    const auto& nm = meshes()[1];
    const auto models = edgefem::test::make_models<double>(nm.mesh);
    const auto u = deformation_displacement(nm.mesh, Deformation::Twist);
    const auto x = deformation_displacement(nm.mesh, Deformation::Random);
    PlanOptions opts;
    opts.vertex_colouring.block = 3;
    opts.segment_colouring.block = 4;
    opts.segment_colouring.balance = false;
    const auto core = run_core<ModelKind::FE>(models.edge, u, x);
    const auto serial = run_parallel<ModelKind::FE>(models.edge, std::make_shared<SerialExecutor>(), Variant::Colour, u, x, opts);
    expect_close(serial, core, 1e-12, "blocked");
    for (const auto& ne : executors())
        expect_bitwise(run_parallel<ModelKind::FE>(models.edge, ne.ex, Variant::Colour, u, x, opts), serial, ne.name);
}

// Owner variant with many small parts (the default gives the small test
// meshes a single part), with the form in tiles of the default size and of
// 1 and 3 batches: every part spills, and the results are still bitwise the
// same for every thread count and close to core.
TEST(ParallelEdgeKernels, OwnerPartsSpillAndStayDeterministic) {
    for (const auto& nm : meshes()) {
        if (nm.mesh.num_vertices() < 40) continue;
        const auto models = edgefem::test::make_models<double>(nm.mesh);
        const auto u = deformation_displacement(nm.mesh, Deformation::Twist);
        const auto x = deformation_displacement(nm.mesh, Deformation::Random);
        const auto core = run_core<ModelKind::FE>(models.edge, u, x);
        const auto form = make_tet_edge_form<double>(nm.mesh, models.topo, Materials(Material{1e5, 0.3, 1000}));
        for (const auto& [parts, tile] : {std::pair<index_t, index_t>{2, 0}, {7, 0}, {13, 0}, {2, 1}, {7, 3}}) {
            PlanOptions opts;
            opts.owner_parts = parts;
            opts.form_tile_batches = tile;  // small tiles: many per part (FormTile)
            const std::string tag = nm.name + "/owner-" + std::to_string(parts) + "-tile-" + std::to_string(tile);
            const ParallelEdgeKernels<double> probe(models.edge, std::make_shared<SerialExecutor>(), Variant::Owner, opts);
            EXPECT_EQ(probe.vertex_parts().parts(), parts) << tag;
            EXPECT_GT(probe.vertex_parts().spill_targets(), 0u) << tag;
            EXPECT_GT(probe.edge_parts().spill_targets(), 0u) << tag;
            for (bool tet_local : {false, true}) {
                const TetEdgeForm<double>& fm = tet_local ? form : TetEdgeForm<double>{};
                const auto serial = run_parallel<ModelKind::FE>(models.edge, std::make_shared<SerialExecutor>(),
                                                                Variant::Owner, u, x, opts, fm);
                expect_close(serial, core, 1e-12, tag + "/serial vs core");
                for (const auto& ne : executors())
                    expect_bitwise(run_parallel<ModelKind::FE>(models.edge, ne.ex, Variant::Owner, u, x, opts, fm), serial,
                                   tag + "/" + ne.name);
            }
        }
    }
}

// Auto: owner on a numbering with locality (the generated box), gather on
// a shuffled one; bitwise the result of the variant it picks.
TEST(ParallelEdgeKernels, AutoPicksOwnerWithLocalityAndGatherWithout) {
    const Mesh box = make_box(12, 8, 6);
    Mesh shuffled = box;
    const index_t nv = box.num_vertices();
    std::vector<index_t> new_of_old(nv);
    for (index_t v = 0; v < nv; ++v) new_of_old[v] = v;
    std::mt19937 rng(7);
    std::shuffle(new_of_old.begin(), new_of_old.end(), rng);
    for (index_t v = 0; v < nv; ++v)
        for (int r = 0; r < 3; ++r) shuffled.X[3 * std::size_t(new_of_old[v]) + r] = box.X[3 * std::size_t(v) + r];
    for (auto& t : shuffled.tets) t = new_of_old[t];
    for (const auto& [mesh, expected] : {std::pair<const Mesh*, Variant>{&box, Variant::Owner}, std::pair<const Mesh*, Variant>{&shuffled, Variant::Gather}}) {
        const auto models = edgefem::test::make_models<double>(*mesh);
        const auto u = deformation_displacement(*mesh, Deformation::Twist);
        const auto x = deformation_displacement(*mesh, Deformation::Random);
        const auto ex = make_executor(ExecutorKind::OpenMP, 2);
        const ParallelEdgeKernels<double> k(models.edge, ex, Variant::Auto);
        EXPECT_EQ(k.variant(), expected);
        expect_bitwise(run_parallel<ModelKind::FE>(models.edge, ex, Variant::Auto, u, x),
                       run_parallel<ModelKind::FE>(models.edge, ex, expected, u, x), to_string(expected));
    }
    EXPECT_EQ(parse_variant("auto"), Variant::Auto);
}

TEST(ForwardSpill, WindowsAndConsumers) {
    // 10 items in parts {0..2}, {3..5}, {6..9}; item i writes up to last[i].
    const std::vector<index_t> last{1, 4, 2, 3, 8, 5, 6, 9, 8, 9};
    const std::vector<index_t> parts{0, 3, 6, 10};
    const ForwardSpill fs = make_forward_spill(10, parts, [&](index_t i) { return last[i]; });
    ASSERT_EQ(fs.parts(), 3);
    EXPECT_EQ(fs.window_end, (std::vector<index_t>{5, 9, 10}));
    EXPECT_EQ(fs.spill_targets(), std::size_t(2 + 3 + 0));
    // Part 1 reads part 0's window; part 2 reads part 1's (part 0's ends at 5).
    EXPECT_EQ(fs.in_first, (std::vector<index_t>{0, 0, 1, 2}));
    EXPECT_EQ(fs.in_part, (std::vector<index_t>{0, 1}));
    // A backward target, parts that do not cover the items: rejected.
    EXPECT_THROW(make_forward_spill(3, std::vector<index_t>{0, 3}, [](index_t i) { return i == 2 ? index_t(1) : i; }),
                 InvalidArgument);
    EXPECT_THROW(make_forward_spill(3, std::vector<index_t>{0, 2}, [](index_t i) { return i; }), InvalidArgument);
    EXPECT_THROW(make_forward_spill(3, std::vector<index_t>{0, 2, 1, 3}, [](index_t i) { return i; }), InvalidArgument);
    // Balanced parts follow the weights: item 0 weighs as much as the rest.
    EXPECT_EQ(balanced_parts(std::vector<index_t>{0, 6, 7, 8, 9, 10, 11, 12}, 2), (std::vector<index_t>{0, 1, 7}));
    EXPECT_EQ(balanced_parts(std::vector<index_t>{0, 1, 2, 3, 4}, 4), (std::vector<index_t>{0, 1, 2, 3, 4}));
}

// The links of linked phases, worked out by hand from the windows: part 0's
// window [3, 8) holds targets of parts 1 and 2, so its next phase needs
// theirs, and parts 1 and 2 need part 0's to add its window.
TEST(ForwardSpill, PhaseLinks) {
    const std::vector<index_t> last{7, 1, 2, 4, 4, 5, 6, 7, 8, 9, 10, 11};
    const ForwardSpill fs = make_forward_spill(12, std::vector<index_t>{0, 3, 6, 9, 12}, [&](index_t i) { return last[i]; });
    ASSERT_EQ(fs.window_end, (std::vector<index_t>{8, 6, 9, 12}));
    const PhaseLinks links = linked(fs, link_window_reads, link_incoming_adds);
    EXPECT_EQ(links.parts, 4);
    EXPECT_EQ(links.phases(), 3);
    EXPECT_EQ(links.first, (std::vector<index_t>{0, 1, 2, 3, /* incoming */ 0, 0, 0, 3}));
    EXPECT_EQ(links.last, (std::vector<index_t>{2, 1, 2, 3, /* incoming */ 0, 1, 2, 3}));
    // Phases over another part count cannot be linked to these.
    PhaseLinks other = links;
    EXPECT_THROW(link_incoming_adds(other, make_forward_spill(3, std::vector<index_t>{0, 1, 3}, [](index_t i) { return i; })),
                 InvalidArgument);
    EXPECT_EQ(PhaseLinks{}.phases(), 0);
}

TEST(Colourings, ConflictFree) {
    for (const auto& nm : meshes()) {
        const auto models = edgefem::test::make_models<double>(nm.mesh);
        const auto& m = models.edge;
        // Independent write sets, from the topology rather than the model.
        const Topology& topo = models.topo;
        const ResourceFn edge_w = test::edge_write_set(topo);
        const ResourceFn seg_w = test::vertex_segment_write_set(topo);
        const ResourceFn tsep_w = test::tsep_strain_write_set(topo);
        const ResourceFn stiff_w = test::tsep_stiffness_write_set(topo);
        const ResourceFn tet_w = [&](index_t t, std::vector<index_t>& out) {
            for (int k = 0; k < 4; ++k) out.push_back(nm.mesh.tets[4 * std::size_t(t) + k]);
        };
        // A per-tet batch writes its tets' vertices, and vertex 0 for a padding lane.
        const ResourceFn tet_batch_w = [&](index_t b, std::vector<index_t>& out) {
            for (int l = 0; l < kTetBatchLanes; ++l) {
                const index_t t = models.tet.batch_tet(b, l);
                if (t >= models.tet.num_tets()) out.push_back(0);
                else tet_w(t, out);
            }
        };
        for (index_t block : {1, 4, 32}) {
            ColouringOptions o;
            o.block = block;
            const Colouring ce = colour_edges(m, o), ct = colour_tsep_strain(m, o), cs = colour_tsep_stiffness(m, o),
                            cq = colour_tets(models.tet, o), cv = colour_vertex_segments(m, o),
                            cb = colour_tet_batches(models.tet, o);
            EXPECT_EQ(colouring_conflicts(ce, m.num_vertices, edge_w), 0) << nm.name;
            EXPECT_EQ(colouring_conflicts(cv, m.num_vertices, seg_w), 0) << nm.name;
            EXPECT_EQ(colouring_conflicts(ct, m.num_edges(), tsep_w), 0) << nm.name;
            EXPECT_EQ(colouring_conflicts(cs, m.num_edges(), stiff_w), 0) << nm.name;
            EXPECT_EQ(colouring_conflicts(cq, nm.mesh.num_vertices(), tet_w), 0) << nm.name;
            EXPECT_EQ(colouring_conflicts(cb, nm.mesh.num_vertices(), tet_batch_w), 0) << nm.name;
            if (block == 1) {
                // Balanced: no colour more than a few times the mean (greedy alone leaves long tails).
                for (const Colouring* c : {&ce, &ct, &cs, &cq}) {
                    const ColouringStats s = c->stats();
                    EXPECT_LE(s.max_units, 2 * s.mean_units + 2) << nm.name << " " << s.describe();
                }
            }
        }
        // The tet-local stiffness's batch colouring: a batch writes the edges
        // of its tets, taken from the topology through the form's slot -> tet map.
        const auto form = make_tet_edge_form<double>(nm.mesh, topo, Materials(Material{}));
        const ResourceFn batch_w = [&](index_t b, std::vector<index_t>& out) {
            for (index_t s = b * kTetLanes<double>; s < std::min<index_t>(topo.num_tets, (b + 1) * kTetLanes<double>); ++s)
                for (index_t e : topo.tet_edges[form.slot_tet[s]]) out.push_back(e);
        };
        const ParallelEdgeKernels<double> pk(m, std::make_shared<SerialExecutor>(), Variant::Colour, {}, form);
        EXPECT_EQ(colouring_conflicts(pk.form_colouring(), m.num_edges(), batch_w), 0) << nm.name;
        // The default plan's vertex-segment colouring (blocks chosen per mesh).
        EXPECT_EQ(colouring_conflicts(pk.vertex_colouring(), m.num_vertices, seg_w), 0) << nm.name;
        if (m.num_vertices >= 64) {
            EXPECT_GT(pk.vertex_colouring().colours(), 1) << nm.name;
        }
        // The checker does catch a conflict.
        Colouring bad = colour_edges(m);
        if (m.num_edges() > 1) {
            bad.colour_first = {0, index_t(bad.units.size())};
            bad.chunk_first = {0, 1};
            bad.chunk_units = {index_t(bad.units.size())};
            EXPECT_GT(colouring_conflicts(bad, m.num_vertices, edge_w), 0);
        }
    }
}

// The per-tet method: colour (and private) against core's serial loops.
TEST(ParallelTetKernels, MatchSerial) {
    for (const auto& nm : meshes()) {
        const auto models = edgefem::test::make_models<double>(nm.mesh);
        const auto u = deformation_displacement(nm.mesh, Deformation::Twist);
        const auto x = deformation_displacement(nm.mesh, Deformation::Random);
        std::vector<double> f0(u.size()), y0(u.size()), D0(3 * u.size(), 0.0);
        TetStiffness<double> K0;
        const double W0 = tet_forces_stiffness<true>(models.tet, u.data(), f0.data(), K0);
        tet_multiply(models.tet, K0, x.data(), y0.data());
        for (index_t t = 0; t < models.tet.num_tets(); ++t)
            for (int a = 0; a < 4; ++a)
                for (int i = 0; i < 9; ++i)
                    D0[9 * std::size_t(models.tet.tet[t][a]) + i] += K0.K[90 * std::size_t(t) + 9 * tet_block_index(a, a) + i];
        for (Variant v : {Variant::Colour, Variant::Private}) {
            auto run = [&](std::shared_ptr<const Executor> ex) {
                ParallelTetKernels<double> k(models.tet, std::move(ex), v);
                Outputs<double> o;
                o.f.resize(u.size());
                o.y.resize(u.size());
                o.D.resize(3 * u.size());
                o.W = k.forces<true>(u.data(), o.f.data());
                TetStiffness<double> K;
                k.stiffness(u.data(), K);
                o.K = K.K;
                k.multiply(K, x.data(), o.y.data());
                k.diagonal_blocks(K, o.D.data());
                return o;
            };
            const auto serial = run(std::make_shared<SerialExecutor>());
            EXPECT_NEAR(serial.W, W0, 1e-12 * std::abs(W0));
            EXPECT_LE(rel_diff(serial.f, f0), 1e-12);
            EXPECT_TRUE(bitwise_equal(serial.K, K0.K));
            EXPECT_LE(rel_diff(serial.y, y0), 1e-12);
            EXPECT_LE(rel_diff(serial.D, D0), 1e-12);
            for (const auto& ne : executors()) {
                if (edgefem::test::skip_oversubscribed(nm.mesh.num_tets(), ne.ex->threads(), kOversubscribeMaxTets)) continue;
                const auto par = run(ne.ex);
                const std::string tag = nm.name + "/" + to_string(v) + "/" + ne.name;
                if (v == Variant::Colour) {
                    EXPECT_EQ(par.W, serial.W) << tag;
                    EXPECT_TRUE(bitwise_equal(par.f, serial.f)) << tag;
                    EXPECT_TRUE(bitwise_equal(par.y, serial.y)) << tag;
                    EXPECT_TRUE(bitwise_equal(par.D, serial.D)) << tag;
                } else {
                    EXPECT_NEAR(par.W, W0, 1e-12 * std::abs(W0)) << tag;
                    EXPECT_LE(rel_diff(par.f, f0), 1e-12) << tag;
                    EXPECT_LE(rel_diff(par.y, y0), 1e-12) << tag;
                    EXPECT_LE(rel_diff(par.D, D0), 1e-12) << tag;
                }
                EXPECT_TRUE(bitwise_equal(par.K, K0.K)) << tag;
            }
        }
    }
}

// The owner variant's default part count (variant.hpp): the mesh's power of
// two near cbrt(#V) / 2.5 in 4..64, capped by the machine's power of two at
// or above its hardware threads (at least 4).
TEST(ParallelEdgeKernels, DefaultOwnerPartsFollowMeshAndMachine) {
    // cbrt(180000) / 2.5 = 22.6 -> 16 (log scale); cbrt(4000) / 2.5 = 6.3 -> 8; cbrt(100) / 2.5 = 1.9 -> 4 (floor).
    EXPECT_EQ(default_owner_parts(180000, 64), 16);
    EXPECT_EQ(default_owner_parts(180000, 16), 16);
    EXPECT_EQ(default_owner_parts(180000, 9), 16);
    EXPECT_EQ(default_owner_parts(180000, 8), 8);
    EXPECT_EQ(default_owner_parts(180000, 2), 4);
    EXPECT_EQ(default_owner_parts(180000, 1), 4);
    EXPECT_EQ(default_owner_parts(4000, 64), 8);
    EXPECT_EQ(default_owner_parts(100, 64), 4);
    EXPECT_EQ(default_owner_parts(100, 1), 4);
    EXPECT_EQ(default_owner_parts(100000000, 1000), 64);
}
