// The CUDA back-end's loops (a Launch, unified/unified_vector_kernels.hpp):
// grid-stride kernels for the element-wise loops, and reductions in an order
// fixed by n alone (never by the device or the grid), so that every run on
// any GPU gives the same bits. Each reduction returns its value to the host
// (one scalar or small struct per call), or leaves it on the device for a
// device-side continuation (sum_then).
#pragma once

#include <memory>

#include "cuda/device_support.cuh"
#include "edgefem/physics/host_device.hpp"

namespace edgefem::cuda {

template <class Body>
__global__ void each_kernel(std::size_t n, Body body) {
    for (std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x; i < n; i += std::size_t(gridDim.x) * blockDim.x)
        body(i);
}

// Sum reductions: a fixed number of blocks (kSumBlocks, fewer for short
// vectors: a function of n), each thread summing its items in index order,
// then a fixed tree in shared memory; the last block to finish (an integer
// counter) then sums the blocks' partials the same way, in block order. One
// launch; the order of every addition is fixed by n.
inline constexpr int kSumBlocks = 1024;

template <class T>
__device__ void block_tree(T* shared, T value, T* out) {
    shared[threadIdx.x] = value;
    __syncthreads();
    for (int s = kThreads / 2; s > 0; s /= 2) {
        if (int(threadIdx.x) < s) shared[threadIdx.x] = shared[threadIdx.x] + shared[threadIdx.x + s];
        __syncthreads();
    }
    if (threadIdx.x == 0) *out = shared[0];
}

// The sum of term(i) over [0, n), left in partial[gridDim.x] and handed to
// finish(total) on thread 0 of the last block. `done` is 0 on entry and
// again on exit.
template <class Term, class Finish>
__global__ void sum_kernel(std::size_t n, Term term, double* partial, unsigned* done, Finish finish) {
    __shared__ double shared[kThreads];
    __shared__ double total;
    __shared__ bool last;
    double s = 0;
    for (std::size_t i = blockIdx.x * std::size_t(kThreads) + threadIdx.x; i < n; i += std::size_t(gridDim.x) * kThreads)
        s += term(i);
    block_tree(shared, s, &partial[blockIdx.x]);
    if (threadIdx.x == 0) {
        __threadfence();  // this block's partial is visible before it counts itself done
        last = atomicAdd(done, 1u) == gridDim.x - 1;
    }
    __syncthreads();
    if (!last) return;
    __threadfence();
    s = 0;
    for (int i = threadIdx.x; i < int(gridDim.x); i += kThreads) s += __ldcg(&partial[i]);
    block_tree(shared, s, &total);
    if (threadIdx.x == 0) {
        *done = 0;
        partial[gridDim.x] = total;
        finish(total);
    }
}

// Generic reductions: chunks of kReduceChunk items (whole vertices), one
// thread each, then groups of kCombineGroup partials combined in order,
// level by level.
inline constexpr std::size_t kReduceChunk = 96;
inline constexpr std::size_t kCombineGroup = 32;

template <class R, class Block>
__global__ void reduce_chunks_kernel(std::size_t n, std::size_t chunks, Block block, R* part) {
    const std::size_t c = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
    if (c >= chunks) return;
    const std::size_t lo = c * kReduceChunk, hi = lo + kReduceChunk < n ? lo + kReduceChunk : n;
    part[c] = block(lo, hi);
}

template <class R, class Combine>
__global__ void combine_kernel(std::size_t count, const R* in, R* out, Combine combine) {
    const std::size_t g = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
    const std::size_t lo = g * kCombineGroup;
    if (lo >= count) return;
    const std::size_t hi = lo + kCombineGroup < count ? lo + kCombineGroup : count;
    R acc = in[lo];
    for (std::size_t k = lo + 1; k < hi; ++k) combine(acc, in[k]);
    out[g] = acc;
}

// Scratch for the reductions' partials, grown as needed. One per back-end:
// its calls run one at a time (a Simulator's steps are sequential).
struct ReduceScratch {
    DeviceArray<unsigned char> bytes;
    DeviceArray<unsigned> done{1};  // sum_kernel's counter
    void* get(std::size_t n) {
        if (bytes.size() < n) bytes.resize(n);
        return bytes.data();
    }
};

struct DeviceLaunch {
    std::shared_ptr<ReduceScratch> scratch = std::make_shared<ReduceScratch>();

    template <class Body>
    void each(std::size_t n, Body body) const {
        if (n == 0) return;
        each_kernel<<<grid_for(n), kThreads>>>(n, body);
        check_launch("each_kernel");
    }
    template <class Body>
    void each_vertex(std::size_t n, Body body) const {
        each(n / 3, body);
    }
    // One vertex (3 dofs) per block: body(3 v, 3 v + 3).
    template <class Body>
    void blocks(std::size_t n, Body body) const {
        each(n / 3, [=] __device__(std::size_t v) { body(3 * v, 3 * v + 3); });
    }
    template <class Term>
    double sum(std::size_t n, Term term) const {
        if (n == 0) return 0;
        double* out = sum_then(n, term, [] __device__(double) {});
        double s = 0;
        check(cudaMemcpy(&s, out, sizeof(double), cudaMemcpyDeviceToHost), "cudaMemcpy (sum)");
        return s;
    }
    // sum's total (the same bits), left on the device in the slot returned
    // (until the next reduction) and handed to finish(total) there, on one
    // thread; nothing waits for it here.
    template <class Term, class Finish>
    double* sum_then(std::size_t n, Term term, Finish finish) const {
        const int blocks = n == 0 ? 1 : sum_blocks(n);
        double* partial = static_cast<double*>(scratch->get((blocks + 1) * sizeof(double)));
        sum_kernel<<<blocks, kThreads>>>(n, term, partial, scratch->done.data(), finish);
        check_launch("sum_kernel");
        return partial + blocks;
    }
    static int sum_blocks(std::size_t n) {
        const std::size_t per_block = std::size_t(kThreads) * 4;
        return int((n + per_block - 1) / per_block < kSumBlocks ? (n + per_block - 1) / per_block : kSumBlocks);
    }
    template <class Term>
    EDGEFEM_HOST_DEVICE static double range_sum(std::size_t lo, std::size_t hi, Term&& term) {
        double s = 0;
        for (std::size_t i = lo; i < hi; ++i) s += term(i);
        return s;
    }
    template <class R, class Block, class Combine>
    R reduce(std::size_t n, R acc, Block block, Combine combine) const {
        if (n == 0) return acc;
        std::size_t count = (n + kReduceChunk - 1) / kReduceChunk;
        // Two buffers: the chunks' results, then each level's.
        const std::size_t half = (count * sizeof(R) + 255) / 256 * 256;
        unsigned char* base = static_cast<unsigned char*>(scratch->get(2 * half));
        R* a = reinterpret_cast<R*>(base);
        R* b = reinterpret_cast<R*>(base + half);
        reduce_chunks_kernel<<<unsigned((count + kThreads - 1) / kThreads), kThreads>>>(n, count, block, a);
        check_launch("reduce_chunks_kernel");
        while (count > 1) {
            const std::size_t groups = (count + kCombineGroup - 1) / kCombineGroup;
            combine_kernel<<<unsigned((groups + kThreads - 1) / kThreads), kThreads>>>(count, a, b, combine);
            check_launch("combine_kernel");
            std::swap(a, b);
            count = groups;
        }
        R total;
        check(cudaMemcpy(&total, a, sizeof(R), cudaMemcpyDeviceToHost), "cudaMemcpy (reduce)");
        combine(acc, total);
        return acc;
    }
};

}  // namespace edgefem::cuda
