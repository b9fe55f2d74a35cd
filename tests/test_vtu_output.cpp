// Frames for ParaView and engines, checked by readers written here, not by
// the writers' code: the compressed binary VTU decoded by a small reader of
// VTK's appended zlib layout (XML header, UInt64 block headers, inflate)
// and compared bit for bit with the values in memory and with the ASCII
// file's numbers; the strain and stress fields against the closed form of a
// homogeneous deformation; PLY and OBJ surfaces parsed back, their triangles
// counted and their orientation checked by the enclosed volume.
#include <gtest/gtest.h>
#include <zlib.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/surface.hpp"
#include "edgefem/core/tet_fields.hpp"
#include "edgefem/core/tet_model.hpp"
#include "edgefem/core/write_surface.hpp"
#include "edgefem/core/write_vtu.hpp"
#include "io_test_util.hpp"

using namespace edgefem;
using edgefem::test::numbers;
using edgefem::test::slurp;

namespace {

// The value of attribute `key` in the tag text `tag` ("" when absent).
std::string attribute(const std::string& tag, const std::string& key) {
    const std::string k = " " + key + "=\"";
    const std::size_t at = tag.find(k);
    if (at == std::string::npos) return {};
    const std::size_t from = at + k.size();
    return tag.substr(from, tag.find('"', from) - from);
}

struct Array {
    std::string type;
    int components = 1;
    std::string bytes;  // the decoded values
    std::string text;   // ASCII: the element's text
};

std::uint64_t u64_at(const std::string& s, std::size_t at) {
    std::uint64_t v;
    std::memcpy(&v, s.data() + at, 8);
    return v;
}

// Reads every DataArray of a .vtu (ASCII or appended zlib binary) by name;
// the points' array (no Name) is "Points".
std::map<std::string, Array> read_vtu(const std::string& file) {
    std::map<std::string, Array> out;
    const std::size_t appended_tag = file.find("<AppendedData encoding=\"raw\">");
    const std::size_t header_end = appended_tag == std::string::npos ? file.size() : appended_tag;
    const std::size_t base = appended_tag == std::string::npos ? 0 : file.find('_', appended_tag) + 1;
    for (std::size_t at = file.find("<DataArray"); at < header_end; at = file.find("<DataArray", at + 1)) {
        const std::string tag = file.substr(at, file.find('>', at) - at + 1);
        Array a;
        a.type = attribute(tag, "type");
        if (const std::string c = attribute(tag, "NumberOfComponents"); !c.empty()) a.components = std::stoi(c);
        std::string name = attribute(tag, "Name");
        if (name.empty()) name = "Points";
        if (attribute(tag, "format") == "ascii") {
            const std::size_t from = at + tag.size();
            a.text = file.substr(from, file.find("</DataArray>", from) - from);
        } else {
            EXPECT_EQ(attribute(tag, "format"), "appended") << tag;
            // vtkZLibDataCompressor: [#blocks, block size, last partial block
            // size (0: full)], a compressed size per block, then the blocks.
            std::size_t p = base + std::stoull(attribute(tag, "offset"));
            const std::uint64_t nb = u64_at(file, p), bs = u64_at(file, p + 8), last = u64_at(file, p + 16);
            std::size_t data = p + 24 + 8 * nb;
            for (std::uint64_t b = 0; b < nb; ++b) {
                const std::uint64_t csize = u64_at(file, p + 24 + 8 * b);
                const std::uint64_t want = (b + 1 == nb && last != 0) ? last : bs;
                std::string block(want, '\0');
                uLongf got = uLongf(want);
                EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(block.data()), &got,
                                     reinterpret_cast<const Bytef*>(file.data() + data), uLong(csize)),
                          Z_OK)
                    << name << " block " << b;
                EXPECT_EQ(got, want) << name << " block " << b;
                a.bytes += block;
                data += csize;
            }
        }
        out[name] = a;
    }
    return out;
}

template <class T>
std::vector<T> values(const Array& a) {
    std::vector<T> v(a.bytes.size() / sizeof(T));
    std::memcpy(v.data(), a.bytes.data(), v.size() * sizeof(T));
    return v;
}

// Bitwise: the same doubles, -0 and NaN payloads included.
bool same_bits(const std::vector<double>& a, const double* b, std::size_t n) {
    return a.size() == n && std::memcmp(a.data(), b, n * sizeof(double)) == 0;
}

}  // namespace

