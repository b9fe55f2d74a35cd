// The STREAM kernels compute STREAM's values on every back-end (sizes that
// are not a multiple of the block included), the sum is bitwise the same for
// any thread count, the measurement returns sane numbers; and the traffic
// models equal the sums of the array sizes they say they count, computed
// here independently from the vectors' sizes. No timing is checked.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "edgefem/core/coefficients.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "cpu/tet_edge_form.hpp"
#include "edgefem/core/topology.hpp"
#include "edgefem/parallel/executors.hpp"
#include "executor_kinds.hpp"
#include "lab/stream_bandwidth.hpp"

using namespace edgefem;

namespace {

std::vector<std::shared_ptr<const Executor>> executors() {
    return {make_executor(ExecutorKind::Serial), make_executor(ExecutorKind::OpenMP, 1), make_executor(ExecutorKind::OpenMP, 2),
            make_executor(ExecutorKind::OpenMP, 3), make_executor(test::kThreadSanitizer ? ExecutorKind::Pool : ExecutorKind::TBB, 2)};
}

}  // namespace

TEST(StreamBandwidth, KernelsComputeStreamValues) {
    for (std::size_t n : {std::size_t(1), std::size_t(1000), 3 * kStreamBlock + 123}) {
        // Quarter-integers: every result below is exact, so it cannot depend
        // on whether the compiler contracts b + s c into a fused multiply-add.
        std::vector<double> a0(n), b0(n), c0(n);
        for (std::size_t i = 0; i < n; ++i) {
            a0[i] = 0.25 * double(i % 101) - 3.0;
            b0[i] = 1.0 + double(i % 17);
            c0[i] = -0.5 * double(i % 5);
        }
        for (const auto& ex : executors()) {
            std::vector<double> a = a0, b = b0, c = c0;
            stream_copy(*ex, a, c);  // c = a
            for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(c[i], a0[i]) << ex->name() << " copy " << i;
            stream_scale(*ex, c, b, 3.0);  // b = 3 c
            for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(b[i], 3.0 * a0[i]) << ex->name() << " scale " << i;
            stream_add(*ex, a, b, c);  // c = a + b
            for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(c[i], a0[i] + 3.0 * a0[i]) << ex->name() << " add " << i;
            stream_triad(*ex, b, c, a, 3.0);  // a = b + 3 c
            for (std::size_t i = 0; i < n; ++i)
                ASSERT_EQ(a[i], 3.0 * a0[i] + 3.0 * (a0[i] + 3.0 * a0[i])) << ex->name() << " triad " << i;
        }
    }
}

TEST(StreamBandwidth, SumIsExactAndThreadIndependent) {
    // Small integers: every partial sum is exact, so the value is known.
    const std::size_t n = 5 * kStreamBlock + 7;
    std::vector<double> a(n);
    double expect = 0;
    for (std::size_t i = 0; i < n; ++i) {
        a[i] = double(i % 13) - 6.0;
        expect += a[i];
    }
    for (const auto& ex : executors()) EXPECT_EQ(stream_sum(*ex, a), expect) << ex->name();
    // Non-exact values: bitwise the same for every back-end and thread count.
    for (std::size_t i = 0; i < n; ++i) a[i] = std::sin(0.37 * double(i)) * std::exp(double(i % 97) / 7);
    const double ref = stream_sum(SerialExecutor{}, a);
    for (const auto& ex : executors()) EXPECT_EQ(stream_sum(*ex, a), ref) << ex->name();
    EXPECT_EQ(stream_sum(SerialExecutor{}, std::vector<double>{}), 0.0);
}

TEST(StreamBandwidth, SizeMismatchThrows) {
    std::vector<double> a(10), b(10), c(11);
    SerialExecutor ex;
    EXPECT_THROW(stream_copy(ex, a, c), InvalidArgument);
    EXPECT_THROW(stream_scale(ex, c, a, 2.0), InvalidArgument);
    EXPECT_THROW(stream_add(ex, a, b, c), InvalidArgument);
    EXPECT_THROW(stream_triad(ex, a, c, b, 2.0), InvalidArgument);
}

