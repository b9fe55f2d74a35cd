// Tagged surfaces and surface loads. The readers keep the files' tagged
// triangles (Gmsh physical surfaces and names, TetGen .face markers, MEDIT
// Triangles); selections by tag and name, with errors naming a tag or name
// no triangle has; pressure and traction distributed to the vertices:
// a uniform pressure on a closed surface sums to zero, on a box face to
// p x area, a traction to t x area, both rotate with the mesh; a bar pulled
// by a traction (nu = 0: the homogeneous solution is exact on linear tets)
// stretches as the analytic StVK bar, t / E at small loads; keyframed
// surface loads give a free body the momentum of their impulse.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/surface.hpp"
#include "edgefem/core/surface_load.hpp"
#include "edgefem/core/surface_selection.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "io_test_util.hpp"

using namespace edgefem;
using edgefem::test::data_file;
using edgefem::test::expect_mesh_error;

namespace {

// The two triangles every small test file tags (vertices 1 2 3 and 2 3 5 of
// the file, 1-based): the first is interior (tets 1 and 3 share it).
const std::vector<index_t> kTriangles = {0, 1, 2, 1, 2, 4};

template <class F>
std::string invalid_message(F&& f) {
    try {
        f();
    } catch (const InvalidArgument& e) {
        return e.what();
    }
    ADD_FAILURE() << "no InvalidArgument";
    return {};
}

std::array<double, 3> total(const std::vector<double>& f) {
    std::array<double, 3> s{0, 0, 0};
    for (std::size_t i = 0; i < f.size(); ++i) s[i % 3] += f[i];
    return s;
}

std::vector<double> forces(const Mesh& m, const SurfaceLoad& l) {
    std::vector<double> f(m.X.size(), 0.0);
    add_surface_load_forces(m.X, l, 1.0, f);
    return f;
}

// A rotation about the axis (1, 2, 3) by 0.7 rad (Rodrigues).
std::array<std::array<double, 3>, 3> rotation() {
    const double n = std::sqrt(14.0), k[3] = {1 / n, 2 / n, 3 / n}, a = 0.7;
    const double c = std::cos(a), s = std::sin(a);
    std::array<std::array<double, 3>, 3> R;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R[i][j] = (i == j ? c : 0) + (1 - c) * k[i] * k[j];
    R[0][1] -= s * k[2], R[0][2] += s * k[1], R[1][0] += s * k[2];
    R[1][2] -= s * k[0], R[2][0] -= s * k[1], R[2][1] += s * k[0];
    return R;
}

std::array<double, 3> rotate(const std::array<std::array<double, 3>, 3>& R, const double* x) {
    return {R[0][0] * x[0] + R[0][1] * x[1] + R[0][2] * x[2], R[1][0] * x[0] + R[1][1] * x[1] + R[1][2] * x[2],
            R[2][0] * x[0] + R[2][1] * x[1] + R[2][2] * x[2]};
}

std::vector<double> rotate_all(const std::array<std::array<double, 3>, 3>& R, const std::vector<double>& x) {
    std::vector<double> out(x.size());
    for (std::size_t v = 0; v < x.size() / 3; ++v) {
        const auto y = rotate(R, &x[3 * v]);
        for (int r = 0; r < 3; ++r) out[3 * v + r] = y[r];
    }
    return out;
}

double max_abs(const std::vector<double>& x) {
    double m = 0;
    for (double v : x) m = std::max(m, std::abs(v));
    return m;
}

}  // namespace