TEST(VtuBinary, DecodesToTheValuesInMemoryAndTheAsciiFileBitwise) {
    edgefem::test::TempDir dir("vtubin");
    const Mesh m = read_tetgen(edgefem::test::data_file("small1"));  // 6 vertices, 3 tets, regions 1 2 1
    std::vector<double> u(18), v(18), f(18), energy = {1.5, 2.25e7, 0.1}, strain(18), stress(18), vm = {-0.0, 1e-300, 3};
    for (int i = 0; i < 18; ++i) {
        u[i] = 1e-3 * (i + 1) / 3.0;  // not exactly representable
        v[i] = std::sqrt(double(i + 2));
        f[i] = -0.5 * i;
        strain[i] = 1.0 / (i + 7);
        stress[i] = std::exp(double(i));
    }
    const std::vector<index_t> file_vertex = {0, 1, 2, 3, 4, 6};
    VtuFields fields;
    fields.displacement = u.data();
    fields.velocity = v.data();
    fields.force = f.data();
    fields.energy_density = energy.data();
    fields.green_strain = strain.data();
    fields.pk2_stress = stress.data();
    fields.von_mises = vm.data();
    fields.file_vertex = file_vertex.data();
    write_vtu(dir.file("b.vtu"), m, fields);  // binary: the default
    write_vtu(dir.file("a.vtu"), m, fields, VtuFormat::Ascii);
    const std::string bin = slurp(dir.file("b.vtu"));
    EXPECT_NE(bin.find("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
                       "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">"),
              std::string::npos);
    const auto b = read_vtu(bin);
    const auto a = read_vtu(slurp(dir.file("a.vtu")));

    std::vector<double> points(m.X);
    for (int i = 0; i < 18; ++i) points[i] += u[i];
    const std::map<std::string, std::pair<const double*, std::size_t>> doubles = {
        {"Points", {points.data(), 18}},     {"displacement", {u.data(), 18}}, {"velocity", {v.data(), 18}},
        {"force", {f.data(), 18}},           {"energy_density", {energy.data(), 3}},
        {"green_strain", {strain.data(), 18}}, {"pk2_stress", {stress.data(), 18}}, {"von_mises", {vm.data(), 3}}};
    for (const auto& [name, data] : doubles) {
        ASSERT_TRUE(b.count(name) && a.count(name)) << name;
        EXPECT_EQ(b.at(name).type, "Float64") << name;
        EXPECT_EQ(b.at(name).components, a.at(name).components) << name;
        EXPECT_TRUE(same_bits(values<double>(b.at(name)), data.first, data.second)) << name;
        EXPECT_TRUE(same_bits(numbers(a.at(name).text), data.first, data.second)) << name;
    }
    EXPECT_EQ(b.at("green_strain").components, 6);
    EXPECT_EQ(b.at("velocity").components, 3);
    EXPECT_EQ(values<std::int32_t>(b.at("connectivity")), (std::vector<std::int32_t>(m.tets.begin(), m.tets.end())));
    EXPECT_EQ(values<std::int64_t>(b.at("offsets")), (std::vector<std::int64_t>{4, 8, 12}));
    EXPECT_EQ(values<std::uint8_t>(b.at("types")), (std::vector<std::uint8_t>{10, 10, 10}));
    EXPECT_EQ(values<std::int32_t>(b.at("region")), (std::vector<std::int32_t>{1, 2, 1}));
    EXPECT_EQ(values<std::int64_t>(b.at("file_vertex")), (std::vector<std::int64_t>{0, 1, 2, 3, 4, 6}));
    EXPECT_EQ(numbers(a.at("connectivity").text), (std::vector<double>{0, 1, 2, 3, 1, 2, 3, 4, 0, 2, 1, 5}));
}

// Arrays of several 32 KiB blocks, with a partial last block and with an
// exactly full one (the header's third word is then 0).
TEST(VtuBinary, ArraysSpanningSeveralBlocks) {
    edgefem::test::TempDir dir("vtublocks");
    const Mesh box = make_box(20, 10, 10);  // 12000 tets: 192,000 bytes of connectivity, 6 blocks
    write_vtu(dir.file("box.vtu"), box);
    const auto b = read_vtu(slurp(dir.file("box.vtu")));
    EXPECT_EQ(values<std::int32_t>(b.at("connectivity")), (std::vector<std::int32_t>(box.tets.begin(), box.tets.end())));
    EXPECT_TRUE(same_bits(values<double>(b.at("Points")), box.X.data(), box.X.size()));
    const auto offsets = values<std::int64_t>(b.at("offsets"));
    ASSERT_EQ(offsets.size(), 12000u);
    EXPECT_EQ(offsets.back(), 48000);

    Mesh same;  // 4096 copies of one tet: 4096 Int64 offsets are exactly one block
    same.X = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (int t = 0; t < 4096; ++t) same.tets.insert(same.tets.end(), {0, 1, 2, 3});
    write_vtu(dir.file("full.vtu"), same);
    const std::string file = slurp(dir.file("full.vtu"));
    const auto c = read_vtu(file);
    ASSERT_EQ(values<std::int64_t>(c.at("offsets")).size(), 4096u);
    EXPECT_EQ(values<std::int64_t>(c.at("offsets"))[4095], 4 * 4096);
    EXPECT_EQ(values<std::uint8_t>(c.at("types")), std::vector<std::uint8_t>(4096, 10));
}

// A homogeneous deformation x = A X: every tet has F = A, so E = (A^T A -
// I) / 2, S = lambda tr(E) I + 2 mu E with its region's constants, and the
// Cauchy stress A S A^T / det A, whose von Mises value is computed here from
// its deviator, sqrt(3/2 s:s).
TEST(TetFields, HomogeneousDeformationHasTheClosedFormStrainAndStress) {
    const Mesh m = read_tetgen(edgefem::test::data_file("small1"));
    Materials materials(Material{1e5, 0.3, 1000});
    materials.by_region[2] = Material{3e6, 0.45, 1000};
    const double A[3][3] = {{1.2, 0.1, -0.05}, {0.03, 0.9, 0.2}, {-0.1, 0.04, 1.1}};
    std::vector<double> u(m.X.size());
    for (index_t v = 0; v < m.num_vertices(); ++v)
        for (int r = 0; r < 3; ++r) {
            double x = 0;
            for (int c = 0; c < 3; ++c) x += A[r][c] * m.X[3 * v + c];
            u[3 * v + r] = x - m.X[3 * v + r];
        }
    const TetModel<double> model = make_tet_model<double>(m, materials);
    std::vector<double> E6(18), S6(18), vm(3);
    tet_strain_stress(m, materials, model, u, E6, S6, vm);

    double E[3][3], detA = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                           A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                           A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            E[i][j] = -0.5 * (i == j);
            for (int k = 0; k < 3; ++k) E[i][j] += 0.5 * A[k][i] * A[k][j];
        }
    const int order[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};  // VTK's XX YY ZZ XY YZ XZ
    for (index_t t = 0; t < m.num_tets(); ++t) {
        const Material& mat = materials.of(m.tet_region(t));
        const double lambda = mat.young * mat.poisson / ((1 + mat.poisson) * (1 - 2 * mat.poisson));
        const double mu = mat.young / (2 * (1 + mat.poisson));
        const double trE = E[0][0] + E[1][1] + E[2][2];
        double S[3][3], sigma[3][3] = {};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) S[i][j] = lambda * trE * (i == j) + 2 * mu * E[i][j];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k)
                    for (int l = 0; l < 3; ++l) sigma[i][j] += A[i][k] * S[k][l] * A[j][l] / detA;
        for (int c = 0; c < 6; ++c) {
            const auto [i, j] = order[c];
            EXPECT_NEAR(E6[6 * t + c], E[i][j], 1e-13) << "tet " << t << " component " << c;
            EXPECT_NEAR(S6[6 * t + c], S[i][j], 1e-13 * mat.young) << "tet " << t << " component " << c;
        }
        const double p = (sigma[0][0] + sigma[1][1] + sigma[2][2]) / 3;
        double ss = 0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) ss += std::pow(sigma[i][j] - p * (i == j), 2);
        EXPECT_NEAR(vm[t], std::sqrt(1.5 * ss), 1e-12 * std::sqrt(1.5 * ss)) << "tet " << t;
    }
    // At rest: no strain, no stress.
    const std::vector<double> zero(u.size(), 0.0);
    tet_strain_stress(m, materials, model, zero, E6, {}, vm);
    for (const double e : E6) EXPECT_EQ(e, 0.0);
    for (const double s : vm) EXPECT_EQ(s, 0.0);
    // Wrong lengths are named.
    const std::vector<double> short_u(5);
    try {
        tet_strain_stress(m, materials, model, short_u, E6, S6, vm);
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("u has 5 values, expected 18"), std::string::npos) << e.what();
    }
    std::vector<double> bad(17);
    EXPECT_THROW(tet_strain_stress(m, materials, model, u, bad, {}, {}), InvalidArgument);
}

