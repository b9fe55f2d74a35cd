// Memory bandwidth, measured and modelled, so a kernel's speed on a mesh
// larger than the last-level cache can be read as a fraction of what the
// memory system delivers (docs/parallel.md, "Memory bandwidth").
//
// * A STREAM-style measurement (McCalpin's copy, scale, add, triad, plus a
//   read-only sum) run on an edgefem Executor in fixed blocks, so it uses the
//   same back-end and threads as the kernels it is compared with.
// * Models of the bytes one call of the edge kernels moves from memory,
//   counted from the data structures' sizes.
//
// Bytes are counted the STREAM way: every array element read or written is
// counted once; the write-allocate read of a written cache line (the line is
// read before it is overwritten unless non-temporal stores are used) is not
// counted, neither for STREAM nor for the kernels, so the ratio of the two
// is like for like.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/executor.hpp"
#include "cpu/tet_edge_form.hpp"

namespace edgefem {

// ---- STREAM ---------------------------------------------------------------

// Elements per block of the STREAM kernels: 64 Ki doubles (512 KiB per
// array). Fixed, so the partial sums of stream_sum (and so its result) do not
// depend on the thread count.
inline constexpr std::size_t kStreamBlock = std::size_t(1) << 16;

// Bytes counted per element (STREAM's convention: 8-byte words, no
// write-allocate traffic): copy and scale move 2 words, add and triad 3, sum 1.
inline constexpr double kStreamCopyBytes = 16, kStreamScaleBytes = 16, kStreamAddBytes = 24,
                        kStreamTriadBytes = 24, kStreamSumBytes = 8;

// The kernels, over fixed blocks of kStreamBlock elements run on `ex`. All
// spans must have the same size (InvalidArgument otherwise); outputs must
// not overlap inputs.
// copy: c = a.
void stream_copy(const Executor& ex, std::span<const double> a, std::span<double> c);
// scale: b = s c.
void stream_scale(const Executor& ex, std::span<const double> c, std::span<double> b, double s);
// add: c = a + b.
void stream_add(const Executor& ex, std::span<const double> a, std::span<const double> b, std::span<double> c);
// triad: a = b + s c.
void stream_triad(const Executor& ex, std::span<const double> b, std::span<const double> c, std::span<double> a,
                  double s);
// Read-only sum of a: per-block partial sums (8 independent accumulators
// inside a block, so the loop is bound by loads, not by the latency of one
// chain of additions), added in block order: the same bits for any thread
// count.
double stream_sum(const Executor& ex, std::span<const double> a);

struct StreamOptions {
    // Elements per array: 8 Mi doubles = 64 MiB, three arrays = 192 MiB, six
    // times a 32 MiB L3 (STREAM's rule: each array at least 4x the caches).
    std::size_t elements = std::size_t(1) << 23;
    // Timed runs of each kernel (after one untimed run that touches the
    // pages); the median is reported.
    int repetitions = 7;
};

// GB/s = 1e9 bytes per second, STREAM-counted (see kStream*Bytes).
struct StreamBandwidth {
    double copy = 0, scale = 0, add = 0, triad = 0, sum = 0;  // medians over the repetitions
    double triad_best = 0;  // the fastest triad run (STREAM itself reports the best)
    std::size_t elements = 0;  // per array
    int repetitions = 0;
    int threads = 0;  // ex.threads()
};

// Allocates three arrays of opts.elements doubles (first touched on `ex`, in
// the kernels' blocks), runs copy, scale, add, triad, sum in that order
// opts.repetitions times (plus one untimed round), times each call with
// steady_clock and returns the median rates. Throws InvalidArgument for
// elements == 0 or repetitions < 1.
StreamBandwidth measure_stream_bandwidth(const Executor& ex, const StreamOptions& opts = {});

// ---- Bytes moved by the edge kernels -----------------------------------------

// What to count:
// * Compulsory: every array the call needs, each once (model arrays read
//   once; state arrays written once and read once; the input read once, the
//   output written once). A lower bound for any schedule of the kernel on a
//   mesh that does not fit the cache; gathers through index lists (u, zeta,
//   f, x, y) are counted once, i.e. as if every cache line fetched were fully
//   used (a good locality ordering such as RCM comes close).
// * PerPass: as core's serial loops (edge_kernels.hpp) run: each array once
//   per loop that touches it, so arrays read by two loops count twice and
//   read-modify-writes count a read and a write; zero-filling an output
//   counts as a write. Gathers are still counted once per loop.
// Neither counts the parallel variants' plan data (gather lists, colour
// lists, private accumulators): by either measure, those variants move more.
enum class TrafficModel { Compulsory, PerPass };

namespace detail {
template <class T>
double traffic_bytes_of(const std::vector<T>& v) {
    return double(v.size()) * double(sizeof(T));
}
}  // namespace detail

// Bytes one force call (edge_forces<Kind>, any Energy) moves. Compulsory:
//   model, read once:  edge (2 index_t #E), edge_first (#V + 1), rest (3 #E S),
//                      LE (#E S), and for FE tsep_first (#E + 1),
//                      tsep_other (#P index_t), LP (#P S);
//   state, written then read (2x): p (3 #E S), zeta (#E S), g (#E double);
//   u read once (3 #V S), f written once (3 #V S).
// PerPass adds what the three loops repeat: edge is read again by the
// scatter (+2 index_t #E); FE: g is read and written again by the TSEP loop
// (+2 #E double); f is zero-filled, then read and written by the scatter
// (+2 x 3 #V S). SN: no TSEP arrays, and zeta is written but not read back.
template <class S>
double force_bytes_per_call(const EdgeModel<S>& m, ModelKind kind = ModelKind::FE,
                            TrafficModel model = TrafficModel::Compulsory) {
    const auto bytes_of = [](const auto& v) { return detail::traffic_bytes_of(v); };
    const double V = m.num_vertices, E = m.num_edges(), s = sizeof(S);
    double b = bytes_of(m.edge) + bytes_of(m.edge_first) + bytes_of(m.rest) + bytes_of(m.LE);
    b += 2 * (3 * E * s) + E * s + 2 * (E * sizeof(double));  // p, zeta written, g
    if (kind == ModelKind::FE) b += bytes_of(m.tsep_first) + bytes_of(m.tsep_other) + bytes_of(m.LP) + E * s;  // + zeta read
    b += 2 * (3 * V * s);  // u read, f written
    if (model == TrafficModel::PerPass) {
        b += bytes_of(m.edge);
        if (kind == ModelKind::FE) b += 2 * E * sizeof(double);
        b += 2 * (3 * V * s);
    }
    return b;
}

// The same for an FE force call with g from the tet-local form
// (tet_form_forces, the owner variant's owner_form_forces): the TSEP arrays
// replaced by the form's edge ids and rows (every batch lane, padding
// included); zeta is read again by the form pass. PerPass adds the edge
// re-read by the scatter, the form pass's read-modify-write of g
// (+2 #E double) and f's zero fill and scatter (+2 x 3 #V S).
// When the form runs in tiles (FormTile: more than one), the passes read
// the state back while a tile's p~, zeta and g are cached: Compulsory then
// counts the state once, as written (p~ 3 #E S, zeta #E S, g #E double),
// and the reads not at all. (The owner variant re-reads each part's head
// after its barrier, which this leaves out: it counts too few bytes there,
// never too many.) `state_stored` false: the call kept its state in a
// cached ring (tet_form_forces_ring, only with tiles): Compulsory counts
// none of it.
template <class S>
double form_force_bytes_per_call(const EdgeModel<S>& m, const TetEdgeForm<S>& form,
                                 TrafficModel model = TrafficModel::Compulsory, bool state_stored = true) {
    const auto bytes_of = [](const auto& v) { return detail::traffic_bytes_of(v); };
    const double E = m.num_edges(), s = sizeof(S);
    double b = force_bytes_per_call(m, ModelKind::SN, model);  // strains, scatter, p~ / zeta / g, u, f
    b += bytes_of(form.edge) + bytes_of(form.A);
    if (model == TrafficModel::Compulsory && form.tiles.size() > 1) {
        b -= 3 * E * s + E * sizeof(double);  // p~ and g read back from the cache
        if (!state_stored) b -= 3 * E * s + E * s + E * sizeof(double);  // nor written: a ring
    } else
        b += E * s;  // zeta read by the form pass
    if (model == TrafficModel::PerPass) b += 2 * E * sizeof(double);
    return b;
}

// Bytes one y = K x call (edge_multiply) moves. Compulsory: K (9 #E S; the
// sink block is never read), edge (2 index_t #E), edge_first (#V + 1), x read
// (3 #V S), y written (3 #V S). PerPass adds y's zero fill and the
// read-modify-write of the scatter (+2 x 3 #V S).
template <class S>
double kx_bytes_per_call(const EdgeModel<S>& m, TrafficModel model = TrafficModel::Compulsory) {
    const auto bytes_of = [](const auto& v) { return detail::traffic_bytes_of(v); };
    const double V = m.num_vertices, E = m.num_edges(), s = sizeof(S);
    double b = 9 * E * s + bytes_of(m.edge) + bytes_of(m.edge_first) + 2 * (3 * V * s);
    if (model == TrafficModel::PerPass) b += 2 * (3 * V * s);
    return b;
}

// Bytes one stiffness call moves with the TSEP-list layout (edge_stiffness_all
// <Kind>; the tet-local layout of tet_edge_form.hpp reads other arrays and is
// not modelled here). Compulsory: p (3 #E S) and g (#E double) read, LE
// (#E S), for FE tsep_first (#E + 1), tsep_other (#P index_t), LP (#P S) and
// target (4 #P index_t) read, K written (9 (#E + 1) S). PerPass (FE) adds the
// TSEP loop's second read of p and its read-modify-write of every K block
// (+3 #E S + 2 x 9 (#E + 1) S).
template <class S>
double stiffness_bytes_per_call(const EdgeModel<S>& m, ModelKind kind = ModelKind::FE,
                                TrafficModel model = TrafficModel::Compulsory) {
    const auto bytes_of = [](const auto& v) { return detail::traffic_bytes_of(v); };
    const double E = m.num_edges(), s = sizeof(S);
    double b = 3 * E * s + E * sizeof(double) + bytes_of(m.LE) + 9 * (E + 1) * s;
    if (kind == ModelKind::FE) {
        b += bytes_of(m.tsep_first) + bytes_of(m.tsep_other) + bytes_of(m.LP) + bytes_of(m.target);
        if (model == TrafficModel::PerPass) b += 3 * E * s + 2 * 9 * (E + 1) * s;
    }
    return b;
}

}  // namespace edgefem