TEST(StreamBandwidth, MeasurementReturnsPositiveRates) {
    StreamOptions opts;
    opts.elements = 2 * kStreamBlock + 5;  // small: this checks the plumbing, not the machine
    opts.repetitions = 3;
    for (const auto& ex : executors()) {
        const StreamBandwidth r = measure_stream_bandwidth(*ex, opts);
        EXPECT_EQ(r.elements, opts.elements);
        EXPECT_EQ(r.repetitions, 3);
        EXPECT_EQ(r.threads, ex->threads());
        for (double v : {r.copy, r.scale, r.add, r.triad, r.sum, r.triad_best}) {
            EXPECT_TRUE(std::isfinite(v)) << ex->name();
            EXPECT_GT(v, 0.0) << ex->name();
        }
        EXPECT_GE(r.triad_best, r.triad);
    }
    opts.repetitions = 0;
    EXPECT_THROW(measure_stream_bandwidth(SerialExecutor{}, opts), InvalidArgument);
    opts.repetitions = 1;
    opts.elements = 0;
    EXPECT_THROW(measure_stream_bandwidth(SerialExecutor{}, opts), InvalidArgument);
}

namespace {

template <class T>
double size_bytes(const std::vector<T>& v) {
    return double(v.size() * sizeof(T));
}

template <class S>
void check_traffic(const EdgeModel<S>& m) {
    // The state and the vertex vectors the kernels use, sized as they do.
    EdgeState<S> st;
    st.resize(m.num_edges());
    EdgeStiffness<S> K;
    K.resize(m.num_edges());
    const std::vector<S> vertex_vector(3 * std::size_t(m.num_vertices));  // u, f, x, y
    const double u = size_bytes(vertex_vector), f = u, x = u, y = u;
    const double p = size_bytes(st.p), zeta = size_bytes(st.zeta), g = size_bytes(st.g);
    const double blocks = size_bytes(K.K) - 9 * sizeof(S);  // without the sink block
    ASSERT_EQ(st.g.size(), std::size_t(m.num_edges()));
    ASSERT_EQ(sizeof(st.g[0]), sizeof(double));

    // Force, FE: model arrays once, p / zeta / g written and read, u read, f written.
    const double model_fe = size_bytes(m.edge) + size_bytes(m.edge_first) + size_bytes(m.rest) + size_bytes(m.LE) +
                            size_bytes(m.tsep_first) + size_bytes(m.tsep_other) + size_bytes(m.LP);
    const double force_fe = model_fe + 2 * p + 2 * zeta + 2 * g + u + f;
    EXPECT_DOUBLE_EQ(force_bytes_per_call(m), force_fe);
    EXPECT_DOUBLE_EQ(force_bytes_per_call(m, ModelKind::FE, TrafficModel::Compulsory), force_fe);
    // Per pass: edge read twice, g four times (write, read-modify-write, read),
    // f zero-filled, then read and written.
    EXPECT_DOUBLE_EQ(force_bytes_per_call(m, ModelKind::FE, TrafficModel::PerPass),
                     force_fe + size_bytes(m.edge) + 2 * g + 2 * f);
    // SN: no TSEP arrays, zeta written only.
    const double model_sn = size_bytes(m.edge) + size_bytes(m.edge_first) + size_bytes(m.rest) + size_bytes(m.LE);
    const double force_sn = model_sn + 2 * p + zeta + 2 * g + u + f;
    EXPECT_DOUBLE_EQ(force_bytes_per_call(m, ModelKind::SN), force_sn);
    EXPECT_DOUBLE_EQ(force_bytes_per_call(m, ModelKind::SN, TrafficModel::PerPass), force_sn + size_bytes(m.edge) + 2 * f);

    // K x: blocks, edge, edge_first once, x read, y written (per pass: y zeroed and read-modified-written).
    const double kx = blocks + size_bytes(m.edge) + size_bytes(m.edge_first) + x + y;
    EXPECT_DOUBLE_EQ(kx_bytes_per_call(m), kx);
    EXPECT_DOUBLE_EQ(kx_bytes_per_call(m, TrafficModel::PerPass), kx + 2 * y);

    // Stiffness (TSEP list): p, g, LE, the TSEP arrays and targets read, K written.
    const double stiff_fe = p + g + size_bytes(m.LE) + size_bytes(m.tsep_first) + size_bytes(m.tsep_other) +
                            size_bytes(m.LP) + size_bytes(m.target) + size_bytes(K.K);
    EXPECT_DOUBLE_EQ(stiffness_bytes_per_call(m), stiff_fe);
    EXPECT_DOUBLE_EQ(stiffness_bytes_per_call(m, ModelKind::FE, TrafficModel::PerPass), stiff_fe + p + 2 * size_bytes(K.K));
    EXPECT_DOUBLE_EQ(stiffness_bytes_per_call(m, ModelKind::SN), p + g + size_bytes(m.LE) + size_bytes(K.K));
}

}  // namespace