namespace {

// The boundary of a box of 4 x 3 x 2 cubes of 1 cm under x = A X, renumbered
// to its own points, and the normals.
struct Skin {
    std::vector<double> positions, normals;
    std::vector<std::array<index_t, 3>> triangles;
    double volume = 0;  // det A times the box's
};

Skin deformed_box_skin() {
    const Mesh box = make_box(4, 3, 2, 0.01);
    const double A[3][3] = {{1.1, 0.2, 0}, {0, 0.95, 0.1}, {0.05, 0, 1.3}};
    const BoundarySurface s = boundary_surface(box);
    const std::vector<index_t> verts = s.vertices();
    std::map<index_t, index_t> local;
    Skin k;
    for (const index_t v : verts) {
        local[v] = index_t(local.size());
        for (int r = 0; r < 3; ++r) {
            double x = 0;
            for (int c = 0; c < 3; ++c) x += A[r][c] * box.X[3 * v + c];
            k.positions.push_back(x);
        }
    }
    for (const auto& t : s.triangles) k.triangles.push_back({local[t[0]], local[t[1]], local[t[2]]});
    k.normals = vertex_normals(k.triangles, k.positions);
    const double detA = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                        A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    k.volume = detA * 0.04 * 0.03 * 0.02;
    return k;
}

// Divergence theorem: the volume enclosed by outward triangles.
double enclosed_volume(const std::vector<double>& x, const std::vector<std::array<index_t, 3>>& tris) {
    double v = 0;
    for (const auto& t : tris) {
        const double* a = &x[3 * t[0]];
        const double* b = &x[3 * t[1]];
        const double* c = &x[3 * t[2]];
        v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
    }
    return v;
}

// 2 triangles per cube face on the outside of NX x NY x NZ cubes.
constexpr std::size_t kBoxTriangles = 4 * (4 * 3 + 3 * 2 + 4 * 2);

}  // namespace

