// An instrumented scalar: a double that counts every binary +, -, *, / it
// executes (compound assignments included; unary minus, comparisons and
// conversions are free), so that the templated kernels run on it count their
// own floating-point operations as the source writes them (no compiler
// optimisation: dead code and common subexpressions are counted).
//
// The edge kernels keep g(E) in double whatever the scalar is (EdgeState::g),
// so the arithmetic on g in the TSEP strain loop is invisible here; see
// bench/flop_counts.hpp, which adds it by hand.
#pragma once

#include <cstdint>
#include <type_traits>

#include "cpu/edge_kernels.hpp"
#include "cpu/tet_edge_form.hpp"
#include "cpu/tet_kernels.hpp"

namespace edgefem::flops {

struct Counted {
    double v = 0;
    static inline std::int64_t ops = 0;  // single-threaded use only

    Counted() = default;
    template <class T, std::enable_if_t<std::is_arithmetic_v<T>, int> = 0>
    Counted(T x) : v(double(x)) {}  // NOLINT: implicit, like a built-in scalar
    operator double() const { return v; }  // NOLINT: g(E) = L(E) zeta stores into double

    Counted operator-() const { return Counted(-v); }
    Counted& operator+=(Counted o) { ++ops; v += o.v; return *this; }
    Counted& operator-=(Counted o) { ++ops; v -= o.v; return *this; }
    Counted& operator*=(Counted o) { ++ops; v *= o.v; return *this; }
    Counted& operator/=(Counted o) { ++ops; v /= o.v; return *this; }
};

inline Counted operator+(Counted a, Counted b) { ++Counted::ops; return Counted(a.v + b.v); }
inline Counted operator-(Counted a, Counted b) { ++Counted::ops; return Counted(a.v - b.v); }
inline Counted operator*(Counted a, Counted b) { ++Counted::ops; return Counted(a.v * b.v); }
inline Counted operator/(Counted a, Counted b) { ++Counted::ops; return Counted(a.v / b.v); }
// Mixed with built-in arithmetic types (2 * x, x * 0.5): exact matches, so
// they win over the built-in operators reached through operator double().
#define EDGEFEM_COUNTED_MIXED(op)                                                               \
    template <class T, std::enable_if_t<std::is_arithmetic_v<T>, int> = 0>                      \
    inline Counted operator op(T a, Counted b) { return Counted(a) op b; }                      \
    template <class T, std::enable_if_t<std::is_arithmetic_v<T>, int> = 0>                      \
    inline Counted operator op(Counted a, T b) { return a op Counted(b); }
EDGEFEM_COUNTED_MIXED(+)
EDGEFEM_COUNTED_MIXED(-)
EDGEFEM_COUNTED_MIXED(*)
EDGEFEM_COUNTED_MIXED(/)
#undef EDGEFEM_COUNTED_MIXED

// The double models converted to the counting scalar (same indices and
// coefficients).
inline EdgeModel<Counted> counted_model(const EdgeModel<double>& m) { return convert_scalar<Counted>(m); }

inline TetModel<Counted> counted_model(const TetModel<double>& m) {
    TetModel<Counted> c;
    c.num_vertices = m.num_vertices;
    c.tet = m.tet;
    c.volume = m.volume;
    c.data.resize(m.data.size());
    for (std::size_t t = 0; t < m.data.size(); ++t) {
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) c.data[t].Dinv[i][j] = m.data[t].Dinv[i][j];
        c.data[t].vol_lambda = m.data[t].vol_lambda;
        c.data[t].vol_mu = m.data[t].vol_mu;
    }
    return c;
}

// Operations counted by one call of each serial kernel (energy off).
struct Measured {
    std::int64_t edge_force_fe = 0, edge_force_sn = 0, edge_stiffness_fe = 0, edge_stiffness_sn = 0, edge_kx = 0;
    std::int64_t tet_force = 0, tet_stiffness = 0, tet_kx = 0;
    std::int64_t edge_stiffness_fe_tet_local = 0;  // FE stiffness from the tet-local form (when given)
    std::int64_t edge_force_fe_tet_local = 0;      // FE forces with the tet-local form's g pass (when given)
};

inline Measured count_kernels(const EdgeModel<double>& edge_d, const TetModel<double>& tet_d,
                              const std::vector<double>& u_d, const TetEdgeForm<double>* form_d = nullptr) {
    const EdgeModel<Counted> em = counted_model(edge_d);
    const BatchedTetModel<Counted> tm = make_batched_tet_model(counted_model(tet_d));
    std::vector<Counted> u(u_d.begin(), u_d.end()), f(u.size()), y(u.size()), x(u.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = Counted(0.001 * double(i % 7));
    Measured r;
    auto count = [](auto&& fn) {
        Counted::ops = 0;
        fn();
        return Counted::ops;
    };
    EdgeState<Counted> st;
    EdgeStiffness<Counted> K;
    r.edge_force_sn = count([&] { edge_forces<ModelKind::SN, false>(em, u.data(), f.data(), st); });
    r.edge_stiffness_sn = count([&] { edge_stiffness_all<ModelKind::SN>(em, st, K); });
    r.edge_force_fe = count([&] { edge_forces<ModelKind::FE, false>(em, u.data(), f.data(), st); });
    r.edge_stiffness_fe = count([&] { edge_stiffness_all<ModelKind::FE>(em, st, K); });
    r.edge_kx = count([&] { edge_multiply(em, K, x.data(), y.data()); });
    if (form_d) {
        const TetEdgeForm<Counted> form = convert_scalar<Counted>(*form_d);
        r.edge_force_fe_tet_local = count([&] { tet_form_forces<ModelKind::FE, false>(em, form, u.data(), f.data(), st); });
        r.edge_stiffness_fe_tet_local = count([&] { tet_form_stiffness_all<ModelKind::FE>(em, form, st, K); });
    }
    TetStiffness<Counted> Kt;
    r.tet_force = count([&] { tet_forces<false>(tm, u.data(), f.data()); });
    r.tet_stiffness = count([&] { tet_stiffness_all(tm, u.data(), Kt); });
    r.tet_kx = count([&] { tet_multiply(tm, Kt, x.data(), y.data()); });
    return r;
}

}  // namespace edgefem::flops
