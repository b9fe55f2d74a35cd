#include "edgefem/core/material.hpp"

#include <cmath>
#include <string>

#include "edgefem/core/error.hpp"

namespace edgefem {

namespace {
std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}
}  // namespace

void Material::validate() const {
    if (!std::isfinite(young) || young <= 0)
        throw InvalidArgument("material: Young's modulus must be positive and finite, got " + num(young));
    if (!std::isfinite(poisson) || poisson <= -1 || poisson >= 0.5)
        throw InvalidArgument("material: Poisson ratio must lie in (-1, 0.5), got " + num(poisson));
    if (!std::isfinite(density) || density <= 0)
        throw InvalidArgument("material: density must be positive and finite, got " + num(density));
}

void Materials::validate() const {
    fallback.validate();
    for (const auto& [region, m] : by_region) {
        try {
            m.validate();
        } catch (const InvalidArgument& e) {
            throw InvalidArgument("region " + std::to_string(region) + ": " + e.what());
        }
    }
}

}  // namespace edgefem
