// The signed volume of a tet (a, b, c, d): (b - a) . ((c - a) x (d - a)) / 6,
// positive for a positively oriented tet. What mesh checks and the inverted-
// tet counts of every back-end use.
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

EDGEFEM_FORMULA double tet_signed_volume(const double* a, const double* b, const double* c, const double* d) {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0])) /
           6.0;
}

}  // namespace edgefem::physics
