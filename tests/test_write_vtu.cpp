// VTU / PVD output: write small meshes as ASCII, parse the numbers back
// (the binary form against these: test_vtu_output.cpp).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/write_vtu.hpp"
#include "io_test_util.hpp"

using namespace edgefem;
using edgefem::test::numbers;
using edgefem::test::slurp;

namespace {

// The text of the first DataArray whose opening tag contains `attribute`
// (e.g. Name="force"), after `section` (e.g. "<Points>").
std::string array_text(const std::string& xml, const std::string& attribute,
                       const std::string& section = "") {
    std::size_t from = section.empty() ? 0 : xml.find(section);
    if (from == std::string::npos) return {};
    std::size_t at = from;
    for (;;) {
        at = xml.find("<DataArray", at);
        if (at == std::string::npos) return {};
        const std::size_t close = xml.find('>', at);
        if (xml.substr(at, close - at).find(attribute) != std::string::npos) {
            const std::size_t end = xml.find("</DataArray>", close);
            return xml.substr(close + 1, end - close - 1);
        }
        at = close;
    }
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

}  // namespace

TEST(write_vtu, FieldsRoundTrip) {
    edgefem::test::TempDir dir("vtu");
    const Mesh m = read_tetgen(edgefem::test::data_file("small1"));
    std::vector<double> u(18), f(18);
    for (int i = 0; i < 18; ++i) {
        u[i] = 1e-3 * (i + 1) / 3.0;  // not exactly representable: tests full precision
        f[i] = -0.5 * i;
    }
    const std::vector<double> energy = {1.5, 2.25e7, 0.1};
    VtuFields fields;
    fields.displacement = u.data();
    fields.force = f.data();
    fields.energy_density = energy.data();
    const std::string path = dir.file("frame.vtu");
    write_vtu(path, m, fields, VtuFormat::Ascii);

    const std::string xml = slurp(path);
    EXPECT_TRUE(contains(xml, "<VTKFile type=\"UnstructuredGrid\""));
    EXPECT_TRUE(contains(xml, "NumberOfPoints=\"6\""));
    EXPECT_TRUE(contains(xml, "NumberOfCells=\"3\""));

    const auto points = numbers(array_text(xml, "NumberOfComponents", "<Points>"));
    ASSERT_EQ(points.size(), 18u);
    for (int i = 0; i < 18; ++i) EXPECT_EQ(points[i], m.X[i] + u[i]) << i;  // bit-exact
    EXPECT_EQ(numbers(array_text(xml, "Name=\"displacement\"")), u);
    EXPECT_EQ(numbers(array_text(xml, "Name=\"force\"")), f);
    EXPECT_EQ(numbers(array_text(xml, "Name=\"energy_density\"")), energy);
    EXPECT_EQ(numbers(array_text(xml, "Name=\"region\"")), (std::vector<double>{1, 2, 1}));
    EXPECT_EQ(numbers(array_text(xml, "Name=\"connectivity\"")),
              (std::vector<double>{0, 1, 2, 3, 1, 2, 3, 4, 0, 2, 1, 5}));
    EXPECT_EQ(numbers(array_text(xml, "Name=\"offsets\"")), (std::vector<double>{4, 8, 12}));
    EXPECT_EQ(numbers(array_text(xml, "Name=\"types\"")), (std::vector<double>{10, 10, 10}));
}

TEST(write_vtu, RestPositionsWithoutFields) {
    edgefem::test::TempDir dir("vtu0");
    const Mesh box = make_box(10, 5, 4);
    const std::string path = dir.file("box.vtu");
    write_vtu(path, box, {}, VtuFormat::Ascii);
    const std::string xml = slurp(path);
    EXPECT_TRUE(contains(xml, "NumberOfPoints=\"330\""));
    EXPECT_TRUE(contains(xml, "NumberOfCells=\"1200\""));
    EXPECT_FALSE(contains(xml, "<PointData"));
    EXPECT_FALSE(contains(xml, "energy_density"));
    EXPECT_EQ(numbers(array_text(xml, "NumberOfComponents", "<Points>")), box.X);
    EXPECT_EQ(numbers(array_text(xml, "Name=\"region\"")), std::vector<double>(1200, 0.0));
    const auto conn = numbers(array_text(xml, "Name=\"connectivity\""));
    ASSERT_EQ(conn.size(), box.tets.size());
    for (std::size_t i = 0; i < conn.size(); ++i) ASSERT_EQ(conn[i], box.tets[i]);
    EXPECT_TRUE(contains(xml, "</VTKFile>"));
}

TEST(write_vtu, PvdListsFrames) {
    edgefem::test::TempDir dir("pvd");
    const Mesh box = make_box(1, 1, 1);
    const std::string pvd = dir.file("series.pvd");
    {
        PvdSeries series(pvd);
        for (int k = 0; k < 3; ++k) {
            const std::string vtu = dir.file("frame_" + std::to_string(k) + ".vtu");
            write_vtu(vtu, box);
            series.add(0.25 * k, vtu);
        }
        series.add(1.0, "/somewhere/else/frame.vtu");
        series.write();
        const std::string xml = slurp(pvd);
        EXPECT_TRUE(contains(xml, "<VTKFile type=\"Collection\""));
        EXPECT_TRUE(contains(xml, "<DataSet timestep=\"0\" group=\"\" part=\"0\" file=\"frame_0.vtu\"/>"));
        EXPECT_TRUE(contains(xml, "timestep=\"0.25\""));
        EXPECT_TRUE(contains(xml, "file=\"frame_2.vtu\""));
        EXPECT_TRUE(contains(xml, "file=\"/somewhere/else/frame.vtu\""));
        series.add(2.0, dir.file("late.vtu"));
    }  // the destructor writes the final list
    EXPECT_TRUE(contains(slurp(pvd), "file=\"late.vtu\""));
}

TEST(write_vtu, UnwritablePathThrows) {
    const Mesh box = make_box(1, 1, 1);
    const std::string path = "/nonexistent_edgefem_dir/out.vtu";
    try {
        write_vtu(path, box);
        FAIL() << "expected edgefem::Error";
    } catch (const edgefem::Error& e) {
        EXPECT_TRUE(contains(e.what(), path)) << e.what();
    }
    PvdSeries series("/nonexistent_edgefem_dir/out.pvd");
    series.add(0, "a.vtu");
    EXPECT_THROW(series.write(), edgefem::Error);
    edgefem::test::TempDir dir("vtudir");
    EXPECT_THROW(write_vtu(dir.path(), box), edgefem::Error);  // a directory
}  // ~PvdSeries swallows the same error

namespace {

// Runs `body` in a child process whose files may not grow past `limit`
// bytes (RLIMIT_FSIZE, with SIGXFSZ ignored: a write past it fails with
// EFBIG, as on a full disk); returns the child's exit status (0 = body
// returned true).
template <class F>
int with_file_size_limit(rlim_t limit, F&& body) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::signal(SIGXFSZ, SIG_IGN);
        rlimit r{limit, limit};
        ::setrlimit(RLIMIT_FSIZE, &r);
        bool ok = false;
        try {
            ok = body();
        } catch (...) {
        }
        ::_exit(ok ? 0 : 1);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 100 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::vector<std::string> files_in(const std::string& dir) {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(dir)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace

// A write that fails part way (a full disk) leaves no partial .vtu, keeps
// the previous .pvd whole, and throws IoError naming the file. The .pvd used
// to be truncated and rewritten in place: a full disk left 4096 bytes of
// broken XML and every frame unreachable.
TEST(write_vtu, FailedWritesLeaveNoPartialFiles) {
    edgefem::test::TempDir dir("vtufull");
    const Mesh box = make_box(10, 10, 10);  // an ASCII frame of about 200 kB
    const std::string pvd = dir.file("s.pvd");
    {
        PvdSeries series(pvd);
        series.add(0, dir.file("f0.vtu"));
        series.write();
    }
    const std::string good_pvd = slurp(pvd);
    ASSERT_TRUE(contains(good_pvd, "</VTKFile>"));
    const int status = with_file_size_limit(64 * 1024, [&] {
        bool vtu_failed = false, pvd_failed = false;
        try {
            write_vtu(dir.file("big.vtu"), box, {}, VtuFormat::Ascii);
        } catch (const IoError& e) {
            vtu_failed = contains(e.what(), dir.file("big.vtu")) && e.path() == dir.file("big.vtu") &&
                         contains(e.what(), "too large");
        }
        PvdSeries series(pvd);
        for (int k = 0; k < 2000; ++k) series.add(k, dir.file("frame_with_a_long_name_" + std::to_string(k) + ".vtu"));
        try {
            series.write();
        } catch (const IoError& e) {
            pvd_failed = contains(e.what(), pvd);
        }
        return vtu_failed && pvd_failed;  // the destructor's retry fails silently
    });
    EXPECT_EQ(status, 0) << "the child saw no IoError naming the file (or crashed)";
    EXPECT_EQ(slurp(pvd), good_pvd);  // the old series, whole
    EXPECT_EQ(files_in(dir.path()), (std::vector<std::string>{"s.pvd"}));  // no partial or temporary file
}

// A symbolic link at the output name is replaced, never followed: its
// target keeps its contents.
TEST(write_vtu, SymlinkAtTheNameIsNotFollowed) {
    edgefem::test::TempDir dir("vtulink");
    edgefem::test::spit(dir.file("precious.txt"), "keep me\n");
    std::filesystem::create_symlink(dir.file("precious.txt"), dir.file("f.vtu"));
    write_vtu(dir.file("f.vtu"), make_box(1, 1, 1));
    EXPECT_EQ(slurp(dir.file("precious.txt")), "keep me\n");
    EXPECT_FALSE(std::filesystem::is_symlink(dir.file("f.vtu")));
    EXPECT_TRUE(contains(slurp(dir.file("f.vtu")), "</VTKFile>"));
}
