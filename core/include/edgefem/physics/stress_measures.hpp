// Stress measures for output, from the StVK element's H (the displacement
// gradient) and S (the second Piola-Kirchhoff stress), physics/tet_stvk.hpp:
//
//   J = det F,  sigma = F S F^T / J  (the Cauchy stress, F = I + H),
//   von Mises = sqrt(((s11 - s22)^2 + (s22 - s33)^2 + (s33 - s11)^2) / 2
//                    + 3 (s12^2 + s23^2 + s13^2))   of sigma.
//
// An inverted tet (J < 0) gives a finite sigma of flipped sign (its von
// Mises value is still >= 0); a degenerate one (J = 0) gives inf or NaN.
#pragma once

#include <cmath>

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

template <class S, class T>
EDGEFEM_FORMULA void cauchy_stress(const T (&H)[3][3], const T (&S2)[3][3], T (&sigma)[3][3]) {
    T F[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) F[r][c] = H[r][c] + (r == c ? S(1) : S(0));
    const T J = F[0][0] * (F[1][1] * F[2][2] - F[1][2] * F[2][1]) - F[0][1] * (F[1][0] * F[2][2] - F[1][2] * F[2][0]) +
                F[0][2] * (F[1][0] * F[2][1] - F[1][1] * F[2][0]);
    T FS[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) FS[r][c] = F[r][0] * S2[0][c] + F[r][1] * S2[1][c] + F[r][2] * S2[2][c];
    for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c)
            sigma[c][r] = sigma[r][c] = (FS[r][0] * F[c][0] + FS[r][1] * F[c][1] + FS[r][2] * F[c][2]) / J;
}

// The von Mises equivalent of a symmetric stress (std::sqrt, or a lane
// type's own sqrt found by argument-dependent lookup).
template <class S, class T>
EDGEFEM_FORMULA T von_mises(const T (&s)[3][3]) {
    using std::sqrt;
    const T a = s[0][0] - s[1][1], b = s[1][1] - s[2][2], c = s[2][2] - s[0][0];
    return sqrt(S(0.5) * (a * a + b * b + c * c) + S(3) * (s[0][1] * s[0][1] + s[1][2] * s[1][2] + s[0][2] * s[0][2]));
}

}  // namespace edgefem::physics