TEST(TaggedSurfaces, EveryReaderKeepsTheFilesTriangles) {
    const Mesh g22 = read_gmsh(data_file("small22.msh"));
    EXPECT_EQ(g22.surfaces.vertices, kTriangles);
    EXPECT_EQ(g22.surfaces.tag, (std::vector<int>{7, 7}));
    EXPECT_EQ(g22.surfaces.names.at(7), "skin");
    EXPECT_EQ(g22.surfaces.names.count(1), 0u);  // a volume's name is not a surface's
    EXPECT_EQ(g22.source.triangle_line, (std::vector<std::int64_t>{22, 24}));
    // 4.1: the surface entity has no physical tag, so its entity tag is the tag.
    const Mesh g41 = read_gmsh(data_file("small41.msh"));
    EXPECT_EQ(g41.surfaces.vertices, kTriangles);
    EXPECT_EQ(g41.surfaces.tag, (std::vector<int>{1, 1}));
    const Mesh medit = read_medit(data_file("small.mesh"));
    EXPECT_EQ(medit.surfaces.vertices, kTriangles);
    EXPECT_EQ(medit.surfaces.tag, (std::vector<int>{5, 5}));
    EXPECT_NE(medit.describe_triangle(1).find("small.mesh:24"), std::string::npos) << medit.describe_triangle(1);

    // TetGen: the .face file next to the .node file, when there is one.
    test::TempDir dir("faces");
    for (const char* ext : {".node", ".ele"}) test::spit(dir.file(std::string("m") + ext), test::slurp(data_file(std::string("small1") + ext)));
    EXPECT_EQ(read_tetgen(dir.file("m")).surfaces.size(), 0u);
    test::spit(dir.file("m.face"), "# faces\n2 1\n1 1 2 3 4\n2  2 3 5  -2\n");
    const Mesh tg = read_tetgen(dir.file("m.node"));
    EXPECT_EQ(tg.surfaces.vertices, kTriangles);
    EXPECT_EQ(tg.surfaces.tag, (std::vector<int>{4, -2}));
    // Without markers the faces carry no tag and are not kept.
    test::spit(dir.file("m.face"), "2 0\n1 1 2 3\n2 2 3 5\n");
    EXPECT_EQ(read_tetgen(dir.file("m")).surfaces.size(), 0u);
}

TEST(TaggedSurfaces, MalformedFaceDataNamesFileAndLine) {
    test::TempDir dir("badfaces");
    for (const char* ext : {".node", ".ele"}) test::spit(dir.file(std::string("m") + ext), test::slurp(data_file(std::string("small1") + ext)));
    const auto face = dir.file("m.face");
    const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
        {"2 1\n1 1 2 3 4\n2 2 3 9 4\n", {"m.face:3", "vertex index 9", "out of range"}},
        {"2 1\n1 1 2 3 4\n2 2 3 x 4\n", {"m.face:3", "'x'"}},
        {"2 1\n1 1 2 3 4\n", {"m.face:1", "face count 2"}},
        {"1 1\n1 1 2 3\n", {"m.face:2", "boundary marker"}},
        {"1 2\n1 1 2 3 4\n", {"m.face:1", "marker flag"}},
        {"1 1\n1 1 2 3 4 5\n", {"m.face:2", "'5'"}},
    };
    for (const auto& [text, parts] : cases) {
        SCOPED_TRACE(text);
        test::spit(face, text);
        std::string msg;
        try {
            read_tetgen(dir.file("m"));
            ADD_FAILURE() << "no MeshError";
        } catch (const MeshError& e) {
            msg = e.what();
        }
        for (const std::string& part : parts) EXPECT_NE(msg.find(part), std::string::npos) << msg;
    }
    // Gmsh: a triangle naming an undefined node, a bad physical name line.
    std::string g = test::slurp(data_file("small22.msh"));
    test::spit(dir.file("a.msh"), std::string(g).replace(g.find("5 2 2 7 1 20 30 55"), 18, "5 2 2 7 1 20 30 56"));
    expect_mesh_error([&] { read_gmsh(dir.file("a.msh")); }, {"a.msh:24", "node tag 56"});
    test::spit(dir.file("b.msh"), std::string(g).replace(g.find("2 7 \"skin\""), 10, "2 7 skin"));
    expect_mesh_error([&] { read_gmsh(dir.file("b.msh")); }, {"b.msh:6", "name"});
    // MEDIT: a triangle's vertex out of range.
    std::string md = test::slurp(data_file("small.mesh"));
    test::spit(dir.file("c.mesh"), std::string(md).replace(md.find("2 3 5 5"), 7, "2 3 7 5"));
    expect_mesh_error([&] { read_medit(dir.file("c.mesh")); }, {"c.mesh:24", "vertex index 7"});
}

TEST(TaggedSurfaces, SelectionsByTagAndNameNameWhatIsMissing) {
    const Mesh m = read_gmsh(data_file("small22.msh"));
    EXPECT_EQ(tagged_triangles(m, {7}).size(), 2u);
    EXPECT_EQ(tags_named(m, "skin"), (std::vector<int>{7}));
    EXPECT_EQ(triangle_vertices(tagged_triangles(m, {7})), (std::vector<index_t>{0, 1, 2, 4}));
    std::string msg = invalid_message([&] { tagged_triangles(m, {99}); });
    EXPECT_NE(msg.find("surface tag 99"), std::string::npos) << msg;
    EXPECT_NE(msg.find("tag 7"), std::string::npos) << msg;
    msg = invalid_message([&] { tags_named(m, "clamp"); });
    EXPECT_NE(msg.find("\"clamp\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"skin\""), std::string::npos) << msg;
    msg = invalid_message([&] { tagged_triangles(make_box(1, 1, 1), {1}); });
    EXPECT_NE(msg.find("no tagged triangles"), std::string::npos) << msg;
    // The first tagged triangle is interior: no outside for a load.
    expect_mesh_error([&] { orient_outward(m, tagged_triangles(m, {7})); }, {"not on the boundary", "10 20 30"});
    // The second one is a boundary face: wound as boundary_surface winds it.
    const auto out = orient_outward(m, {Triangle{1, 2, 4}});
    bool found = false;
    for (const auto& t : boundary_surface(m).triangles) found = found || t == out[0];
    EXPECT_TRUE(found);
}

