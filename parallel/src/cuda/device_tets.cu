#include "cuda/device_operators.cuh"
#include "edgefem/physics/tet_volume.hpp"

namespace edgefem::cuda {

DeviceTets::DeviceTets(const Mesh& mesh) : num_tets(mesh.num_tets()), X(mesh.X), tets(mesh.tets) {}

template <class S>
index_t DeviceTets::inverted(const DeviceLaunch& launch, const S* u) const {
    const double* X0 = X.data();
    const index_t* T = tets.data();
    const double n = launch.sum(std::size_t(num_tets), [=] __device__(std::size_t t) {
        double x[4][3];
        for (int i = 0; i < 4; ++i) {
            const std::size_t v = std::size_t(T[4 * t + i]);
            for (int r = 0; r < 3; ++r) x[i][r] = X0[3 * v + r] + double(u[3 * v + r]);
        }
        return physics::tet_signed_volume(x[0], x[1], x[2], x[3]) <= 0 ? 1.0 : 0.0;
    });
    return index_t(n);
}

template index_t DeviceTets::inverted<double>(const DeviceLaunch&, const double*) const;
template index_t DeviceTets::inverted<float>(const DeviceLaunch&, const float*) const;

}  // namespace edgefem::cuda
