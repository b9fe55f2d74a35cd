#include "edgefem/core/make_box.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "edgefem/core/error.hpp"
#include "edgefem/core/memory_estimate.hpp"

namespace edgefem {

Mesh make_box(index_t nx, index_t ny, index_t nz, double cell) {
    if (nx < 1 || ny < 1 || nz < 1)
        throw InvalidArgument("make_box: cell counts must be >= 1, got " + std::to_string(nx) +
                              " x " + std::to_string(ny) + " x " + std::to_string(nz));
    if (!(cell > 0) || !std::isfinite(cell))
        throw InvalidArgument("make_box: cell size must be positive and finite, got " +
                              std::to_string(cell));
    const double limit = std::numeric_limits<index_t>::max();
    const double nt = 6.0 * nx * ny * nz;
    const double nv = (nx + 1.0) * (ny + 1.0) * (nz + 1.0);
    if (nt > limit || nv > limit)
        throw InvalidArgument("make_box: " + std::to_string(nt) +
                              " tets exceed the 32-bit index range");
    // Below 2^31 a box can still ask for tens of GB (box:1000x1000x350 ended
    // in a bare std::bad_alloc): refuse it with the size it would need.
    if (nt > double(kMaxBoxTets)) {
        char buf[320];
        std::snprintf(buf, sizeof buf,
                      "box of %d x %d x %d cells: %.3g tets, more than the limit of %lld (2^28); the mesh alone "
                      "would take %.3g GB, and a model several times that",
                      int(nx), int(ny), int(nz), nt, static_cast<long long>(kMaxBoxTets),
                      (nv * 3 * sizeof(double) + nt * 4 * sizeof(index_t)) / 1e9);
        throw InvalidArgument(buf);
    }
    // Under the limit a box can still need far more memory than the machine
    // has (2^28 tets: about 270 GB to simulate): said before allocating.
    check_memory("box of " + std::to_string(nx) + " x " + std::to_string(ny) + " x " + std::to_string(nz) + " cells",
                 static_cast<std::int64_t>(nt));

    Mesh mesh;
    const index_t sx = nx + 1, sy = ny + 1;
    const auto vid = [&](index_t i, index_t j, index_t k) { return i + sx * (j + sy * k); };
    mesh.X.resize(static_cast<std::size_t>(3 * nv));
    const double ox = -0.5 * nx * cell, oy = -0.5 * ny * cell, oz = -0.5 * nz * cell;
    for (index_t k = 0; k <= nz; ++k)
        for (index_t j = 0; j <= ny; ++j)
            for (index_t i = 0; i <= nx; ++i) {
                double* p = &mesh.X[3 * static_cast<std::size_t>(vid(i, j, k))];
                p[0] = ox + i * cell;
                p[1] = oy + j * cell;
                p[2] = oz + k * cell;
            }

    // The 6 axis permutations; odd ones are reoriented by swapping the last
    // two vertices so that every tet has positive volume.
    static constexpr int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                        {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    mesh.tets.reserve(static_cast<std::size_t>(4 * nt));
    for (index_t k = 0; k < nz; ++k)
        for (index_t j = 0; j < ny; ++j)
            for (index_t i = 0; i < nx; ++i)
                for (int p = 0; p < 6; ++p) {
                    int c[3] = {0, 0, 0};
                    index_t t[4];
                    t[0] = vid(i, j, k);
                    c[perms[p][0]] = 1;
                    t[1] = vid(i + c[0], j + c[1], k + c[2]);
                    c[perms[p][1]] = 1;
                    t[2] = vid(i + c[0], j + c[1], k + c[2]);
                    t[3] = vid(i + 1, j + 1, k + 1);
                    if (p >= 3) std::swap(t[2], t[3]);
                    mesh.tets.insert(mesh.tets.end(), t, t + 4);
                }
    return mesh;
}

bool is_box_spec(const std::string& spec) { return spec.rfind("box:", 0) == 0; }

Mesh make_box_from_spec(const std::string& spec) {
    const auto bad = [&] {
        return InvalidArgument("bad box mesh '" + spec + "': expected box:NXxNYxNZ with positive integers, e.g. box:10x5x4");
    };
    if (!is_box_spec(spec)) throw bad();
    index_t n[3];
    const char* p = spec.data() + 4;
    const char* end = spec.data() + spec.size();
    for (int i = 0; i < 3; ++i) {
        const auto [next, ec] = std::from_chars(p, end, n[i]);
        if (ec != std::errc() || n[i] <= 0) throw bad();
        p = next;
        if (i < 2) {
            if (p == end || (*p != 'x' && *p != 'X')) throw bad();
            ++p;
        }
    }
    if (p != end) throw bad();
    return make_box(n[0], n[1], n[2]);
}

Mesh make_box_of_size(double target_tets) {
    if (!(target_tets >= 6))
        throw InvalidArgument("make_box_of_size: target must be >= 6 tets");
    // 6 * n * (n/2) * (2n/5) tets with n cells along x.
    const double n = std::cbrt(target_tets / (6.0 * 0.5 * 0.4));
    const index_t nx = std::max<index_t>(1, static_cast<index_t>(std::lround(n)));
    const index_t ny = std::max<index_t>(1, static_cast<index_t>(std::lround(n * 0.5)));
    const index_t nz = std::max<index_t>(1, static_cast<index_t>(std::lround(n * 0.4)));
    return make_box(nx, ny, nz, 0.1 / nx);
}

}  // namespace edgefem