TEST(TaggedSurfaces, CompactionRenumbersAndPermutationKeepsThem) {
    Mesh m = read_gmsh(data_file("small22.msh"));
    // An unused vertex in front: every index moves by one, compaction undoes it.
    Mesh shifted = m;
    shifted.X.insert(shifted.X.begin(), {9, 9, 9});
    shifted.source = {};
    for (index_t& v : shifted.tets) ++v;
    for (index_t& v : shifted.surfaces.vertices) ++v;
    ValidationOptions o;
    o.compact_unreferenced = true;
    validate_mesh(shifted, o);
    EXPECT_EQ(shifted.surfaces.vertices, kTriangles);
    // An index out of range is a MeshError naming the triangle.
    Mesh bad = m;
    bad.surfaces.vertices[4] = 6;
    expect_mesh_error([&] { check_mesh(bad); }, {"triangle 1", "small22.msh:24", "vertex index 6"});
}

TEST(SurfaceLoads, PressureOnAClosedSurfaceSumsToZeroAndOnAFaceToPTimesArea) {
    Mesh m = make_box(5, 3, 4, 0.01);
    const auto R = rotation();
    m.X = rotate_all(R, m.X);
    SurfaceLoad all;
    all.triangles = boundary_surface(m).triangles;
    all.pressure = 2.5e3;
    const auto f = forces(m, all);
    const auto s = total(f);
    const double scale = all.pressure * 2 * (0.05 * 0.03 + 0.05 * 0.04 + 0.03 * 0.04);  // p x surface area
    for (int r = 0; r < 3; ++r) EXPECT_LT(std::abs(s[r]), 1e-14 * scale) << r;
    EXPECT_GT(max_abs(f), 1e-3 * scale / double(m.num_vertices()));

    // The x = max face of the unrotated box: p pushes in (-x), t pulls.
    const Mesh b = make_box(5, 3, 4, 0.01);
    SurfaceLoad face;
    face.triangles = boundary_in_box(b, {0.0249, -1, -1}, {1, 1, 1});
    ASSERT_EQ(face.triangles.size(), 2u * 3 * 4);
    face.pressure = 2.5e3;
    const double area = 0.03 * 0.04;
    auto sf = total(forces(b, face));
    EXPECT_NEAR(sf[0], -face.pressure * area, 1e-14 * face.pressure * area);
    EXPECT_NEAR(sf[1], 0, 1e-14 * face.pressure * area);
    EXPECT_NEAR(sf[2], 0, 1e-14 * face.pressure * area);
    face.pressure = 0;
    face.traction = {1e3, -2e3, 3e3};
    sf = total(forces(b, face));
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(sf[r], face.traction[r] * area, 1e-14 * 4e3 * area) << r;
    // Every vertex of the face is loaded, no other.
    const auto fv = forces(b, face);
    const auto verts = triangle_vertices(face.triangles);
    std::size_t loaded = 0;
    for (index_t v = 0; v < b.num_vertices(); ++v)
        if (fv[3 * v] != 0) ++loaded;
    EXPECT_EQ(loaded, verts.size());
}

TEST(SurfaceLoads, ForcesRotateWithTheMesh) {
    const Mesh a = make_box(4, 3, 2, 0.01);
    Mesh b = a;
    const auto R = rotation();
    b.X = rotate_all(R, a.X);
    SurfaceLoad la;
    la.triangles = boundary_in_box(a, {-1, -1, 0.0099}, {1, 1, 1});  // the z = max face
    la.pressure = 700;
    la.traction = {100, 200, -300};
    SurfaceLoad lb = la;
    const auto t = rotate(R, la.traction.data());
    lb.traction = {t[0], t[1], t[2]};
    const auto fa = rotate_all(R, forces(a, la)), fb = forces(b, lb);
    const double tol = 1e-13 * max_abs(fa);
    for (std::size_t i = 0; i < fa.size(); ++i) ASSERT_NEAR(fa[i], fb[i], tol) << i;
}

