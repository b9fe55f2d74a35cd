// The edge-based kernels of core (edge_kernels.hpp) run on an Executor.
// Every formula is core's: the coloured and private variants run the plain
// workers (kernel::edge_strain, tsep_strain_segment, edge_stiffness,
// tsep_stiffness_segment; the coloured edge scatter runs the vertex-segment
// workers edge_force_segment, edge_kx_segment and edge_diagonal over
// coloured blocks of vertices, the private one edge_force, edge_kx; the
// owner variant runs the segment workers over fixed parts, forward targets
// past a part going to its spill window, see forward_spill.hpp), the
// gather and atomic variants the worker variants of
// core/edge_kernel_variants.hpp. This class only decides which items run
// where, and owns the per-mesh plan (colourings, gather lists, private
// buffers). One object must not run two kernels at the same time.
//
// Given a tet-local form (tet_edge_form.hpp), the FE stiffness adds its pair
// terms from it instead of the TSEP list: in the owner variant over owner
// parts of the form's batches with K windows past each part's edges (and
// its FE forces take g from the form the same way, owner_form_forces); in
// the others as a coloured scatter over batches (no two batches of a colour
// write the same K(E)). Either way the result is independent of the thread
// count.
#pragma once

#include <atomic>
#include <memory>
#include <vector>

#include "cpu/edge_kernel_variants.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/executor.hpp"
#include "cpu/tet_edge_form.hpp"
#include "cpu/colouring.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/forward_spill.hpp"
#include "cpu/loops.hpp"
#include "cpu/variant.hpp"

namespace edgefem {

template <class S>
class ParallelEdgeKernels {
public:
    ParallelEdgeKernels(EdgeModel<S> model, std::shared_ptr<const Executor> executor, Variant variant,
                        const PlanOptions& opts = {}, TetEdgeForm<S> form = {});

    const EdgeModel<S>& model() const { return m_; }
    const Executor& executor() const { return *ex_; }
    // The variant that runs: Auto is resolved when the plan is built.
    Variant variant() const { return variant_; }

    // K blocks: #E, then the sink block(s) (one per chunk of the coloured
    // stiffness pass, one otherwise). Use resize() to size an EdgeStiffness.
    index_t stiffness_blocks() const { return m_.num_edges() + num_sinks_; }
    void resize(EdgeStiffness<S>& K) const { K.K.assign(9 * std::size_t(stiffness_blocks()), S(0)); }

    // As edge_forces: f = dW/du (overwritten), W when Energy, state in st.
    template <ModelKind Kind, bool Energy>
    double forces(const S* u, S* f, EdgeState<S>& st) const;
    // As edge_stiffness_all (K must have stiffness_blocks() blocks).
    template <ModelKind Kind, bool Definite = false>
    void stiffness(const EdgeState<S>& st, EdgeStiffness<S>& K) const;
    // As edge_multiply / edge_diagonal_blocks.
    void multiply(const EdgeStiffness<S>& K, const S* x, S* y) const;
    void diagonal_blocks(const EdgeStiffness<S>& K, S* D) const;

    // Colour variant only (empty otherwise).
    // The edge scatter's colouring: units of vertices, each running its
    // segment (the edges whose V0 it is).
    const Colouring& vertex_colouring() const { return vert_col_; }
    const Colouring& tsep_colouring() const { return tsep_col_; }
    const Colouring& stiffness_colouring() const { return stiff_col_; }
    // Owner variant only: the parts of the edge scatter (vertices) and of
    // the TSEP loop (edges), with their spill windows.
    const ForwardSpill& vertex_parts() const { return vspill_; }
    const ForwardSpill& edge_parts() const { return espill_; }
    // Owner variant with the tet-local form: batch offsets of its parts.
    const std::vector<index_t>& form_batch_parts() const { return form_batch_first_; }
    // Edges of the owner FE force that receive g terms from earlier parts:
    // scattered with a correction after the barrier.
    index_t corrected_edges() const { return index_t(corr_edges_.size()); }
    // Tet-local stiffness only: the colouring of the form's batches.
    const Colouring& form_colouring() const { return form_col_; }
    bool tet_local_stiffness() const { return form_.num_tets > 0; }
    // Owner variant: FE forces with g from the tet-local form
    // (PlanOptions::form_forces).
    bool form_forces() const { return form_forces_ && tet_local_stiffness() && variant_ == Variant::Owner; }
    // Bytes of the plan (colour lists, gather lists; private buffers once allocated).
    std::size_t plan_bytes() const;

private:
    template <class Body>
    void each_range(index_t n, Body&& body) const {
        par::for_range(*ex_, n, par::range_chunk(n, range_chunk_), body);
    }
    // Private variant: body(part, begin, end) over `parts` contiguous pieces of [0, n).
    template <class Body>
    void each_part(index_t n, Body&& body) const {
        ex_->for_chunks(parts_, [&](index_t p) {
            body(int(p), par::part_begin(n, parts_, int(p)), par::part_begin(n, parts_, int(p) + 1));
        });
    }
    // out[i] (+)= sum over parts of buf[part * stride + i] for i < len, in
    // part order; the buffers are re-zeroed for the next call.
    template <class T, class U>
    void reduce_parts(std::vector<U>& buf, std::size_t len, std::size_t stride, T* out, bool accumulate) const;
    template <class T>
    std::vector<T>& private_buffer(std::vector<T>& buf, std::size_t len) const {
        if (buf.size() != len * std::size_t(parts_)) buf.assign(len * std::size_t(parts_), T(0));
        return buf;
    }
    // The edge-to-vertex scatter of the force and of K x (3 values per
    // vertex; `out` is overwritten), by the variant's strategy, from the
    // per-edge workers: segment(a, out[, fwd]) for the edges whose V0 is a,
    // gather(v, incident edges, count, out) for vertex v, edge_to(i, add)
    // adding through add(k, value), and edge(i, out).
    template <class Middle>
    void owner_force_phases(const S* u, S* f, EdgeState<S>& st, Middle&& middle) const;
    void owner_fused_forces(const S* u, S* f, EdgeState<S>& st) const;
    void owner_form_forces(const S* u, S* f, EdgeState<S>& st) const;
    void build_owner_form_parts();
    void build_owner_form_tiles(index_t batches_per_tile);
    template <class Segment, class Gather, class EdgeTo, class Edge>
    void scatter_to_vertices(S* out, const Segment& segment, const Gather& gather, const EdgeTo& edge_to,
                             const Edge& edge) const;
    // Incoming stiffness contributions per edge (the one-pass TSEP-list
    // stiffness of the gather and owner variants).
    void build_stiffness_sources();
    // The owner variant's vertex-segment parts (balanced on edges).
    static ForwardSpill vertex_spill(const EdgeModel<S>& m, index_t parts) {
        return make_forward_spill(m.num_vertices, balanced_parts(m.edge_first, parts), [&m](index_t a) {
            index_t t = a;
            for (index_t e = m.edge_first[a]; e < m.edge_first[a + 1]; ++e) t = std::max(t, m.edge[e][1]);
            return t;
        });
    }

