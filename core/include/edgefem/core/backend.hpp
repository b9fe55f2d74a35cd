// Where a Simulator runs: a back-end builds the elastic operator, owns the
// memory its vectors live in and runs the vector kernels
// (vector_kernels.hpp) on them. Core provides two: the reference back-end
// (plain serial loops in index order, the oracle of the tests) and the CPU
// back-end's vector kernels (fixed blocks on an Executor: serial, or
// parallel/'s OpenMP, TBB and pool executors; bitwise the same for any
// thread count) with an operator factory (parallel/'s tuned CPU operators,
// or the reference operator).
#pragma once

#include <functional>
#include <memory>

#include "edgefem/core/backend_vector.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/executor.hpp"
#include "edgefem/core/vector_kernels.hpp"

namespace edgefem {

// Builds the elastic model a simulator uses: a back-end's operator
// (cpu_operator_factory in edgefem/parallel/cpu_backend.hpp for the CPU
// back-end's). The default is the reference back-end's
// (make_reference_operator: plain serial loops).
template <class S>
using OperatorFactory =
    std::function<std::unique_ptr<ElasticOperator<S>>(const Mesh&, const Materials&, ModelKind, Method)>;

template <class S>
class Backend {
public:
    virtual ~Backend() = default;
    virtual const char* name() const = 0;
    virtual int threads() const = 0;
    // An operator whose vectors (u, f, K x) are in memory().
    virtual std::unique_ptr<ElasticOperator<S>> make_operator(const Mesh& mesh, const Materials& materials,
                                                              ModelKind model, Method method) const = 0;
    virtual const VectorKernels<S>& kernels() const = 0;
    virtual const VectorMemory& memory() const = 0;
    // The host threads its kernels run on, for host-side solvers that can
    // use them (the AMG preconditioner); null: none to share (serial).
    virtual std::shared_ptr<const Executor> executor() const { return nullptr; }
    // n zeros in memory().
    template <class T>
    BackendVector<T> vector(std::size_t n) const {
        return BackendVector<T>(memory(), n);
    }
};

// Plain serial loops in index order, for the vectors and the operator
// (make_reference_operator): slow, simple, the reference results.
template <class S>
std::shared_ptr<const Backend<S>> make_reference_backend();

// Vector kernels in fixed blocks on `executor` (serial when null), the
// results the same for any thread count; operators from `factory` (the
// reference operator when empty; cpu_operator_factory in
// edgefem/parallel/cpu_backend.hpp for the tuned ones). What
// Simulator(scene) runs on.
template <class S>
std::shared_ptr<const Backend<S>> make_cpu_backend(std::shared_ptr<const Executor> executor = nullptr,
                                                          OperatorFactory<S> factory = {});

}  // namespace edgefem