namespace {

// A 0.1 x 0.02 x 0.02 m bar (nu = 0), clamped at x = min, pulled by a
// traction t (Pa) on its x = max face; the static solution.
std::vector<double> pulled_bar(double t, const std::array<std::array<double, 3>, 3>* R, Mesh* mesh_out) {
    Scene s;
    s.mesh = make_box(10, 2, 2, 0.01);
    s.materials = Material{1e6, 0.0, 1000};
    const Mesh rest = s.mesh;
    for (index_t v = 0; v < rest.num_vertices(); ++v)
        if (rest.X[3 * v] < -0.0499) s.fixed.push_back(v);
    SurfaceLoad l;
    l.triangles = boundary_in_box(rest, {0.0499, -1, -1}, {1, 1, 1});
    l.traction = {t, 0, 0};
    if (R) {
        s.mesh.X = rotate_all(*R, rest.X);
        const auto tr = rotate(*R, l.traction.data());
        l.traction = {tr[0], tr[1], tr[2]};
    }
    s.surface_loads.push_back(l);
    s.solver.linear_solver = LinearSolver::Direct;
    s.solver.newton_tolerance = 1e-12;
    if (mesh_out) *mesh_out = s.mesh;
    Simulator<double> sim(s);
    EXPECT_TRUE(sim.solve_static().converged);
    const auto u = sim.displacement();
    return {u.begin(), u.end()};
}

}  // namespace

TEST(SurfaceLoads, BarPulledByATractionStretchesAsTheAnalyticBar) {
    // nu = 0: uniaxial stress is homogeneous and the clamp does not disturb
    // it, so linear tets reproduce it exactly. StVK with lambda = 0: the
    // nominal stress P = (1 + e) E ((1 + e)^2 - 1) / 2 equals the traction.
    const double E = 1e6;
    for (const double t : {1e2, 5e4}) {
        SCOPED_TRACE(t);
        Mesh m;
        const auto u = pulled_bar(t, nullptr, &m);
        double e = t / E;  // Newton on the analytic relation
        for (int k = 0; k < 50; ++k) {
            const double g = (1 + e) * E * ((1 + e) * (1 + e) - 1) / 2 - t;
            const double dg = E * ((1 + e) * (1 + e) - 1) / 2 + (1 + e) * E * (1 + e);
            e -= g / dg;
        }
        for (index_t v = 0; v < m.num_vertices(); ++v) {
            const double x = m.X[3 * v] + 0.05;
            ASSERT_NEAR(u[3 * v], e * x, 1e-8 * e * 0.1) << v;
            ASSERT_NEAR(u[3 * v + 1], 0, 1e-8 * e * 0.1) << v;
            ASSERT_NEAR(u[3 * v + 2], 0, 1e-8 * e * 0.1) << v;
        }
        if (t == 1e2) {
            EXPECT_NEAR(e, t / E, 1e-3 * t / E);  // small loads: the linear t / E
        }
    }
    // Rotating the mesh and the traction rotates the solution.
    const auto R = rotation();
    const auto u0 = pulled_bar(5e4, nullptr, nullptr);
    const auto ur = pulled_bar(5e4, &R, nullptr);
    const auto u0r = rotate_all(R, u0);
    for (std::size_t i = 0; i < u0r.size(); ++i) ASSERT_NEAR(ur[i], u0r[i], 1e-8 * max_abs(u0)) << i;
}

