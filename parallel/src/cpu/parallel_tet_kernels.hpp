// The per-tet kernels of core (tet_kernels.hpp) run on an Executor, batch
// by batch (BatchedTetModel::batches, as the serial loops): the stiffness is
// per batch (no conflicts); forces and K x scatter to the up to 16 vertices
// of each batch's tets, coloured (batches of one colour share no vertex) or
// into private accumulators. The per-tet method has no gather or atomic
// workers in core: those variants run coloured (variant() says which runs).
#pragma once

#include <memory>
#include <type_traits>
#include <vector>

#include "edgefem/core/executor.hpp"
#include "cpu/tet_kernels.hpp"
#include "cpu/colouring.hpp"
#include "cpu/loops.hpp"
#include "cpu/variant.hpp"

namespace edgefem {

template <class S>
class ParallelTetKernels {
    static_assert(std::is_floating_point_v<S>, "the batches exist for built-in scalars only");

public:
    ParallelTetKernels(BatchedTetModel<S> model, std::shared_ptr<const Executor> executor, Variant variant,
                       const PlanOptions& opts = {})
        : m_(std::move(model)),
          ex_(executor ? std::move(executor) : std::make_shared<SerialExecutor>()),
          variant_(variant == Variant::Private ? Variant::Private : Variant::Colour),
          range_chunk_(std::max<index_t>(1, opts.range_chunk)),
          parts_(std::max(1, ex_->threads())) {
        if (variant_ == Variant::Colour) {
            col_ = colour_tet_batches(m_, opts.tet_colouring);
            partial_.resize(col_.num_chunks());
        }
    }

    const BatchedTetModel<S>& model() const { return m_; }
    Variant variant() const { return variant_; }
    const Colouring& colouring() const { return col_; }

    // As tet_forces (energy summed per chunk, chunks in a fixed order).
    template <bool Energy>
    double forces(const S* u, S* f) const {
        const std::size_t nf = 3 * std::size_t(m_.num_vertices);
        const auto& m = m_;
        if (variant_ == Variant::Colour) {
            par::for_range(*ex_, index_t(nf), par::range_chunk(index_t(nf), range_chunk_), [&](index_t b, index_t e) { std::fill(f + b, f + e, S(0)); });
            std::fill(partial_.begin(), partial_.end(), 0.0);
            par::for_colours(*ex_, col_, [&](index_t b, index_t chunk) {
                const auto w = kernel::batch_force<Energy>(m.batches[b], u, f);
                if constexpr (Energy)
                    for (int l = 0; l < kTetBatchLanes; ++l) partial_[chunk] += double(w[l]);
            });
            double W = 0;
            if constexpr (Energy)
                for (double x : partial_) W += x;
            return W;
        }
        if (pf_.size() != nf * parts_) pf_.assign(nf * parts_, S(0));
        std::vector<double> part_energy(parts_, 0.0);
        ex_->for_chunks(parts_, [&](index_t p) {
            S* fp = &pf_[std::size_t(p) * nf];
            double W = 0;
            for (index_t b = par::part_begin(m.num_batches(), parts_, p); b < par::part_begin(m.num_batches(), parts_, p + 1); ++b) {
                const auto w = kernel::batch_force<Energy>(m.batches[b], u, fp);
                if constexpr (Energy)
                    for (int l = 0; l < kTetBatchLanes; ++l) W += double(w[l]);
            }
            part_energy[p] = W;
        });
        reduce(pf_, nf, f);
        double W = 0;
        for (double x : part_energy) W += x;
        return W;
    }

    // As tet_stiffness_all (chunks of about range_chunk / 8 tets).
    void stiffness(const S* u, TetStiffness<S>& K) const {
        K.K.resize(90 * std::size_t(m_.num_tets()));
        const auto& m = m_;
        const index_t nb = m.num_batches();
        par::for_range(*ex_, nb, par::range_chunk(nb, range_chunk_ / (8 * kTetBatchLanes) + 1), [&](index_t b, index_t e) {
            for (index_t q = b; q < e; ++q) kernel::batch_stiffness(m, q, u, K.K.data());
        });
    }

    // As tet_multiply (per tet, over each batch's tets).
    void multiply(const TetStiffness<S>& K, const S* x, S* y) const {
        scatter(3, y, [&](index_t t, S* out) { kernel::tet_kx(m_, t, &K.K[90 * std::size_t(t)], x, out); });
    }

    // The 3x3 diagonal blocks of K (9 #V): the sum of the tets' (a, a) blocks.
    void diagonal_blocks(const TetStiffness<S>& K, S* D) const {
        scatter(9, D, [&](index_t t, S* out) {
            for (int a = 0; a < 4; ++a) {
                const S* blk = &K.K[90 * std::size_t(t) + 9 * tet_block_index(a, a)];
                S* d = &out[9 * std::size_t(m_.tet[t][a])];
                for (int i = 0; i < 9; ++i) d[i] += blk[i];
            }
        });
    }

private:
    // out = sum over tets of body(t, out) with `per` values per vertex, batch
    // by batch (the colouring's items), each batch's tets in lane order.
    template <class Body>
    void scatter(int per, S* out, Body&& body) const {
        const std::size_t n = per * std::size_t(m_.num_vertices);
        auto batch = [&](index_t b, S* o) {
            for (int l = 0; l < kTetBatchLanes; ++l)
                if (const index_t t = m_.batch_tet(b, l); t < m_.num_tets()) body(t, o);
        };
        if (variant_ == Variant::Colour) {
            par::for_range(*ex_, index_t(n), par::range_chunk(index_t(n), range_chunk_), [&](index_t b, index_t e) { std::fill(out + b, out + e, S(0)); });
            par::for_colours(*ex_, col_, [&](index_t b, index_t) { batch(b, out); });
            return;
        }
        std::vector<S>& buf = per == 3 ? pf_ : pd_;
        if (buf.size() != n * parts_) buf.assign(n * parts_, S(0));
        ex_->for_chunks(parts_, [&](index_t p) {
            S* op = &buf[std::size_t(p) * n];
            for (index_t b = par::part_begin(m_.num_batches(), parts_, p); b < par::part_begin(m_.num_batches(), parts_, p + 1); ++b)
                batch(b, op);
        });
        reduce(buf, n, out);
    }
    void reduce(std::vector<S>& buf, std::size_t n, S* out) const {
        par::for_range(*ex_, index_t(n), par::range_chunk(index_t(n), range_chunk_), [&](index_t b, index_t e) {
            for (index_t i = b; i < e; ++i) {
                S s = 0;
                for (int p = 0; p < parts_; ++p) {
                    s += buf[std::size_t(p) * n + i];
                    buf[std::size_t(p) * n + i] = S(0);
                }
                out[i] = s;
            }
        });
    }

    BatchedTetModel<S> m_;
    std::shared_ptr<const Executor> ex_;
    Variant variant_;
    index_t range_chunk_;
    int parts_;
    Colouring col_;
    mutable std::vector<double> partial_;
    mutable std::vector<S> pf_, pd_;
};

}  // namespace edgefem