TEST(SurfaceFiles, PlyReadsBackWithOutwardTriangles) {
    edgefem::test::TempDir dir("ply");
    const Skin k = deformed_box_skin();
    write_ply(dir.file("s.ply"), k.positions, k.triangles, k.normals);
    const std::string file = slurp(dir.file("s.ply"));
    const std::size_t body = file.find("end_header\n") + 11;
    std::istringstream header(file.substr(0, body));
    std::string line, format;
    std::size_t nv = 0, nf = 0;
    std::vector<std::string> props;
    while (std::getline(header, line)) {
        std::istringstream w(line);
        std::string a, b, c;
        w >> a >> b >> c;
        if (a == "format") format = b;
        if (a == "element" && b == "vertex") nv = std::stoul(c);
        if (a == "element" && b == "face") nf = std::stoul(c);
        if (a == "property" && b == "float") props.push_back(c);
        if (a == "property" && b == "list") {
            EXPECT_EQ(line, "property list uchar int vertex_indices");
        }
    }
    EXPECT_EQ(format, "binary_little_endian");
    EXPECT_EQ(props, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz"}));
    ASSERT_EQ(nv, k.positions.size() / 3);
    ASSERT_EQ(nf, kBoxTriangles);
    ASSERT_EQ(file.size(), body + nv * 24 + nf * 13);
    std::vector<double> x(3 * nv);
    for (std::size_t v = 0; v < nv; ++v) {
        float p[6];
        std::memcpy(p, file.data() + body + 24 * v, 24);
        for (int c = 0; c < 3; ++c) {
            x[3 * v + c] = p[c];
            EXPECT_EQ(p[c], float(k.positions[3 * v + c]));
            EXPECT_EQ(p[3 + c], float(k.normals[3 * v + c]));
        }
        EXPECT_NEAR(double(p[3]) * p[3] + double(p[4]) * p[4] + double(p[5]) * p[5], 1.0, 1e-6);
    }
    std::vector<std::array<index_t, 3>> tris(nf);
    for (std::size_t f = 0; f < nf; ++f) {
        const char* at = file.data() + body + 24 * nv + 13 * f;
        EXPECT_EQ(std::uint8_t(at[0]), 3);
        std::memcpy(tris[f].data(), at + 1, 12);
    }
    EXPECT_NEAR(enclosed_volume(x, tris), k.volume, 1e-6 * k.volume);  // float positions
}

TEST(SurfaceFiles, ObjReadsBackExactlyWithOutwardTriangles) {
    edgefem::test::TempDir dir("obj");
    const Skin k = deformed_box_skin();
    write_obj(dir.file("s.obj"), k.positions, k.triangles, k.normals);
    std::istringstream in(slurp(dir.file("s.obj")));
    in.imbue(std::locale::classic());
    std::vector<double> x, n;
    std::vector<std::array<index_t, 3>> tris;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream w(line);
        w.imbue(std::locale::classic());
        std::string tag;
        w >> tag;
        double a, b, c;
        if (tag == "v" && w >> a >> b >> c) x.insert(x.end(), {a, b, c});
        if (tag == "vn" && w >> a >> b >> c) n.insert(n.end(), {a, b, c});
        if (tag == "f") {
            std::array<index_t, 3> t;
            for (index_t& v : t) {
                std::string ref;
                w >> ref;  // "i//i": vertex and normal, 1-based
                const std::size_t slash = ref.find("//");
                ASSERT_NE(slash, std::string::npos) << line;
                EXPECT_EQ(ref.substr(0, slash), ref.substr(slash + 2));
                v = index_t(std::stol(ref.substr(0, slash)) - 1);
            }
            tris.push_back(t);
        }
    }
    EXPECT_EQ(x, k.positions);  // shortest round-trip text: exact
    EXPECT_EQ(n, k.normals);
    EXPECT_EQ(tris.size(), kBoxTriangles);
    EXPECT_NEAR(enclosed_volume(x, tris), k.volume, 1e-12 * k.volume);
}

