// The layout-templated force kernels (layout_kernels.hpp) against
// edge_forces<FE>: every combination of AoS/SoA vectors, double/float and
// split/packed TSEP records gives the same forces and g, to 1e-12 relative in
// double and 1e-5 in float (max |difference| / max |reference|), on every test
// mesh under a twist and a random configuration.
#include <gtest/gtest.h>

#include "lab/deformations.hpp"
#include "lab/layout_kernels.hpp"
#include "models.hpp"
#include "test_meshes.hpp"

using namespace edgefem;
using test::rel_diff;

namespace {

struct Reference {
    std::vector<double> f, g;
};

template <class S>
Reference reference(const EdgeModel<double>& md, const std::vector<double>& u) {
    const EdgeModel<S> m = convert_scalar<S>(md);
    const auto us = test::cast<S>(u);
    std::vector<S> f(us.size());
    EdgeState<S> st;
    edge_forces<ModelKind::FE, false>(m, us.data(), f.data(), st);
    return {test::cast<double>(f), st.g};
}

void compare_all(const Mesh& mesh, const std::string& name) {
    const auto models = test::make_models<double>(mesh);
    const EdgeModel<double>& md = models.edge;
    for (Deformation d : {Deformation::Twist, Deformation::Random}) {
        const std::vector<double> u = deformation_displacement(mesh, d);
        const Reference ref_double = reference<double>(md, u), ref_float = reference<float>(md, u);
        for_each_force_layout([&]<class L>(L) {
            using S = typename L::scalar;
            SCOPED_TRACE(name + " deformation " + std::to_string(int(d)) + " layout " + L::name());
            const typename L::Model m = make_layout_model<L::vec, S, L::tsep>(md);
            const typename L::Vectors ul = to_vec3_array<L::vec, S>(u.data(), md.num_vertices);
            typename L::Vectors fl;
            typename L::State st;
            // Twice: the second call reuses the state and must overwrite f.
            layout_forces(m, ul, fl, st);
            layout_forces(m, ul, fl, st);
            std::vector<double> f(u.size());
            from_vec3_array(fl, f.data());
            if constexpr (sizeof(S) == 8) {
                EXPECT_LE(rel_diff(f, ref_double.f), 1e-12);
                EXPECT_LE(rel_diff(st.g, ref_double.g), 1e-12);
            } else {
                // Against the float kernels (same arithmetic) and against double.
                EXPECT_LE(rel_diff(f, ref_float.f), 1e-5);
                EXPECT_LE(rel_diff(st.g, ref_float.g), 1e-5);
                EXPECT_LE(rel_diff(f, ref_double.f), 1e-5);
            }
        });
    }
}

}  // namespace

TEST(LayoutKernels, EveryLayoutMatchesEdgeForces) {
    for (const auto& [name, mesh] : test::test_meshes(20000)) compare_all(mesh, name);
}

// AoS double split is EdgeModel's own layout: the same bytes per tet as
// EdgeModel::bytes_per_tet(false); packed records hold the same bytes as
// split ones; float saves 4 bytes per coefficient and per rest component.
TEST(LayoutKernels, BytesPerTet) {
    const auto models = test::make_models<double>(test::test_meshes(20000).front().mesh);
    const EdgeModel<double>& md = models.edge;
    const double ref = md.bytes_per_tet(false);
    const auto aos_d_split = make_layout_model<VecLayout::AoS, double, TsepLayout::Split>(md);
    const auto soa_d_packed = make_layout_model<VecLayout::SoA, double, TsepLayout::Packed>(md);
    const auto aos_f_split = make_layout_model<VecLayout::AoS, float, TsepLayout::Split>(md);
    EXPECT_DOUBLE_EQ(aos_d_split.bytes_per_tet(), ref);
    EXPECT_DOUBLE_EQ(soa_d_packed.bytes_per_tet(), ref);
    const double saved = 4.0 * (3 * md.num_edges() + md.num_edges() + md.LP.size()) / md.num_tets;
    EXPECT_DOUBLE_EQ(aos_f_split.bytes_per_tet(), ref - saved);
}

// Vec3Array round-trips xyz data in both layouts.
TEST(LayoutKernels, Vec3ArrayRoundTrip) {
    const std::vector<double> xyz = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    const auto aos = to_vec3_array<VecLayout::AoS, double>(xyz.data(), 4);
    const auto soa = to_vec3_array<VecLayout::SoA, double>(xyz.data(), 4);
    EXPECT_EQ(aos.data, xyz);
    EXPECT_EQ(soa.data, (std::vector<double>{1, 4, 7, 10, 2, 5, 8, 11, 3, 6, 9, 12}));
    std::vector<double> back(xyz.size());
    from_vec3_array(soa, back.data());
    EXPECT_EQ(back, xyz);
}