TEST(SurfaceLoads, KeyframedLoadsGiveAFreeBodyTheirImpulse) {
    // No constraint, no gravity: internal forces sum to zero, so the
    // momentum after n steps is sum_k F s(t_k + dt / 2) dt. Two loads with
    // different keyframes (the host-summed path) and one constant.
    Scene s;
    s.mesh = make_box(3, 2, 2, 0.01);
    s.materials = Material{1e5, 0.3, 1000};
    s.integrator = Integrator::Explicit;
    s.dt = 1e-4;
    SurfaceLoad a, b, c;
    a.triangles = boundary_in_box(s.mesh, {0.0149, -1, -1}, {1, 1, 1});
    a.traction = {50, 0, 0};
    a.keyframes = {{0, 0}, {1e-3, 1}};
    b.triangles = boundary_in_box(s.mesh, {-1, -1, 0.0099}, {1, 1, 1});
    b.pressure = 30;  // pushes -z
    b.keyframes = {{0, 1}, {5e-4, 0}};
    c.triangles = boundary_surface(s.mesh).triangles;
    c.pressure = 1e3;  // closed surface: no net force
    s.surface_loads = {a, b, c};
    Simulator<double> sim(s);
    const int n = 12;
    for (int k = 0; k < n; ++k) sim.step();
    std::array<double, 3> p{0, 0, 0}, expected{0, 0, 0};
    const auto v = sim.velocity();
    const auto mass = sim.lumped_mass();
    for (index_t i = 0; i < sim.num_vertices(); ++i)
        for (int r = 0; r < 3; ++r) p[r] += mass[i] * v[3 * i + r];
    const double Ax = 0.02 * 0.02, Az = 0.03 * 0.02;
    for (int k = 0; k < n; ++k) {
        const double t = (k + 0.5) * s.dt;
        expected[0] += 50 * Ax * keyframe_value(a.keyframes, t) * s.dt;
        expected[2] += -30 * Az * keyframe_value(b.keyframes, t) * s.dt;
    }
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(p[r], expected[r], 1e-10 * std::abs(expected[0])) << r;
}

TEST(SurfaceLoads, SceneFileSelectorsAndErrors) {
    const std::string dir = EDGEFEM_TEST_DATA;
    // Fixed by tag and by name on the Gmsh file: vertices of both triangles.
    for (const char* sel : {R"({"surface": 7})", R"({"surface": "skin"})"}) {
        const SceneFile f = parse_scene(std::string(R"({"mesh": "small22.msh", "fixed": )") + sel + "}", dir, "t.json");
        EXPECT_EQ(f.scene.fixed, (std::vector<index_t>{0, 1, 2, 4})) << sel;
    }
    const auto fails = [&](const std::string& text, std::initializer_list<const char*> parts) {
        const std::string msg = invalid_message([&] { parse_scene(text, dir, "t.json"); });
        for (const char* p : parts) EXPECT_NE(msg.find(p), std::string::npos) << msg;
    };
    fails(R"({"mesh": "small22.msh", "fixed": {"surface": 3}})", {"\"fixed.surface\"", "surface tag 3", "tag 7"});
    fails(R"({"mesh": "small22.msh", "fixed": [{"box": {}}, {"surface": "clamp"}]})", {"\"fixed[1].surface\"", "\"clamp\""});
    fails(R"({"mesh": "small22.msh", "surface_loads": [{"on": {"surface": 7}, "pressure": 1}]})",
          {"surface_loads[0].on.surface", "not on the boundary"});
    fails(R"({"mesh": "box:2x2x2", "surface_loads": [{"on": {"boundary": true}}]})", {"\"pressure\" or \"traction\""});
    fails(R"({"mesh": "box:2x2x2", "surface_loads": [{"on": {"box": {"min": [5, 5, 5]}}, "pressure": 1}]})",
          {"surface_loads[0].on.box", "no boundary triangle"});
    fails(R"({"mesh": "box:2x2x2", "surface_loads": [{"on": {"boundary": true}, "traction": [1, 2]}]})",
          {"surface_loads[0].traction"});

    // A traction and a pressure on the whole boundary, keyframed; a face
    // selected twice is loaded once.
    const SceneFile f = parse_scene(R"({"mesh": "box:2x2x2",
        "surface_loads": [{"on": [{"box": {"min": [0.0099, -1, -1]}}, {"box": {"min": [0.0099, -1, -1]}}],
                           "traction": [10, 0, 0], "keyframes": [[0, 0], [1, 1]]},
                          {"on": {"boundary": true}, "pressure": 5}],
        "prescribed": {"select": {"box": {"max": [-0.0099, 1, 1]}}, "displacement": [0.001, 0, 0]}})",
                                    dir, "t.json");
    ASSERT_EQ(f.scene.surface_loads.size(), 2u);
    EXPECT_EQ(f.scene.surface_loads[0].triangles.size(), 8u);
    EXPECT_EQ(f.scene.surface_loads[0].keyframes.size(), 2u);
    EXPECT_EQ(f.scene.surface_loads[1].triangles.size(), 6u * 8);
    EXPECT_EQ(f.scene.surface_loads[1].pressure, 5);
    ASSERT_EQ(f.scene.prescribed.size(), 9u);
    const auto& p = f.scene.prescribed[0];
    EXPECT_DOUBLE_EQ(p.target[0], f.scene.mesh.X[3 * p.vertex] + 0.001);
}
