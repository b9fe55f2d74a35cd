// Surfaces for rendering (surface.hpp). The boundary of a tet mesh: closed
// (every edge of it in exactly two triangles, with opposite directions) and
// outward (the divergence theorem over its triangles gives the mesh's
// volume, positive), on generated boxes (whose boundary triangle count is
// known) and the shared meshes. The embedding: barycentric weights that sum
// to 1 and reproduce the point; the embedded points follow any affine
// motion exactly, inside the mesh and outside it; vertex normals of a box's
// faces are the axes.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/surface.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

namespace {

double mesh_volume(const Mesh& m) {
    double v = 0;
    for (index_t t = 0; t < m.num_tets(); ++t) {
        const index_t* q = &m.tets[4 * std::size_t(t)];
        v += signed_volume(&m.X[3 * q[0]], &m.X[3 * q[1]], &m.X[3 * q[2]], &m.X[3 * q[3]]);
    }
    return v;
}

// Sum over the triangles of a . (b x c) / 6: the enclosed volume when the
// surface is closed and wound outward.
double enclosed_volume(const Mesh& m, const BoundarySurface& s) {
    double v = 0;
    const double o[3] = {0, 0, 0};
    for (const auto& t : s.triangles) v += signed_volume(o, &m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]]);
    return v;
}

}  // namespace

TEST(Surface, BoundaryIsClosedAndOutward) {
    for (const auto& nm : test::test_meshes(300000)) {
        SCOPED_TRACE(nm.name);
        const BoundarySurface s = boundary_surface(nm.mesh);
        ASSERT_FALSE(s.triangles.empty());
        ASSERT_EQ(s.tet.size(), s.triangles.size());
        std::map<std::pair<index_t, index_t>, int> directed;
        for (const auto& t : s.triangles)
            for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
        for (const auto& [e, count] : directed) {
            EXPECT_EQ(count, 1) << "edge " << e.first << "-" << e.second << " used twice in one direction";
            EXPECT_EQ(directed.count({e.second, e.first}), 1u) << "boundary edge " << e.first << "-" << e.second << " is open";
        }
        const double V = mesh_volume(nm.mesh);
        EXPECT_NEAR(enclosed_volume(nm.mesh, s), V, 1e-10 * V);
        // Each triangle is a face of its tet.
        for (std::size_t k = 0; k < s.triangles.size(); k += 97)
            for (index_t v : s.triangles[k]) {
                const index_t* q = &nm.mesh.tets[4 * std::size_t(s.tet[k])];
                EXPECT_TRUE(v == q[0] || v == q[1] || v == q[2] || v == q[3]);
            }
    }
}

TEST(Surface, BoxBoundaryHasTwoTrianglesPerCellFace) {
    const Mesh m = make_box(5, 3, 2);
    const BoundarySurface s = boundary_surface(m);
    EXPECT_EQ(s.triangles.size(), std::size_t(4 * (5 * 3 + 3 * 2 + 5 * 2)));
    EXPECT_EQ(s.vertices().size(), std::size_t(6 * 4 * 3 - 4 * 2 * 1));  // all vertices but the 4 x 2 x 1 inner ones
    // Normals of the top face (z = max) point along +z, of the bottom along -z.
    const std::vector<double> n = vertex_normals(s.triangles, m.X);
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (std::size_t k = 0; k < m.X.size(); ++k) {
        lo[k % 3] = std::min(lo[k % 3], m.X[k]);
        hi[k % 3] = std::max(hi[k % 3], m.X[k]);
    }
    const auto at = [](double x, double b) { return std::abs(x - b) < 1e-12; };
    int checked = 0;
    for (std::size_t v = 0; v < m.X.size() / 3; ++v) {
        const double* x = &m.X[3 * v];
        if (at(x[0], lo[0]) || at(x[0], hi[0]) || at(x[1], lo[1]) || at(x[1], hi[1])) continue;  // rims mix faces
        if (at(x[2], hi[2])) {
            EXPECT_NEAR(n[3 * v + 2], 1.0, 1e-12);
            ++checked;
        }
        if (at(x[2], lo[2])) {
            EXPECT_NEAR(n[3 * v + 2], -1.0, 1e-12);
            ++checked;
        }
    }
    EXPECT_EQ(checked, 2 * 4 * 2);
}

