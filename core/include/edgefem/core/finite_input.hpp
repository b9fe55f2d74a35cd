// A caller's per-vertex vectors (xyz interleaved) checked for NaN and
// infinity before the library uses them, so that a bad input is named as
// one (InvalidArgument naming the array, the vertex and the component)
// instead of surfacing later as a failed solve or an "unstable" step.
#pragma once

#include <cmath>
#include <cstddef>
#include <span>
#include <string>

#include "edgefem/core/error.hpp"

namespace edgefem {

template <class S>
void require_finite_vectors(std::span<const S> xyz, const std::string& name) {
    for (std::size_t i = 0; i < xyz.size(); ++i)
        if (!std::isfinite(xyz[i]))
            throw InvalidArgument(name + ": vertex " + std::to_string(i / 3) + " has a non-finite " + "xyz"[i % 3] +
                                  " component (" + std::to_string(double(xyz[i])) + ")");
}

}  // namespace edgefem
