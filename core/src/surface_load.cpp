#include "edgefem/core/surface_load.hpp"

#include <cmath>
#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/core/surface_selection.hpp"

namespace edgefem {

void add_surface_load_forces(std::span<const double> X, const SurfaceLoad& load, double scale, std::span<double> out) {
    const std::size_t nv = X.size() / 3;
    if (out.size() != X.size())
        throw InvalidArgument("surface load: expected 3 x #V = " + std::to_string(X.size()) + " force values, got " +
                              std::to_string(out.size()));
    for (std::size_t k = 0; k < load.triangles.size(); ++k) {
        const Triangle& t = load.triangles[k];
        for (const index_t v : t)
            if (v < 0 || std::size_t(v) >= nv)
                throw InvalidArgument("surface load: triangle " + std::to_string(k) + ": vertex " + std::to_string(v) +
                                      " out of range (mesh has " + std::to_string(nv) + " vertices)");
        const double* a = &X[3 * std::size_t(t[0])];
        const double* b = &X[3 * std::size_t(t[1])];
        const double* c = &X[3 * std::size_t(t[2])];
        const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        // n A = (b - a) x (c - a) / 2: the outward area vector.
        const double nA[3] = {0.5 * (e1[1] * e2[2] - e1[2] * e2[1]), 0.5 * (e1[2] * e2[0] - e1[0] * e2[2]),
                              0.5 * (e1[0] * e2[1] - e1[1] * e2[0])};
        const double area = std::sqrt(nA[0] * nA[0] + nA[1] * nA[1] + nA[2] * nA[2]);
        for (int r = 0; r < 3; ++r) {
            const double third = scale * (load.traction[r] * area - load.pressure * nA[r]) / 3;
            for (const index_t v : t) out[3 * std::size_t(v) + r] += third;
        }
    }
}

}  // namespace edgefem