TEST(StreamBandwidth, TrafficModelsCountTheArrays) {
    const Mesh mesh = make_box(5, 4, 3);
    const Topology topo = build_topology(mesh);
    const Coefficients coef = compute_coefficients(mesh, topo, Material{1e5, 0.3, 1000});
    const EdgeModel<double> md = make_edge_model<double>(topo, coef);
    ASSERT_GT(md.num_tseps(), 0);
    check_traffic(md);
    const EdgeModel<float> mf = make_edge_model<float>(topo, coef);
    check_traffic(mf);
    // float halves the coefficients and state but not the indices or g.
    EXPECT_LT(force_bytes_per_call(mf), force_bytes_per_call(md));
    EXPECT_GT(force_bytes_per_call(mf), 0.5 * force_bytes_per_call(md));

    // The force from the tet-local form: the TSEP arrays replaced by the
    // form's, zeta read again by the form pass; in tiles, the state counted
    // once (as written), its read-backs cached.
    TetEdgeForm<double> form = make_tet_edge_form<double>(mesh, topo, Materials(Material{1e5, 0.3, 1000}));
    const double E = md.num_edges();
    const double sn = force_bytes_per_call(md, ModelKind::SN);
    const double arrays = size_bytes(form.edge) + size_bytes(form.A);
    form.tiles.clear();
    EXPECT_DOUBLE_EQ(form_force_bytes_per_call(md, form), sn + arrays + 8 * E);
    form.tiles = plan_form_tiles(form, topo.edges, topo.first_edge, 1);
    ASSERT_GT(form.tiles.size(), 1u);
    EXPECT_DOUBLE_EQ(form_force_bytes_per_call(md, form), sn + arrays - 3 * 8 * E - 8 * E);
    EXPECT_DOUBLE_EQ(form_force_bytes_per_call(md, form, TrafficModel::PerPass),
                     force_bytes_per_call(md, ModelKind::SN, TrafficModel::PerPass) + arrays + 8 * E + 2 * 8 * E);
    // On a ring (tet_form_forces_ring) the state is not written either: the
    // model arrays, the form, u and f are left.
    const double V = md.num_vertices;
    EXPECT_DOUBLE_EQ(form_force_bytes_per_call(md, form, TrafficModel::Compulsory, false),
                     size_bytes(md.edge) + size_bytes(md.edge_first) + size_bytes(md.rest) + size_bytes(md.LE) + arrays +
                         2 * 3 * 8 * V);
    EXPECT_DOUBLE_EQ(form_force_bytes_per_call(md, form, TrafficModel::Compulsory, false),
                     form_force_bytes_per_call(md, form) - (3 * 8 * E + 8 * E + 8 * E));
}
