#include "lab/stream_bandwidth.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"

namespace edgefem {

namespace {

index_t num_blocks(std::size_t n) { return static_cast<index_t>((n + kStreamBlock - 1) / kStreamBlock); }

// body(begin, end) over [0, n) in kStreamBlock blocks on ex.
template <class Body>
void each_block(const Executor& ex, std::size_t n, Body&& body) {
    ex.for_chunks(num_blocks(n), [&](index_t k) {
        const std::size_t b = std::size_t(k) * kStreamBlock;
        body(b, std::min(n, b + kStreamBlock));
    });
}

void check_sizes(const char* what, std::size_t n, std::initializer_list<std::size_t> others) {
    for (std::size_t m : others)
        if (m != n)
            throw InvalidArgument(std::string(what) + ": arrays of different sizes (" + std::to_string(n) + " and " +
                                  std::to_string(m) + ")");
}

double block_sum(const double* __restrict a, std::size_t n) {
    double s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8)
        for (int k = 0; k < 8; ++k) s[k] += a[i + k];
    for (; i < n; ++i) s[0] += a[i];
    return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

}  // namespace

void stream_copy(const Executor& ex, std::span<const double> a, std::span<double> c) {
    check_sizes("stream_copy", a.size(), {c.size()});
    const double* __restrict pa = a.data();
    double* __restrict pc = c.data();
    each_block(ex, a.size(), [=](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) pc[i] = pa[i];
    });
}

void stream_scale(const Executor& ex, std::span<const double> c, std::span<double> b, double s) {
    check_sizes("stream_scale", c.size(), {b.size()});
    const double* __restrict pc = c.data();
    double* __restrict pb = b.data();
    each_block(ex, c.size(), [=](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) pb[i] = s * pc[i];
    });
}

void stream_add(const Executor& ex, std::span<const double> a, std::span<const double> b, std::span<double> c) {
    check_sizes("stream_add", a.size(), {b.size(), c.size()});
    const double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    double* __restrict pc = c.data();
    each_block(ex, a.size(), [=](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) pc[i] = pa[i] + pb[i];
    });
}

void stream_triad(const Executor& ex, std::span<const double> b, std::span<const double> c, std::span<double> a,
                  double s) {
    check_sizes("stream_triad", b.size(), {c.size(), a.size()});
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
    double* __restrict pa = a.data();
    each_block(ex, b.size(), [=](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) pa[i] = pb[i] + s * pc[i];
    });
}

double stream_sum(const Executor& ex, std::span<const double> a) {
    std::vector<double> partial(std::size_t(num_blocks(a.size())), 0.0);
    const double* pa = a.data();
    double* pp = partial.data();
    each_block(ex, a.size(), [=](std::size_t b, std::size_t e) { pp[b / kStreamBlock] = block_sum(pa + b, e - b); });
    double s = 0;
    for (double p : partial) s += p;
    return s;
}

StreamBandwidth measure_stream_bandwidth(const Executor& ex, const StreamOptions& opts) {
    if (opts.elements == 0) throw InvalidArgument("measure_stream_bandwidth: elements must be positive");
    if (opts.repetitions < 1) throw InvalidArgument("measure_stream_bandwidth: repetitions must be at least 1");
    const std::size_t n = opts.elements;
    // Uninitialised storage, first touched on the executor in the kernels'
    // blocks (where the pages land matters on NUMA machines).
    const std::unique_ptr<double[]> sa(new double[n]), sb(new double[n]), sc(new double[n]);
    const std::span<double> a(sa.get(), n), b(sb.get(), n), c(sc.get(), n);
    each_block(ex, n, [&](std::size_t lo, std::size_t hi) {
        std::fill(a.begin() + lo, a.begin() + hi, 1.0);
        std::fill(b.begin() + lo, b.begin() + hi, 2.0);
        std::fill(c.begin() + lo, c.begin() + hi, 0.0);
    });

    using clock = std::chrono::steady_clock;
    enum { Copy, Scale, Add, Triad, Sum, Kernels };
    std::vector<double> seconds[Kernels];
    const double scalar = 3.0;
    volatile double sink = 0;  // keeps the sum alive
    for (int rep = 0; rep <= opts.repetitions; ++rep) {  // rep 0: untimed
        const auto timed = [&](int k, auto&& call) {
            const auto t0 = clock::now();
            call();
            const double s = std::chrono::duration<double>(clock::now() - t0).count();
            if (rep > 0) seconds[k].push_back(s);
        };
        timed(Copy, [&] { stream_copy(ex, a, c); });
        timed(Scale, [&] { stream_scale(ex, c, b, scalar); });
        timed(Add, [&] { stream_add(ex, a, b, c); });
        timed(Triad, [&] { stream_triad(ex, b, c, a, scalar); });
        timed(Sum, [&] { sink = sink + stream_sum(ex, a); });
    }
    (void)sink;

    const auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const std::size_t m = v.size();
        return m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
    };
    const auto rate = [&](double bytes_per_element, double s) { return bytes_per_element * double(n) / s * 1e-9; };
    StreamBandwidth r;
    r.copy = rate(kStreamCopyBytes, median(seconds[Copy]));
    r.scale = rate(kStreamScaleBytes, median(seconds[Scale]));
    r.add = rate(kStreamAddBytes, median(seconds[Add]));
    r.triad = rate(kStreamTriadBytes, median(seconds[Triad]));
    r.sum = rate(kStreamSumBytes, median(seconds[Sum]));
    r.triad_best = rate(kStreamTriadBytes, *std::min_element(seconds[Triad].begin(), seconds[Triad].end()));
    r.elements = n;
    r.repetitions = opts.repetitions;
    r.threads = ex.threads();
    return r;
}

}  // namespace edgefem
