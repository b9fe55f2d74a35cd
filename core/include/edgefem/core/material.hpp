// Linear-elastic constants of the StVK material, per region.
#pragma once

#include <map>

namespace edgefem {

struct Material {
    double young = 1e5;      // Young's modulus Y (Pa)
    double poisson = 0.3;    // Poisson ratio nu, in (-1, 0.5)
    double density = 1000;   // kg/m^3

    // lambda = Y nu / ((1+nu)(1-2nu)), mu = Y / (2(1+nu)).
    double lambda() const { return young * poisson / ((1 + poisson) * (1 - 2 * poisson)); }
    double mu() const { return young / (2 * (1 + poisson)); }

    // Throws InvalidArgument naming the parameter when Y <= 0, nu outside
    // (-1, 0.5), density <= 0, or any value non-finite.
    void validate() const;
};

// One material per region id; regions without an entry use `fallback`.
struct Materials {
    Material fallback;
    std::map<int, Material> by_region;

    Materials() = default;
    Materials(const Material& m) : fallback(m) {}  // NOLINT: a single material is the common case
    const Material& of(int region) const {
        const auto it = by_region.find(region);
        return it == by_region.end() ? fallback : it->second;
    }
    void validate() const;
};

}  // namespace edgefem