    EdgeModel<S> m_;
    std::shared_ptr<const Executor> ex_;
    Variant variant_;
    index_t range_chunk_;
    int parts_ = 1;          // private accumulators
    index_t num_sinks_ = 1;  // sink blocks after the #E edge blocks
    Colouring vert_col_, tsep_col_, stiff_col_;
    TetEdgeForm<S> form_;  // empty: TSEP-list stiffness
    bool form_forces_ = true;
    Colouring form_col_;
    // Gather lists: vertex -> incident edges (side-encoded), edge -> incoming
    // TSEPs (E0, L(P)), edge -> incoming stiffness contributions.
    std::vector<index_t> inc_first_, inc_;
    std::vector<index_t> tin_first_, tin_e0_;
    std::vector<S> tin_L_;
    std::vector<index_t> kin_first_;
    std::vector<kernel::StiffnessSource> kin_;
    // Owner variant: parts and spill windows (values per target: 3 for
    // forces and K x, 9 for diagonal blocks, 1 for g), kept zeroed.
    ForwardSpill vspill_, espill_;
    // What each phase of the owner kernels waits for (run_linked): the
    // edge and vertex scatters (forward_spill.hpp), K x (pad, segments,
    // incoming), the forces from the TSEP list (strains, fused loop,
    // corrections, incoming f) and from the form (as owner_form_forces),
    // and the stiffness from the form (batches, incoming).
    PhaseLinks vertex_links_, kx_links_, fused_links_, form_force_links_, form_stiffness_links_;
    // owner_fused_forces: per part, the edges whose g gets terms from
    // earlier parts' windows (offsets into a list).
    std::vector<index_t> corr_first_, corr_edges_;
    mutable std::vector<S> spill_v_, spill_d_;
    mutable std::vector<S> spill_v4_;  // owner K x on padded vectors: 4 per spill target
    // Owner variant: per vertex part, the first vertex whose segment reaches
    // past the part (the part's end when none). The segments before it run
    // the direct-only kernels: with the spill split in them (a run-time part
    // end) the loops run slower (K x on armadillo-7k: 46.1 against 44.3 us at
    // 1 thread, on xyz strides).
    std::vector<index_t> spill_vertex_first_;
    mutable std::vector<double> spill_g_;
    // Owner variant with the tet-local form: the form's batches of each part
    // (those whose first tet's lowest vertex is in the part's vertices:
    // every edge they write is at or past the part's first edge) and the
    // windows past its edges, for g (owner_form_forces) and K.
    std::vector<index_t> form_batch_first_;
    // Per part, the first of its batches that writes past the part's edges:
    // the batches before it run the plain kernels (no window test per
    // update).
    std::vector<index_t> form_spill_first_;
    ForwardSpill fspill_;
    // Owner variant with the form, per part: the end of its head (its edges
    // that earlier parts' batches read, strained before the others and
    // final only once the windows are in), the end of the vertices whose
    // segments hold head edges (scattered last), and its tiles
    // (owner_tiles_[tile_first_[q] .. tile_first_[q + 1]), FormTile).
    std::vector<index_t> head_end_, defer_end_, tile_first_;
    std::vector<FormTile> owner_tiles_;
    index_t form_tile_batches_ = kFormTileBatches;
    mutable std::vector<double> spill_fg_;
    mutable std::vector<S> spill_fk_;  // owner stiffness from the form: K windows
    // Private accumulators (allocated on first use).
    mutable std::vector<S> pv_, pd_, pk_;
    mutable std::vector<double> pg_;
};

// ---- Implementation -----------------------------------------------------------

namespace par {
template <class T>
inline void atomic_add(T* base, std::size_t i, T v) {
    std::atomic_ref<T>(base[i]).fetch_add(v, std::memory_order_relaxed);
}
}  // namespace par

template <class S>
ParallelEdgeKernels<S>::ParallelEdgeKernels(EdgeModel<S> model, std::shared_ptr<const Executor> executor,
                                            Variant variant, const PlanOptions& opts, TetEdgeForm<S> form)
    : m_(std::move(model)),
      ex_(executor ? std::move(executor) : std::make_shared<SerialExecutor>()),
      variant_(variant),
      range_chunk_(std::max<index_t>(1, opts.range_chunk)),
      parts_(std::max(1, ex_->threads())),
      form_(std::move(form)),
      form_forces_(opts.form_forces),
      form_tile_batches_(opts.form_tile_batches > 0 ? opts.form_tile_batches : kFormTileBatches) {
    const index_t ne = m_.num_edges(), nv = m_.num_vertices;
    const index_t owner_parts = opts.owner_parts > 0 ? opts.owner_parts : default_owner_parts(nv, hardware_threads());
    if (variant_ == Variant::Auto) {
        // Owner wins every kernel at 1 and 2 threads when the numbering has
        // locality (docs/parallel.md); without it (TetGen's input order on
        // large meshes) its spill windows outgrow the work and gather, which
        // does not depend on the numbering, is the safe choice. The test is
        // a function of the mesh only, so results stay thread-count free.
        vspill_ = vertex_spill(m_, owner_parts);  // kept when owner is chosen
        variant_ = vspill_.spill_targets() <= std::size_t(nv) ? Variant::Owner : Variant::Gather;
        if (variant_ == Variant::Gather) vspill_ = {};
    }
    if (form_.num_tets > 0) {
        if (form_.num_edges != ne) throw InvalidArgument("tet-local form and edge model belong to different meshes");
        m_.target = {};  // the TSEP-list stiffness plan is not needed
        const auto& f = form_;
        form_col_ = colour_items(f.num_batches(), ne, [&f](index_t b, std::vector<index_t>& out) {
            for (int k = 0; k < 6; ++k)
                for (int l = 0; l < f.batch_size(b); ++l) out.push_back(f.edge[(std::size_t(b) * 6 + k) * kTetLanes<S> + l]);
        }, opts.form_colouring);
    }
    switch (variant_) {
        case Variant::Auto:  // resolved to a concrete variant by the constructor
            break;
        case Variant::Colour: {
            vert_col_ = colour_vertex_segments(m_, resolved_vertex_colouring(opts.vertex_colouring, nv));
            tsep_col_ = colour_tsep_strain(m_, opts.segment_colouring);
            if (opts.stiffness && !m_.target.empty()) {
                stiff_col_ = colour_tsep_stiffness(m_, opts.segment_colouring);
                // Each chunk of the stiffness pass gets its own sink block, so
                // concurrent chunks never write the same scratch.
                num_sinks_ = std::max<index_t>(1, stiff_col_.num_chunks());
                const index_t sink = ne << 1;
                for (int c = 0; c < stiff_col_.colours(); ++c)
                    for (index_t x = stiff_col_.colour_first[c]; x < stiff_col_.colour_first[c + 1]; ++x) {
                        const index_t k = (x - stiff_col_.colour_first[c]) / stiff_col_.chunk_units[c];
                        const index_t chunk = stiff_col_.chunk_first[c] + k;
                        const index_t u = stiff_col_.units[x];
                        for (index_t e0 = stiff_col_.unit_begin(u); e0 < stiff_col_.unit_end(u); ++e0)
                            for (index_t P = m_.tsep_first[e0]; P < m_.tsep_first[e0 + 1]; ++P)
                                for (auto& t : m_.target[P])
                                    if (t == sink) t = (ne + chunk) << 1;
                    }
            }
            break;
        }
        case Variant::Gather: {
            inc_first_.assign(std::size_t(nv) + 1, 0);
            for (const auto& e : m_.edge) {
                ++inc_first_[e[0] + 1];
                ++inc_first_[e[1] + 1];
            }
            for (index_t v = 0; v < nv; ++v) inc_first_[v + 1] += inc_first_[v];
            inc_.resize(inc_first_.back());
            std::vector<index_t> pos(inc_first_.begin(), inc_first_.end() - 1);
            for (index_t e = 0; e < ne; ++e) {  // ascending edges per vertex
                inc_[pos[m_.edge[e][0]]++] = e << 1;
                inc_[pos[m_.edge[e][1]]++] = (e << 1) | 1;
            }
            const index_t np = m_.num_tseps();
            tin_first_.assign(std::size_t(ne) + 1, 0);
            for (index_t P = 0; P < np; ++P) ++tin_first_[m_.tsep_other[P] + 1];
            for (index_t e = 0; e < ne; ++e) tin_first_[e + 1] += tin_first_[e];
            tin_e0_.resize(np);
            tin_L_.resize(np);
            pos.assign(tin_first_.begin(), tin_first_.end() - 1);
            for (index_t e0 = 0; e0 < ne; ++e0)  // ascending TSEPs per edge
                for (index_t P = m_.tsep_first[e0]; P < m_.tsep_first[e0 + 1]; ++P) {
                    const index_t at = pos[m_.tsep_other[P]]++;
                    tin_e0_[at] = e0;
                    tin_L_[at] = m_.LP[P];
                }
            if (opts.stiffness && !m_.target.empty()) build_stiffness_sources();
            break;
        }
        case Variant::Owner: {
            const auto& m = m_;
            if (vspill_.parts() == 0) vspill_ = vertex_spill(m, owner_parts);  // Auto has built it already
            // The TSEP loop's parts are the vertex parts' edge segments, so
            // that it fuses with the edge scatter (owner_fused_forces).
            std::vector<index_t> edge_first(vspill_.part_first.size());
            for (std::size_t q = 0; q < edge_first.size(); ++q) edge_first[q] = m.edge_first[vspill_.part_first[q]];
            espill_ = make_forward_spill(ne, edge_first, [&m](index_t e0) {
                index_t t = e0;
                for (index_t P = m.tsep_first[e0]; P < m.tsep_first[e0 + 1]; ++P) t = std::max(t, m.tsep_other[P]);
                return t;
            });
            // The edges that receive g terms from an earlier part (through a
            // spill window, so only after the barrier), per part.
            std::vector<unsigned char> spilled(std::size_t(ne), 0);
            for (index_t q = 0; q < espill_.parts(); ++q)
                for (index_t e0 = espill_.part_first[q]; e0 < espill_.part_first[q + 1]; ++e0)
                    for (index_t P = m.tsep_first[e0]; P < m.tsep_first[e0 + 1]; ++P)
                        if (m.tsep_other[P] >= espill_.part_first[q + 1]) spilled[m.tsep_other[P]] = 1;
            corr_first_.assign(std::size_t(espill_.parts()) + 1, 0);
            corr_edges_.clear();
            for (index_t q = 0; q < espill_.parts(); ++q) {
                for (index_t e = espill_.part_first[q]; e < espill_.part_first[q + 1]; ++e)
                    if (spilled[e]) corr_edges_.push_back(e);
                corr_first_[q + 1] = index_t(corr_edges_.size());
            }
            spill_v_.assign(3 * vspill_.spill_targets(), S(0));
            if constexpr (std::is_floating_point_v<S>) spill_v4_.assign(4 * vspill_.spill_targets(), S(0));
            spill_d_.assign(9 * vspill_.spill_targets(), S(0));
            spill_vertex_first_.assign(std::size_t(vspill_.parts()), 0);
            for (index_t q = 0; q < vspill_.parts(); ++q) {
                const index_t b = vspill_.part_first[q], e = vspill_.part_first[q + 1];
                index_t c = b;
                while (c < e && (m.edge_first[c] == m.edge_first[c + 1] || m.edge[m.edge_first[c + 1] - 1][1] < e)) ++c;
                spill_vertex_first_[q] = c;
            }
            spill_g_.assign(espill_.spill_targets(), 0.0);
            vertex_links_ = linked(vspill_, link_incoming_adds);
            kx_links_ = linked(vspill_, link_window_reads, link_incoming_adds);
            fused_links_ = linked(espill_, link_window_reads, link_incoming_adds);
            link_incoming_adds(fused_links_, vspill_);
            if (tet_local_stiffness()) build_owner_form_parts();
            if (opts.stiffness && !m_.target.empty()) build_stiffness_sources();
            break;
        }
        default: break;
    }
}

template <class S>
void ParallelEdgeKernels<S>::build_stiffness_sources() {
    const index_t ne = m_.num_edges(), np = m_.num_tseps();
    kin_first_.assign(std::size_t(ne) + 1, 0);
    for (index_t P = 0; P < np; ++P)
        for (int k = 0; k < 4; ++k)
            if ((m_.target[P][k] >> 1) < ne) ++kin_first_[(m_.target[P][k] >> 1) + 1];
    for (index_t e = 0; e < ne; ++e) kin_first_[e + 1] += kin_first_[e];
    kin_.resize(kin_first_.back());
    std::vector<index_t> pos(kin_first_.begin(), kin_first_.end() - 1);
    for (index_t e0 = 0; e0 < ne; ++e0)  // ascending (P, k) per target
        for (index_t P = m_.tsep_first[e0]; P < m_.tsep_first[e0 + 1]; ++P)
            for (int k = 0; k < 4; ++k) {
                const index_t t = m_.target[P][k];
                if ((t >> 1) >= ne) continue;
                kin_[pos[t >> 1]++] = {P, e0, std::uint8_t(k | ((t & 1) << 2))};
            }
}

template <class S>
std::size_t ParallelEdgeKernels<S>::plan_bytes() const {
    auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
    std::size_t b = 0;
    for (const Colouring* c : {&vert_col_, &tsep_col_, &stiff_col_, &form_col_})
        b += bytes(c->units) + bytes(c->colour_first) + bytes(c->chunk_first) + bytes(c->chunk_units);
    b += bytes(inc_first_) + bytes(inc_) + bytes(tin_first_) + bytes(tin_e0_) + bytes(tin_L_) + bytes(kin_first_) +
         bytes(kin_);
    b += bytes(pv_) + bytes(pd_) + bytes(pk_) + bytes(pg_);
    for (const ForwardSpill* fs : {&vspill_, &espill_, &fspill_})
        b += bytes(fs->part_first) + bytes(fs->window_end) + bytes(fs->window_first) + bytes(fs->in_first) +
             bytes(fs->in_part);
    b += bytes(spill_v_) + bytes(spill_v4_) + bytes(spill_d_) + bytes(spill_g_) + bytes(corr_first_) + bytes(corr_edges_) +
         bytes(form_batch_first_) + bytes(form_spill_first_) + bytes(spill_fg_) + bytes(spill_fk_);
    return b;
}

template <class S>
template <class T, class U>
void ParallelEdgeKernels<S>::reduce_parts(std::vector<U>& buf, std::size_t len, std::size_t stride, T* out,
                                          bool accumulate) const {
    par::for_range(*ex_, index_t(len), par::range_chunk(index_t(len), range_chunk_), [&](index_t b, index_t e) {
        for (index_t i = b; i < e; ++i) {
            U s = accumulate ? U(out[i]) : U(0);
            for (int p = 0; p < parts_; ++p) {
                U& x = buf[std::size_t(p) * stride + i];
                s += x;
                x = U(0);
            }
            out[i] = T(s);
        }
    });
}

template <class S>
template <ModelKind Kind, bool Energy>
double ParallelEdgeKernels<S>::forces(const S* u, S* f, EdgeState<S>& st) const {
    const index_t ne = m_.num_edges();
    st.resize(ne);
    S* p = st.p.data();
    S* zeta = st.zeta.data();
    double* g = st.g.data();
    const auto& m = m_;
    if constexpr (Kind == ModelKind::FE)
        if (variant_ == Variant::Owner) {
            if (form_forces())
                owner_form_forces(u, f, st);
            else
                owner_fused_forces(u, f, st);
            if constexpr (Energy)
                return physics::energy_from_terms(
                blocked_sum(*ex_, std::size_t(ne), [&](std::size_t i) { return physics::energy_term(double(zeta[i]), g[i]); }));
            return 0;
        }
    each_range(ne, [&](index_t b, index_t e) {
        kernel::edge_strain_range(m, u, b, e, p, zeta, g);
    });
    if constexpr (Kind == ModelKind::FE) {
        switch (variant_) {
            case Variant::Auto:  // resolved to a concrete variant by the constructor
                break;
            case Variant::Colour:
                par::for_colours(*ex_, tsep_col_, [&](index_t e0, index_t) { kernel::tsep_strain_segment(m, e0, zeta, g); });
                break;
            case Variant::Gather:
                each_range(ne, [&](index_t b, index_t e) {
                    for (index_t i = b; i < e; ++i)
                        kernel::tsep_strain_gather(m, i, &tin_e0_[tin_first_[i]], &tin_L_[tin_first_[i]],
                                                   tin_first_[i + 1] - tin_first_[i], zeta, g);
                });
                break;
            case Variant::Atomic:
                each_range(ne, [&](index_t b, index_t e) {
                    for (index_t i = b; i < e; ++i)
                        kernel::tsep_strain_segment_to(m, i, zeta, [g](std::size_t k, double v) { par::atomic_add(g, k, v); });
                });
                break;
            case Variant::Owner:  // owner_fused_forces
                break;
            case Variant::Private: {
                auto& buf = private_buffer(pg_, ne);
                each_part(ne, [&](int part, index_t b, index_t e) {
                    double* gp = &buf[std::size_t(part) * ne];
                    for (index_t i = b; i < e; ++i) kernel::tsep_strain_segment(m, i, zeta, gp);
                });
                reduce_parts(buf, ne, ne, g, true);
                break;
            }
        }
    }
    scatter_to_vertices(
        f, [&](index_t a, S* o, const auto&... fwd) { kernel::edge_force_segment(m, a, p, g, o, fwd...); },
        [&](index_t v, const index_t* inc, index_t n, S* o) { kernel::vertex_force_gather(v, inc, n, p, g, o); },
        [&](index_t i, const auto& add) { kernel::edge_force_to(m, i, p, g, add); },
        [&](index_t i, S* o) { kernel::edge_force(m, i, p, g, o); });
    if constexpr (Energy)
        return physics::energy_from_terms(
                blocked_sum(*ex_, std::size_t(ne), [&](std::size_t i) { return physics::energy_term(double(zeta[i]), g[i]); }));
    return 0;
}

template <class S>
void ParallelEdgeKernels<S>::build_owner_form_parts() {
    const auto& m = m_;
    const auto& f = form_;
    constexpr int L = kTetLanes<S>;
    const index_t P = vspill_.parts(), nb = f.num_batches(), ne = m.num_edges();
    // Local edge 0 of a tet joins its two lowest vertices, V0 first.
    const auto low_vertex = [&](index_t b) { return m.edge[f.edge[std::size_t(b) * 6 * L]][0]; };
    form_batch_first_.assign(std::size_t(P) + 1, nb);
    form_batch_first_[0] = 0;
    index_t b = 0;
    for (index_t q = 1; q < P; ++q) {
        while (b < nb && low_vertex(b) < vspill_.part_first[q]) ++b;
        form_batch_first_[q] = b;
    }
    // Each part's batches reach up to their largest edge: that is the
    // window, anchored at the part's first edge.
    std::vector<index_t> reach(static_cast<std::size_t>(ne));
    for (index_t e = 0; e < ne; ++e) reach[e] = e;
    form_spill_first_.assign(std::size_t(P), 0);
    for (index_t q = 0; q < P; ++q) {
        const index_t anchor = espill_.part_first[q], end = espill_.part_first[q + 1];
        form_spill_first_[q] = form_batch_first_[q + 1];
        for (index_t bb = form_batch_first_[q]; bb < form_batch_first_[q + 1]; ++bb)
            for (int k = 0; k < 6; ++k)
                for (int l = 0; l < f.batch_size(bb); ++l) {
                    const index_t e = f.edge[(std::size_t(bb) * 6 + k) * L + l];
                    if (e < anchor) throw InvalidArgument("owner form parts: a batch writes an edge before its part");
                    reach[anchor] = std::max(reach[anchor], e);
                    if (e >= end) form_spill_first_[q] = std::min(form_spill_first_[q], bb);
                }
    }
    fspill_ = make_forward_spill(ne, espill_.part_first, [&reach](index_t e) { return reach[e]; });
    form_stiffness_links_ = linked(fspill_, link_incoming_adds);
    form_force_links_ = linked(fspill_, link_window_reads, link_incoming_adds);
    link_incoming_adds(form_force_links_, vspill_);
    if (form_forces()) spill_fg_.assign(fspill_.spill_targets(), 0.0);
    spill_fk_.assign(9 * fspill_.spill_targets(), S(0));
    build_owner_form_tiles(form_tile_batches_);
}

// Each part's head (its edges that earlier parts' batches read and write
// through their windows: up to the furthest window end before it), the
// vertices whose segments hold head edges, and the part's tiles
// (plan_form_tiles over the part's batches, from the end of its head;
// the part zeroes its f in phase 0, so the tiles' zero_end goes unused).
template <class S>
void ParallelEdgeKernels<S>::build_owner_form_tiles(index_t batches_per_tile) {
    const ForwardSpill &vs = vspill_, &fs = fspill_;
    const index_t P = vs.parts();
    head_end_.assign(std::size_t(P), 0);
    defer_end_.assign(std::size_t(P), 0);
    tile_first_.assign(std::size_t(P) + 1, 0);
    owner_tiles_.clear();
    index_t reach = 0;  // the furthest window end of the earlier parts
    for (index_t q = 0; q < P; ++q) {
        const index_t vb = vs.part_first[q], ve = vs.part_first[q + 1];
        const index_t eb = fs.part_first[q], ee = fs.part_first[q + 1];
        const index_t head = std::clamp(reach, eb, ee);
        head_end_[q] = head;
        defer_end_[q] = head > eb ? m_.edge[head - 1][0] + 1 : vb;
        const auto tiles = plan_form_tiles(form_, m_.edge, m_.edge_first, batches_per_tile,
                                           FormTileRange{form_batch_first_[q], form_batch_first_[q + 1], head, ee,
                                                         defer_end_[q], ve});
        owner_tiles_.insert(owner_tiles_.end(), tiles.begin(), tiles.end());
        tile_first_[q + 1] = index_t(owner_tiles_.size());
        reach = std::max(reach, fs.window_end[q]);
    }
}

// The owner variant's FE forces in one region of 4 phases over the parts
// (vertex parts and their edge segments): 0 strains of the part's edges, f
// zeroed; 1 and 2 `middle(phase, part, vertex range, edge end, fout)`,
// f written through fout (the part's f window past its vertices); 3 the
// incoming f windows added. Every sum has an order fixed by the parts alone:
// bitwise the same for any thread count.
template <class S>
template <class Middle>
void ParallelEdgeKernels<S>::owner_force_phases(const S* u, S* f, EdgeState<S>& st, Middle&& middle) const {
    const auto& m = m_;
    const ForwardSpill &vs = vspill_, &es = espill_;
    run_linked(*ex_, fused_links_, [&](int phase, index_t q) {
        const index_t vb = vs.part_first[q], ve = vs.part_first[q + 1];
        const index_t eb = es.part_first[q], ee = es.part_first[q + 1];
        if (phase == 0) {
            kernel::edge_strain_range(m, u, eb, ee, st.p.data(), st.zeta.data(), st.g.data());
            std::fill(f + 3 * std::size_t(vb), f + 3 * std::size_t(ve), S(0));
        } else if (phase == 3) {
            add_incoming_spills<3>(vs, q, f, spill_v_);
        } else {
            middle(phase, q, vb, ve, ee, kernel::ForwardOut<S>{f, spill_v_.data() + 3 * vs.window_first[q], ve});
        }
    });
}

// With the TSEP list: 1 the fused TSEP + edge scatter of the part's segments
// (kernel::tsep_force_segment), every edge with the g it has so far; 2 for
// the edges that earlier parts' TSEPs write, their window terms added to g
// and scattered (kernel::edge_force_add).
template <class S>
void ParallelEdgeKernels<S>::owner_fused_forces(const S* u, S* f, EdgeState<S>& st) const {
    const auto& m = m_;
    const ForwardSpill& es = espill_;
    const S* p = st.p.data();
    const S* zeta = st.zeta.data();
    double* g = st.g.data();
    owner_force_phases(u, f, st, [&](int phase, index_t q, index_t vb, index_t ve, index_t ee,
                                     const kernel::ForwardOut<S>& fout) {
        if (phase == 1) {
            const kernel::ForwardOut<double> gout{g, spill_g_.data() + es.window_first[q], ee};
            for (index_t a = vb; a < ve; ++a) kernel::tsep_force_segment(m, a, p, zeta, g, f, gout, fout);
        } else {
            // Only the listed edges have non-zero window entries.
            for (index_t k = corr_first_[q]; k < corr_first_[q + 1]; ++k) {
                const index_t e = corr_edges_[k];
                const double dg = take_incoming_spill(es, q, e, spill_g_);
                g[e] += dg;
                kernel::edge_force_add(m, e, p, dg, f, fout);
            }
        }
    });
}

// With the tet-local form (the parts also hold the form's batches whose
// lowest vertex is theirs): 1 the part's batches add their terms to g, past
// the part's edges into its window; 2 the incoming windows added to g (now
// final), then the edge scatter of the part's vertex segments.
template <class S>
void ParallelEdgeKernels<S>::owner_form_forces(const S* u, S* f, EdgeState<S>& st) const {
    const auto& m = m_;
    const ForwardSpill &vs = vspill_, &fs = fspill_;
    S* p = st.p.data();
    S* zeta = st.zeta.data();
    double* g = st.g.data();
    const bool far = form_.tiles.size() > 1;  // core's tiles: the mesh exceeds the cache
    run_linked(*ex_, form_force_links_, [&](int phase, index_t q) {
        const index_t vb = vs.part_first[q], ve = vs.part_first[q + 1];
        const index_t eb = fs.part_first[q], ee = fs.part_first[q + 1];
        const kernel::ForwardOut<S> fout{f, spill_v_.data() + 3 * vs.window_first[q], ve};
        // The edge scatter of segments [a0, a1): direct-only before the
        // part's first spilling segment (spill_vertex_first_).
        const auto scatter = [&](index_t a0, index_t a1) {
            const index_t c = std::clamp(spill_vertex_first_[q], a0, a1);
            for (index_t a = a0; a < c; ++a) kernel::edge_force_segment(m, a, p, g, f);
            for (index_t a = c; a < a1; ++a) kernel::edge_force_segment(m, a, p, g, f, fout);
        };
        if (phase == 0) {
            kernel::edge_strain_range(m, u, eb, head_end_[q], p, zeta, g);
            std::fill(f + 3 * std::size_t(vb), f + 3 * std::size_t(ve), S(0));
        } else if (phase == 1) {
            // Tile by tile: the rest of the part's strains, its batches,
            // and the scatter of the segments whose g is final.
            const kernel::ForwardOut<double> gout{g, spill_fg_.data() + fs.window_first[q], ee};
            FormTile prev{form_batch_first_[q], head_end_[q], defer_end_[q], 0};
            for (index_t i = tile_first_[q]; i < tile_first_[q + 1]; ++i) {
                const FormTile& t = owner_tiles_[i];
                kernel::edge_strain_range(m, u, prev.edge_end, t.edge_end, p, zeta, g);
                const index_t split = std::clamp(form_spill_first_[q], prev.batch_end, t.batch_end);
                // Rows and ids fetched ahead non-temporally on a mesh larger
                // than the cache (kernel::prefetch_form_batch).
                if (far) {
                    kernel::tet_form_strain_batches_prefetched(form_, prev.batch_end, split, zeta, g, EdgeSlot{});
                    kernel::tet_form_strain_batches_prefetched(form_, split, t.batch_end, zeta, gout);
                } else {
                    for (index_t b = prev.batch_end; b < split; ++b) kernel::tet_form_strain(form_, b, zeta, g);
                    for (index_t b = split; b < t.batch_end; ++b) kernel::tet_form_strain(form_, b, zeta, gout);
                }
                scatter(prev.vertex_end, t.vertex_end);
                prev = t;
            }
        } else if (phase == 2) {
            // The head: its incoming windows added, then its segments.
            add_incoming_spills<1>(fs, q, g, spill_fg_);
            scatter(vb, defer_end_[q]);
        } else {
            add_incoming_spills<3>(vs, q, f, spill_v_);
        }
    });
}

template <class S>
template <ModelKind Kind, bool Definite>
void ParallelEdgeKernels<S>::stiffness(const EdgeState<S>& st, EdgeStiffness<S>& Ks) const {
    const index_t ne = m_.num_edges();
    if (Ks.K.size() != 9 * std::size_t(stiffness_blocks())) resize(Ks);
    const S* p = st.p.data();
    const double* g = st.g.data();
    S* K = Ks.K.data();
    const auto& m = m_;
    if (Kind == ModelKind::FE && !tet_local_stiffness() &&
        (variant_ == Variant::Gather || variant_ == Variant::Owner)) {  // one pass: K(E) = edge term + its TSEP terms
        each_range(ne, [&](index_t b, index_t e) {
            for (index_t i = b; i < e; ++i) {
                kernel::edge_stiffness<Definite>(m, i, p, g, K);
                kernel::tsep_stiffness_gather(m, i, &kin_[kin_first_[i]], kin_first_[i + 1] - kin_first_[i], p, K);
            }
        });
        return;
    }
    if (Kind == ModelKind::FE && tet_local_stiffness() && variant_ == Variant::Owner) {
        // Owner parts of the form's batches (as owner_form_forces): 0 the
        // edge terms of the part's edges, then its batches' pair terms,
        // past its edges into its window (no other part writes the part's
        // own blocks in this phase, so no barrier between the two; a third
        // phase cost a barrier per build); 1 the incoming windows added.
        // Only the last part's last batch has padding lanes (they write the
        // sink).
        const ForwardSpill& fs = fspill_;
        const bool far = form_.tiles.size() > 1;
        run_linked(*ex_, form_stiffness_links_, [&](int phase, index_t q) {
            const index_t eb = fs.part_first[q], ee = fs.part_first[q + 1];
            if (phase == 0) {  // tile by tile (FormTile): the edge terms, then the batches
                const kernel::ForwardOut<S> kout{K, spill_fk_.data() + 9 * fs.window_first[q], ee};
                index_t e0 = eb, b0 = form_batch_first_[q];
                for (index_t t = tile_first_[q]; t < tile_first_[q + 1]; ++t) {
                    const index_t e1 = std::max(e0, owner_tiles_[t].edge_end), b1 = owner_tiles_[t].batch_end;
                    for (index_t i = e0; i < e1; ++i) kernel::edge_stiffness<Definite>(m, i, p, g, K);
                    const index_t split = std::clamp(form_spill_first_[q], b0, b1);
                    if (far) {
                        kernel::tet_form_stiffness_batches_prefetched(form_, b0, split, p, K);
                        kernel::tet_form_stiffness_batches_prefetched(form_, split, b1, p, kout);
                    } else {
                        for (index_t b = b0; b < split; ++b) kernel::tet_form_stiffness(form_, b, p, K);
                        for (index_t b = split; b < b1; ++b) kernel::tet_form_stiffness(form_, b, p, kout);
                    }
                    e0 = e1;
                    b0 = b1;
                }
            } else {
                add_incoming_spills<9>(fs, q, K, spill_fk_);
            }
        });
        return;
    }
    each_range(ne, [&](index_t b, index_t e) {
        for (index_t i = b; i < e; ++i) kernel::edge_stiffness<Definite>(m, i, p, g, K);
    });
    if constexpr (Kind == ModelKind::FE) {
        if (tet_local_stiffness()) {
            // Only the last batch has padding lanes, so one chunk writes the sink.
            par::for_colours(*ex_, form_col_, [&](index_t b, index_t) { kernel::tet_form_stiffness(form_, b, p, K); });
            return;
        }
        switch (variant_) {
            case Variant::Auto:  // resolved to a concrete variant by the constructor
                break;
            case Variant::Colour:
                par::for_colours(*ex_, stiff_col_, [&](index_t e0, index_t) { kernel::tsep_stiffness_segment(m, e0, p, K); });
                break;
            case Variant::Atomic:
                each_range(ne, [&](index_t b, index_t e) {
                    for (index_t i = b; i < e; ++i)
                        kernel::tsep_stiffness_segment_to(m, i, p, [K](std::size_t k, S v) { par::atomic_add(K, k, v); });
                });
                break;
            case Variant::Private: {
                const std::size_t len = 9 * (std::size_t(ne) + 1);
                auto& buf = private_buffer(pk_, len);
                each_part(ne, [&](int part, index_t b, index_t e) {
                    S* kp = &buf[std::size_t(part) * len];
                    for (index_t i = b; i < e; ++i) kernel::tsep_stiffness_segment(m, i, p, kp);
                });
                reduce_parts(buf, 9 * std::size_t(ne), len, K, true);  // the sink is not reduced
                break;
            }
            default: break;
        }
    }
}

template <class S>
void ParallelEdgeKernels<S>::multiply(const EdgeStiffness<S>& Ks, const S* x, S* y) const {
    const S* K = Ks.K.data();
    const auto& m = m_;
    if constexpr (std::is_floating_point_v<S>) {
        if (variant_ == Variant::Owner) {
            // On padded copies, as core's edge_multiply (one vector load per
            // x(V1), one load + store per y(V1)), in three phases: each part
            // pads its x range; runs its segments into y4 and its padded
            // spill window (the non-spilling ones in an out-of-line loop);
            // adds the incoming windows and copies its y range out. Bitwise
            // the same as on xyz strides. armadillo-7k: 44.6 -> 37.9 us at 1
            // thread, 24.6 -> 22.0 at 2 (the third phase's barrier included).
            const ForwardSpill& vs = vspill_;
            const index_t nv = m.num_vertices;
            Ks.x4.resize(4 * std::size_t(nv));
            Ks.y4.resize(4 * std::size_t(nv));
            S* x4 = Ks.x4.data();
            S* y4 = Ks.y4.data();
            run_linked(*ex_, kx_links_, [&](int phase, index_t q) {
                const index_t b = vs.part_first[q], e = vs.part_first[q + 1];
                if (phase == 0) {
                    kernel::pad_xyz(x, x4, b, e);
                } else if (phase == 1) {
                    std::fill(y4 + 4 * std::size_t(b), y4 + 4 * std::size_t(e), S(0));
                    const index_t c = spill_vertex_first_[q];
                    kernel::edge_kx_segments<4>(m, b, c, K, x4, y4);
                    const kernel::ForwardOut<S> fwd{y4, spill_v4_.data() + 4 * vs.window_first[q], e};
                    for (index_t a = c; a < e; ++a) kernel::edge_kx_segment<4>(m, a, K, x4, y4, fwd);
                } else {
                    add_incoming_spills<4>(vs, q, y4, spill_v4_);
                    kernel::unpad_xyz(y4, y, b, e);
                }
            });
            return;
        }
    }
    scatter_to_vertices(
        y, [&](index_t a, S* o, const auto&... fwd) { kernel::edge_kx_segment(m, a, K, x, o, fwd...); },
        [&](index_t v, const index_t* inc, index_t n, S* o) { kernel::vertex_kx_gather(m, v, inc, n, K, x, o); },
        [&](index_t i, const auto& add) { kernel::edge_kx_to(m, i, K, x, add); },
        [&](index_t i, S* o) { kernel::edge_kx(m, i, K, x, o); });
}

template <class S>
template <class Segment, class Gather, class EdgeTo, class Edge>
void ParallelEdgeKernels<S>::scatter_to_vertices(S* out, const Segment& segment, const Gather& gather,
                                                 const EdgeTo& edge_to, const Edge& edge) const {
    const index_t ne = m_.num_edges(), nv = m_.num_vertices;
    const std::size_t n = 3 * std::size_t(nv);
    auto zero = [&] { each_range(index_t(n), [&](index_t b, index_t e) { std::fill(out + b, out + e, S(0)); }); };
    switch (variant_) {
        case Variant::Auto:  // resolved to a concrete variant by the constructor
            break;
        case Variant::Colour:
            zero();
            par::for_colours(*ex_, vert_col_, [&](index_t a, index_t) { segment(a, out); });
            break;
        case Variant::Gather:
            each_range(nv, [&](index_t b, index_t e) {
                for (index_t v = b; v < e; ++v) gather(v, &inc_[inc_first_[v]], inc_first_[v + 1] - inc_first_[v], out);
            });
            break;
        case Variant::Atomic:
            zero();
            each_range(ne, [&](index_t b, index_t e) {
                for (index_t i = b; i < e; ++i) edge_to(i, [out](std::size_t k, S v) { par::atomic_add(out, k, v); });
            });
            break;
        case Variant::Private: {
            auto& buf = private_buffer(pv_, n);
            each_part(ne, [&](int part, index_t b, index_t e) {
                S* op = &buf[std::size_t(part) * n];
                for (index_t i = b; i < e; ++i) edge(i, op);
            });
            reduce_parts(buf, n, n, out, false);
            break;
        }
        case Variant::Owner:
            // A part's own range is written by no other part before the
            // barrier, so it is zeroed inside the part's work.
            run_forward_spill<3>(*ex_, vspill_, vertex_links_, out, spill_v_, [&](index_t q, index_t b, index_t e, const auto& fwd) {
                std::fill(out + 3 * std::size_t(b), out + 3 * std::size_t(e), S(0));
                const index_t c = spill_vertex_first_[q];
                for (index_t a = b; a < c; ++a) segment(a, out);
                for (index_t a = c; a < e; ++a) segment(a, out, fwd);
            });
            break;
    }
}

template <class S>
void ParallelEdgeKernels<S>::diagonal_blocks(const EdgeStiffness<S>& Ks, S* D) const {
    const index_t ne = m_.num_edges(), nv = m_.num_vertices;
    const std::size_t nd = 9 * std::size_t(nv);
    const S* K = Ks.K.data();
    const auto& m = m_;
    switch (variant_) {
        case Variant::Auto:  // resolved to a concrete variant by the constructor
            break;
        case Variant::Colour:
            each_range(index_t(nd), [&](index_t b, index_t e) { std::fill(D + b, D + e, S(0)); });
            par::for_colours(*ex_, vert_col_, [&](index_t a, index_t) { kernel::edge_diagonal_segment(m, a, K, D); });
            break;
        case Variant::Gather:
            each_range(nv, [&](index_t b, index_t e) {
                for (index_t v = b; v < e; ++v)
                    kernel::vertex_diagonal_gather(v, &inc_[inc_first_[v]], inc_first_[v + 1] - inc_first_[v], K, D);
            });
            break;
        case Variant::Atomic:
            each_range(index_t(nd), [&](index_t b, index_t e) { std::fill(D + b, D + e, S(0)); });
            each_range(ne, [&](index_t b, index_t e) {
                for (index_t i = b; i < e; ++i)
                    kernel::edge_diagonal_to(m, i, K, [D](std::size_t k, S v) { par::atomic_add(D, k, v); });
            });
            break;
        case Variant::Private: {
            auto& buf = private_buffer(pd_, nd);
            each_part(ne, [&](int part, index_t b, index_t e) {
                S* dp = &buf[std::size_t(part) * nd];
                for (index_t i = b; i < e; ++i) kernel::edge_diagonal(m, i, K, dp);
            });
            reduce_parts(buf, nd, nd, D, false);
            break;
        }
        case Variant::Owner:
            run_forward_spill<9>(*ex_, vspill_, vertex_links_, D, spill_d_, [&](index_t q, index_t b, index_t e, const auto& fwd) {
                std::fill(D + 9 * std::size_t(b), D + 9 * std::size_t(e), S(0));
                const index_t c = spill_vertex_first_[q];
                for (index_t a = b; a < c; ++a) kernel::edge_diagonal_segment(m, a, K, D);
                for (index_t a = c; a < e; ++a) kernel::edge_diagonal_segment(m, a, K, D, fwd);
            });
            break;
    }
}

}  // namespace edgefem
