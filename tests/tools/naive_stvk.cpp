// An independent textbook StVK (per-tet, Total Lagrangian, from positions:
// F = Ds Dm^-1, G = (F^T F - I) / 2, P = F (lambda tr(G) I + 2 mu G),
// f_i = Vol P grad(phi_i)), sharing no code with edgefem: its own TetGen
// reader, Eigen for the algebra. Compares the files `edgefem forces` wrote.
//
// usage: naive_stvk MESH_PREFIX YOUNG POISSON OUT_PREFIX TOLERANCE
// reads MESH_PREFIX.node/.ele, OUT_PREFIX.pos/.force/.energy; exits 0 when
// max|f - f_ref| / max|f_ref| and |W - W_ref| / |W_ref| are within TOLERANCE.
#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<std::vector<double>> read_rows(const std::string& path, bool header) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::vector<std::vector<double>> rows;
    std::string line;
    bool skipped = !header;
    while (std::getline(in, line)) {
        if (const auto h = line.find('#'); h != std::string::npos) line.resize(h);
        std::istringstream ss(line);
        std::vector<double> row;
        double v;
        while (ss >> v) row.push_back(v);
        if (row.empty()) continue;
        if (!skipped) {
            skipped = true;
            continue;
        }
        rows.push_back(row);
    }
    return rows;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 6) {
        std::cerr << "usage: naive_stvk MESH_PREFIX YOUNG POISSON OUT_PREFIX TOLERANCE\n";
        return 2;
    }
    const std::string mesh = argv[1], out = argv[4];
    const double Y = std::stod(argv[2]), nu = std::stod(argv[3]), tol = std::stod(argv[5]);
    const double lambda = Y * nu / ((1 + nu) * (1 - 2 * nu)), mu = Y / (2 * (1 + nu));

    const auto nodes = read_rows(mesh + ".node", true);
    const auto eles = read_rows(mesh + ".ele", true);
    const auto pos = read_rows(out + ".pos", false);
    const auto force = read_rows(out + ".force", false);
    const auto energy = read_rows(out + ".energy", false);
    const int base = static_cast<int>(nodes.at(0).at(0));  // 0- or 1-based
    const std::size_t nv = nodes.size();
    if (pos.size() != nv || force.size() != nv) {
        std::cerr << "vertex count mismatch\n";
        return 1;
    }
    auto X = [&](std::size_t v) { return Eigen::Vector3d(nodes[v][1], nodes[v][2], nodes[v][3]); };
    auto x = [&](std::size_t v) { return Eigen::Vector3d(pos[v][0], pos[v][1], pos[v][2]); };

    std::vector<Eigen::Vector3d> f(nv, Eigen::Vector3d::Zero());
    double W = 0;
    for (const auto& e : eles) {
        std::size_t v[4];
        for (int k = 0; k < 4; ++k) v[k] = static_cast<std::size_t>(e.at(k + 1)) - base;
        Eigen::Matrix3d Dm, Ds;
        for (int c = 0; c < 3; ++c) {
            Dm.col(c) = X(v[c + 1]) - X(v[0]);
            Ds.col(c) = x(v[c + 1]) - x(v[0]);
        }
        const double vol = Dm.determinant() / 6;
        const Eigen::Matrix3d Dinv = Dm.inverse();
        const Eigen::Matrix3d F = Ds * Dinv;
        const Eigen::Matrix3d G = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
        const Eigen::Matrix3d S = lambda * G.trace() * Eigen::Matrix3d::Identity() + 2 * mu * G;
        W += vol * (0.5 * lambda * G.trace() * G.trace() + mu * (G.array() * G.array()).sum());
        const Eigen::Matrix3d H = vol * F * S * Dinv.transpose();  // columns: gradients wrt x_1..x_3
        for (int c = 0; c < 3; ++c) {
            f[v[c + 1]] += H.col(c);
            f[v[0]] -= H.col(c);
        }
    }
    double diff = 0, scale = 0;
    for (std::size_t v = 0; v < nv; ++v)
        for (int r = 0; r < 3; ++r) {
            diff = std::max(diff, std::abs(force[v][r] - f[v][r]));
            scale = std::max(scale, std::abs(f[v][r]));
        }
    const double rel_f = diff / scale, rel_W = std::abs(energy.at(0).at(0) - W) / std::abs(W);
    std::printf("force_rel_diff: %.3e\nenergy_rel_diff: %.3e\ntolerance: %.1e\n", rel_f, rel_W, tol);
    return (rel_f <= tol && rel_W <= tol) ? 0 : 1;
}
