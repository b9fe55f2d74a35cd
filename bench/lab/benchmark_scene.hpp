// The scene every "one time step" benchmark uses (bench_step, bench_paper,
// `edgefem bench --kernel step`), so their numbers are comparable.
#pragma once

#include "edgefem/core/scene.hpp"

namespace edgefem {

// Semi-implicit, h = 1 ms, gravity (0, 0, -9.81), the vertices in the lowest
// 1% of the mesh's z extent fixed, 20 warm-started CG iterations, no
// per-step inverted-tet count. Callers change what they vary.
Scene step_benchmark_scene(Mesh mesh, const Materials& materials);

}  // namespace edgefem
