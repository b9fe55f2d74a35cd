// The elastic operators of the CUDA back-end (ElasticOperator on device
// vectors) and what they share: the mesh on the device for the inverted-tet
// count.
#pragma once

#include <memory>

#include "cuda/device_launch.cuh"
#include "edgefem/core/elastic_operator.hpp"

namespace edgefem::cuda {

// The rest positions and tets on the device.
struct DeviceTets {
    explicit DeviceTets(const Mesh& mesh);
    // Tets with non-positive volume at X + u (tet_signed_volume).
    template <class S>
    index_t inverted(const DeviceLaunch& launch, const S* u) const;

    index_t num_tets = 0;
    DeviceArray<double> X;
    DeviceArray<index_t> tets;
};

// `lanes`: CudaOptions::multiply_lanes.
template <class S>
std::unique_ptr<ElasticOperator<S>> make_device_edge_operator(const Mesh& mesh, const Materials& materials,
                                                              ModelKind model, int lanes);  // device_edge_operator.cu
template <class S>
std::unique_ptr<ElasticOperator<S>> make_device_tet_operator(const Mesh& mesh,
                                                             const Materials& materials);  // device_tet_operator.cu

}  // namespace edgefem::cuda