TEST(SurfaceFiles, VtuOfTrianglesDecodes) {
    edgefem::test::TempDir dir("svtu");
    const Skin k = deformed_box_skin();
    const std::vector<int> region(k.triangles.size(), 7);
    std::vector<double> vm(k.triangles.size());
    for (std::size_t i = 0; i < vm.size(); ++i) vm[i] = 1.0 / double(i + 3);
    VtuFields f;
    f.normals = k.normals.data();
    f.von_mises = vm.data();
    write_surface_vtu(dir.file("s.vtu"), k.positions, k.triangles, region, f);
    const auto b = read_vtu(slurp(dir.file("s.vtu")));
    EXPECT_TRUE(same_bits(values<double>(b.at("Points")), k.positions.data(), k.positions.size()));
    EXPECT_TRUE(same_bits(values<double>(b.at("normals")), k.normals.data(), k.normals.size()));
    EXPECT_TRUE(same_bits(values<double>(b.at("von_mises")), vm.data(), vm.size()));
    const auto conn = values<std::int32_t>(b.at("connectivity"));
    ASSERT_EQ(conn.size(), 3 * kBoxTriangles);
    EXPECT_EQ(std::memcmp(conn.data(), k.triangles.data(), conn.size() * 4), 0);
    EXPECT_EQ(values<std::uint8_t>(b.at("types")), std::vector<std::uint8_t>(kBoxTriangles, 5));  // VTK_TRIANGLE
    EXPECT_EQ(values<std::int64_t>(b.at("offsets")).back(), std::int64_t(3 * kBoxTriangles));
    EXPECT_EQ(values<std::int32_t>(b.at("region")), std::vector<std::int32_t>(kBoxTriangles, 7));
}

TEST(SurfaceFiles, BadInputIsNamed) {
    edgefem::test::TempDir dir("sbad");
    const std::vector<double> x = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::vector<std::array<index_t, 3>> bad = {{0, 1, 3}};
    const auto message = [](auto&& fn) {
        try {
            fn();
        } catch (const InvalidArgument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message([&] { write_ply(dir.file("a.ply"), x, bad); }).find("write_ply: triangle 0 names point 3"),
              std::string::npos);
    EXPECT_NE(message([&] { write_obj(dir.file("a.obj"), x, bad); }).find("write_obj: triangle 0 names point 3"),
              std::string::npos);
    const std::vector<std::array<index_t, 3>> good = {{0, 1, 2}};
    EXPECT_NE(message([&] { write_ply(dir.file("a.ply"), x, good, std::vector<double>(6)); }).find("normals has 6"),
              std::string::npos);
    EXPECT_NE(message([&] { write_surface_vtu(dir.file("a.vtu"), x, good, std::vector<int>{}); }).find("region has 0"),
              std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(dir.file("a.ply")));
}