TEST(Surface, EmbeddedPointsFollowAffineMotionsExactly) {
    for (const auto& nm : test::test_meshes(10000)) {
        SCOPED_TRACE(nm.name);
        const Mesh& m = nm.mesh;
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (std::size_t k = 0; k < m.X.size(); ++k) {
            lo[k % 3] = std::min(lo[k % 3], m.X[k]);
            hi[k % 3] = std::max(hi[k % 3], m.X[k]);
        }
        // Points in and around the bounding box (10 % beyond it), tet centroids.
        std::mt19937 rng(3);
        std::vector<double> pts;
        for (int p = 0; p < 300; ++p)
            for (int i = 0; i < 3; ++i) {
                const double ext = hi[i] - lo[i];
                pts.push_back(std::uniform_real_distribution<double>(lo[i] - 0.1 * ext, hi[i] + 0.1 * ext)(rng));
            }
        for (index_t t = 0; t < m.num_tets(); t += 37)
            for (int i = 0; i < 3; ++i) {
                double c = 0;
                for (int k = 0; k < 4; ++k) c += m.X[3 * std::size_t(m.tets[4 * std::size_t(t) + k]) + i];
                pts.push_back(c / 4);
            }
        const Embedding e = embed_points(m, pts);
        const double scale = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
        int inside = 0;
        for (std::size_t p = 0; p < e.tet.size(); ++p) {
            const auto& w = e.weight[p];
            EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 1.0, 1e-12);
            if (e.outside[p] == 0) {
                ++inside;
                for (double x : w) EXPECT_GE(x, -1e-12);
            }
        }
        EXPECT_GT(inside, int(e.tet.size()) / 4);
        // u = A X + c: every embedded point moves to p + A p + c.
        const double A[3][3] = {{0.1, -0.2, 0.05}, {0.3, 0.02, -0.1}, {-0.05, 0.15, 0.2}}, c[3] = {0.01, -0.02, 0.03};
        std::vector<double> u(m.X.size());
        for (std::size_t v = 0; v < m.X.size() / 3; ++v)
            for (int i = 0; i < 3; ++i)
                u[3 * v + i] = A[i][0] * m.X[3 * v] + A[i][1] * m.X[3 * v + 1] + A[i][2] * m.X[3 * v + 2] + c[i];
        std::vector<double> out(pts.size());
        embedded_positions<double>(m, e, u, out);
        for (std::size_t p = 0; p < pts.size() / 3; ++p)
            for (int i = 0; i < 3; ++i) {
                const double want = pts[3 * p + i] + A[i][0] * pts[3 * p] + A[i][1] * pts[3 * p + 1] +
                                    A[i][2] * pts[3 * p + 2] + c[i];
                EXPECT_NEAR(out[3 * p + i], want, 1e-9 * scale) << "point " << p;
            }
    }
}

TEST(Surface, BadInputIsNamed) {
    const Mesh m = make_box(2, 2, 2);
    EXPECT_THROW(embed_points(m, std::vector<double>{0, 0}), InvalidArgument);
    EXPECT_THROW(embed_points(m, std::vector<double>{0, NAN, 0}), InvalidArgument);
    const Embedding e = embed_points(m, std::vector<double>{0.01, 0.01, 0.01});
    std::vector<double> out(3), u_short(5);
    EXPECT_THROW(embedded_positions<double>(m, e, u_short, out), InvalidArgument);
    Mesh bad = m;
    bad.tets[5] = 999;
    EXPECT_THROW(boundary_surface(bad), MeshError);
    const std::vector<std::array<index_t, 3>> tri = {{0, 1, 99}};
    EXPECT_THROW(vertex_normals(tri, m.X), InvalidArgument);
}
