#include "edgefem/core/tet_fields.hpp"

#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/physics/stress_measures.hpp"
#include "edgefem/physics/tet_stvk.hpp"

namespace edgefem {

namespace {

void check_length(const char* what, std::size_t got, std::size_t want, bool optional) {
    if ((optional && got == 0) || got == want) return;
    throw InvalidArgument(std::string("tet_strain_stress: ") + what + " has " + std::to_string(got) +
                          " values, expected " + std::to_string(want));
}

void store_symmetric(const double (&m)[3][3], double* out) {
    out[0] = m[0][0];
    out[1] = m[1][1];
    out[2] = m[2][2];
    out[3] = m[0][1];
    out[4] = m[1][2];
    out[5] = m[0][2];
}

}  // namespace

void tet_strain_stress(const Mesh& mesh, const Materials& materials, const TetModel<double>& model,
                       std::span<const double> u, std::span<double> green_strain, std::span<double> pk2_stress,
                       std::span<double> von_mises) {
    const std::size_t nt = std::size_t(mesh.num_tets());
    if (model.tet.size() != nt) throw InvalidArgument("tet_strain_stress: the tet model is not the mesh's");
    check_length("u", u.size(), 3 * std::size_t(mesh.num_vertices()), false);
    check_length("green_strain", green_strain.size(), kSymmetricComponents * nt, true);
    check_length("pk2_stress", pk2_stress.size(), kSymmetricComponents * nt, true);
    check_length("von_mises", von_mises.size(), nt, true);
    for (std::size_t t = 0; t < nt; ++t) {
        double U[4][3];
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c) U[i][c] = u[3 * std::size_t(model.tet[t][i]) + c];
        const Material& m = materials.of(mesh.tet_region(index_t(t)));
        double H[3][3], G[3][3], S[3][3];
        physics::displacement_gradient(U, model.data[t].Dinv, H);
        physics::green_strain<double>(H, G);
        physics::stvk_stress(G, m.lambda(), m.mu(), S);
        if (!green_strain.empty()) store_symmetric(G, &green_strain[kSymmetricComponents * t]);
        if (!pk2_stress.empty()) store_symmetric(S, &pk2_stress[kSymmetricComponents * t]);
        if (!von_mises.empty()) {
            double sigma[3][3];
            physics::cauchy_stress<double>(H, S, sigma);
            von_mises[t] = physics::von_mises<double>(sigma);
        }
    }
}

}  // namespace edgefem
