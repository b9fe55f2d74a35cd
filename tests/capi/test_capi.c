/* The C API from C11: the paper's 1,200-tet box built from arrays, clamped
 * at its x = min end, sagging under gravity; then the error paths. Prints
 * "test_capi: ok" and exits 0 on success. */
#define _POSIX_C_SOURCE 200112L /* setenv, unsetenv */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edgefem/edgefem.h"

static int failures = 0;

#define CHECK(cond)                                                              \
    do {                                                                         \
        if (!(cond)) {                                                           \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
            ++failures;                                                          \
        }                                                                        \
    } while (0)

#define CHECK_OK(call)                                                                      \
    do {                                                                                    \
        edgefem_status s_ = (call);                                                         \
        if (s_ != EDGEFEM_OK) {                                                             \
            fprintf(stderr, "%s:%d: %s -> %s: %s\n", __FILE__, __LINE__, #call,             \
                    edgefem_status_string(s_), edgefem_last_error());                       \
            ++failures;                                                                     \
        }                                                                                   \
    } while (0)

/* Expects `status` with a non-empty message containing `needle`. */
static void expect_error(edgefem_status got, edgefem_status want, const char* needle, const char* what) {
    const char* msg = edgefem_last_error();
    if (got != want) {
        fprintf(stderr, "%s: got %s, want %s (%s)\n", what, edgefem_status_string(got), edgefem_status_string(want),
                msg);
        ++failures;
    } else if (msg == NULL || msg[0] == '\0' || (needle && strstr(msg, needle) == NULL)) {
        fprintf(stderr, "%s: message '%s' lacks '%s'\n", what, msg ? msg : "(null)", needle ? needle : "");
        ++failures;
    } else {
        printf("  %s -> %s: %s\n", what, edgefem_status_string(got), msg);
    }
}

/* A box of nx x ny x nz cubes of side h centred at the origin, each cube
 * split into 6 tets around its main diagonal, oriented positively. */
static void make_box(int nx, int ny, int nz, double h, double** X, int32_t* nv, int32_t** T, int32_t* nt) {
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    const int sx = nx + 1, sy = ny + 1, sz = nz + 1;
    *nv = sx * sy * sz;
    *nt = 6 * nx * ny * nz;
    *X = malloc(sizeof(double) * 3 * (size_t)*nv);
    *T = malloc(sizeof(int32_t) * 4 * (size_t)*nt);
    for (int k = 0; k < sz; ++k)
        for (int j = 0; j < sy; ++j)
            for (int i = 0; i < sx; ++i) {
                double* p = *X + 3 * (size_t)(i + sx * (j + sy * k));
                p[0] = (i - 0.5 * nx) * h;
                p[1] = (j - 0.5 * ny) * h;
                p[2] = (k - 0.5 * nz) * h;
            }
    int32_t* t = *T;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                for (int p = 0; p < 6; ++p) {
                    int c[3] = {i, j, k};
                    for (int s = 0; s < 4; ++s) {
                        if (s > 0) ++c[perms[p][s - 1]];
                        t[s] = c[0] + sx * (c[1] + sy * c[2]);
                    }
                    /* orientation: swap the last two when the volume is negative */
                    const double *a = *X + 3 * t[0], *b = *X + 3 * t[1], *cc = *X + 3 * t[2], *d = *X + 3 * t[3];
                    double u[3], v[3], w[3];
                    for (int r = 0; r < 3; ++r) {
                        u[r] = b[r] - a[r];
                        v[r] = cc[r] - a[r];
                        w[r] = d[r] - a[r];
                    }
                    const double vol = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                                       u[2] * (v[0] * w[1] - v[1] * w[0]);
                    if (vol < 0) {
                        const int32_t tmp = t[2];
                        t[2] = t[3];
                        t[3] = tmp;
                    }
                    t += 4;
                }
}

/* Tagged surfaces, regions, mesh options, solver settings and surface
 * loads: the Gmsh test mesh's physical surface "skin" (tag 7), and a bar
 * (nu = 0) pulled by a traction on its x = max face, whose static stretch is
 * the analytic t / E at a small load. */
static void test_surfaces_regions_loads(void) {
    edgefem_scene* g = NULL;
    CHECK_OK(edgefem_scene_create_from_mesh_file_with(EDGEFEM_TEST_DATA "/small22.msh", 0, 0, &g));
    if (!g) return;
    size_t n = 0;
    CHECK_OK(edgefem_scene_surface_count(g, 7, &n));
    CHECK(n == 2);
    int32_t tri[6] = {0};
    CHECK_OK(edgefem_scene_get_surface(g, 7, tri, 6));
    const int32_t want[6] = {0, 1, 2, 1, 2, 4};
    CHECK(memcmp(tri, want, sizeof want) == 0);
    expect_error(edgefem_scene_get_surface(g, 7, tri, 5), EDGEFEM_ERROR_INVALID_ARGUMENT, "expected 3 x", "short surface buffer");
    int32_t tag = 0;
    CHECK_OK(edgefem_scene_surface_tag(g, "skin", &tag));
    CHECK(tag == 7);
    expect_error(edgefem_scene_surface_tag(g, "clamp", &tag), EDGEFEM_ERROR_INVALID_ARGUMENT, "\"clamp\"", "unknown physical name");
    expect_error(edgefem_scene_surface_count(g, 3, &n), EDGEFEM_ERROR_INVALID_ARGUMENT, "surface tag 3", "unknown tag");
    expect_error(edgefem_scene_add_surface_load(g, 7, 1e3, 0, 0, 0, NULL, NULL, 0), EDGEFEM_ERROR_INVALID_ARGUMENT,
                 "not on the boundary", "load on an interior triangle");
    CHECK_OK(edgefem_scene_fix_surface(g, 7));
    int32_t regions[3] = {0};
    CHECK_OK(edgefem_scene_get_regions(g, regions, 3));
    CHECK(regions[0] == 1 && regions[1] == 2 && regions[2] == 1);
    expect_error(edgefem_scene_get_regions(g, regions, 2), EDGEFEM_ERROR_INVALID_ARGUMENT, "#T = 3", "short region buffer");
    const int32_t other[3] = {4, 4, 5};
    CHECK_OK(edgefem_scene_set_regions(g, other, 3));
    CHECK_OK(edgefem_scene_get_regions(g, regions, 3));
    CHECK(regions[0] == 4 && regions[2] == 5);
    expect_error(edgefem_scene_set_regions(g, other, 2), EDGEFEM_ERROR_INVALID_ARGUMENT, "regions", "short regions");
    CHECK_OK(edgefem_scene_set_region_material(g, 5, 2e5, 0.25, 900));
    expect_error(edgefem_scene_set_region_material(g, 5, 2e5, 0.5, 900), EDGEFEM_ERROR_INVALID_ARGUMENT, "oisson",
                 "region material with nu = 0.5");
    edgefem_sim* gs = NULL;
    CHECK_OK(edgefem_sim_create(g, &gs));
    CHECK_OK(edgefem_sim_step(gs, NULL));
    edgefem_sim_destroy(gs);
    edgefem_scene_destroy(g);
    edgefem_scene* bad = NULL;
    expect_error(edgefem_scene_create_from_mesh_file_with(EDGEFEM_TEST_DATA "/small22.msh", 0, 2, &bad),
                 EDGEFEM_ERROR_INVALID_ARGUMENT, "compact: 2", "compact = 2");
    expect_error(edgefem_scene_create_from_mesh_file_with(EDGEFEM_TEST_DATA "/small22.msh", -1, 0, &bad),
                 EDGEFEM_ERROR_INVALID_ARGUMENT, "fix_orientation: -1", "fix_orientation = -1");
    CHECK(bad == NULL);

    /* The bar: 0.1 x 0.02 x 0.02 m, clamped at x = min, t = 100 Pa on x = max. */
    edgefem_scene* bar = NULL;
    CHECK_OK(edgefem_scene_create_box(10, 2, 2, 0.01, &bar));
    if (!bar) return;
    CHECK_OK(edgefem_scene_set_material(bar, 1e6, 0.0, 1000));
    double rest[3 * 99];
    CHECK_OK(edgefem_scene_get_rest_positions(bar, rest, 3 * 99));
    int32_t clamp[9], nclamp = 0;
    for (int32_t v = 0; v < 99; ++v)
        if (rest[3 * v] < -0.0499) clamp[nclamp++] = v;
    CHECK(nclamp == 9);
    CHECK_OK(edgefem_scene_set_fixed(bar, clamp, (size_t)nclamp));
    size_t nb = 0;
    CHECK_OK(edgefem_scene_boundary_count(bar, &nb));
    int32_t* all = malloc(sizeof(int32_t) * 3 * nb);
    int32_t* end = malloc(sizeof(int32_t) * 3 * nb);
    CHECK_OK(edgefem_scene_get_boundary(bar, all, 3 * nb));
    size_t nend = 0;
    for (size_t k = 0; k < nb; ++k) {
        int on = 1;
        for (int i = 0; i < 3; ++i) on = on && rest[3 * all[3 * k + i]] > 0.0499;
        if (on)
            for (int i = 0; i < 3; ++i) end[nend++] = all[3 * k + i];
    }
    CHECK(nend == 3 * 8);
    const double times[2] = {0, 1}, values[2] = {1, 1};
    CHECK_OK(edgefem_scene_add_surface_load_triangles(bar, end, nend, 0, 100, 0, 0, times, values, 2));
    expect_error(edgefem_scene_add_surface_load_triangles(bar, end, 4, 0, 1, 0, 0, NULL, NULL, 0),
                 EDGEFEM_ERROR_INVALID_ARGUMENT, "multiple of 3", "4 triangle indices");
    end[1] = 99;
    expect_error(edgefem_scene_add_surface_load_triangles(bar, end, 3, 0, 1, 0, 0, NULL, NULL, 0),
                 EDGEFEM_ERROR_INVALID_ARGUMENT, "triangles[1] = 99", "triangle vertex out of range");
    expect_error(edgefem_scene_add_surface_load_triangles(bar, all, 3, NAN, 0, 0, 0, NULL, NULL, 0),
                 EDGEFEM_ERROR_INVALID_ARGUMENT, "pressure", "NaN pressure");
    expect_error(edgefem_scene_set_linear_solver(bar, 2), EDGEFEM_ERROR_INVALID_ARGUMENT, "solver: 2", "linear solver 2");
    expect_error(edgefem_scene_set_method(bar, -1), EDGEFEM_ERROR_INVALID_ARGUMENT, "method: -1", "method -1");
    expect_error(edgefem_scene_set_newton(bar, 0, 10, 1), EDGEFEM_ERROR_INVALID_ARGUMENT, "tolerance", "Newton tolerance 0");
    CHECK_OK(edgefem_scene_set_method(bar, EDGEFEM_METHOD_EDGE));
    CHECK_OK(edgefem_scene_set_linear_solver(bar, EDGEFEM_LINEAR_DIRECT));
    CHECK_OK(edgefem_scene_set_newton(bar, 1e-12, 50, 1));
    edgefem_sim* bs = NULL;
    CHECK_OK(edgefem_sim_create(bar, &bs));
    if (bs) {
        int32_t converged = 0;
        CHECK_OK(edgefem_sim_solve_static(bs, &converged));
        CHECK(converged == 1);
        double u[3 * 99];
        CHECK_OK(edgefem_sim_get_displacement(bs, u, 3 * 99));
        const double strain = 100 / 1e6;
        double worst = 0;
        for (int32_t v = 0; v < 99; ++v) {
            const double want_ux = strain * (rest[3 * v] + 0.05);
            const double d = fabs(u[3 * v] - want_ux) + fabs(u[3 * v + 1]) + fabs(u[3 * v + 2]);
            if (d > worst) worst = d;
        }
        printf("  bar under 100 Pa: max |u - t/E x| = %.3g m (t/E x at the end: %.3g m)\n", worst, strain * 0.1);
        CHECK(worst < 1e-3 * strain * 0.1);
        edgefem_sim_destroy(bs);
    }
    CHECK_OK(edgefem_scene_clear_surface_loads(bar));
    free(all);
    free(end);
    edgefem_scene_destroy(bar);
}

/* Render surfaces: points embedded in the tets follow an affine motion
 * u = A X exactly (barycentric interpolation reproduces affine fields, also
 * extrapolated outside the mesh); vertex normals of two triangles; errors. */
static void test_embedding(void) {
    double* X;
    int32_t* T;
    int32_t nv, nt;
    make_box(3, 2, 2, 0.1, &X, &nv, &T, &nt); /* [-0.15, 0.15] x [-0.1, 0.1] x [-0.1, 0.1] */
    edgefem_scene* scene = NULL;
    CHECK_OK(edgefem_scene_create_from_arrays(X, nv, T, nt, &scene));
    const double pts[] = {0.01, 0.02, -0.03, -0.14, 0.09, 0.05, 0.1, -0.05, 0.099, 0.2, 0.0, 0.0 /* outside */};
    const size_t np = 4;
    edgefem_embedding* e = NULL;
    CHECK_OK(edgefem_embedding_create(scene, pts, 3 * np, &e));
    size_t n = 0;
    CHECK_OK(edgefem_embedding_num_points(e, &n));
    CHECK(n == np);
    double outside[4];
    CHECK_OK(edgefem_embedding_get_outside(e, outside, np));
    /* the last point is 0.05 m beyond the face x = 0.15; the estimate is the
     * distance to its tet's face plane, here a diagonal one (0.05 / sqrt 2) */
    CHECK(outside[0] == 0 && outside[1] == 0 && outside[2] == 0 && outside[3] > 0.02 && outside[3] <= 0.05 + 1e-15);
    edgefem_sim* sim = NULL;
    CHECK_OK(edgefem_sim_create(scene, &sim));
    edgefem_scene_destroy(scene); /* the embedding keeps its own mesh */
    const double A[3][3] = {{0.1, -0.2, 0.05}, {0.3, 0.02, -0.1}, {-0.05, 0.15, 0.2}};
    double* u = malloc(sizeof(double) * 3 * (size_t)nv);
    for (int32_t v = 0; v < nv; ++v)
        for (int i = 0; i < 3; ++i)
            u[3 * v + i] = A[i][0] * X[3 * v] + A[i][1] * X[3 * v + 1] + A[i][2] * X[3 * v + 2];
    CHECK_OK(edgefem_sim_set_displacement(sim, u, 3 * (size_t)nv));
    double y[12];
    CHECK_OK(edgefem_sim_embedded_positions(sim, e, y, 3 * np));
    double worst = 0;
    for (size_t k = 0; k < np; ++k)
        for (int i = 0; i < 3; ++i) {
            const double* p = pts + 3 * k;
            const double want = p[i] + A[i][0] * p[0] + A[i][1] * p[1] + A[i][2] * p[2];
            worst = fmax(worst, fabs(y[3 * k + i] - want));
        }
    CHECK(worst < 1e-15);
    expect_error(edgefem_sim_embedded_positions(sim, e, y, 3 * np - 1), EDGEFEM_ERROR_INVALID_ARGUMENT,
                 "3 x (number of points)", "short embedded positions buffer");
    const double bad_pts[] = {0, 0, NAN};
    edgefem_embedding* bad = NULL;
    edgefem_scene* scene2 = NULL;
    CHECK_OK(edgefem_scene_create_box(2, 2, 2, 0.1, &scene2));
    expect_error(edgefem_embedding_create(scene2, bad_pts, 3, &bad), EDGEFEM_ERROR_INVALID_ARGUMENT, "points[2]",
                 "NaN render point");
    CHECK(bad == NULL);
    expect_error(edgefem_embedding_create(scene2, pts, 4, &bad), EDGEFEM_ERROR_INVALID_ARGUMENT, "count is 4",
                 "render points not in threes");
    CHECK_OK(edgefem_embedding_create(scene2, pts, 3, &bad));
    expect_error(edgefem_sim_embedded_positions(sim, bad, y, 3), EDGEFEM_ERROR_INVALID_ARGUMENT, "27 vertices",
                 "embedding of another mesh");
    edgefem_embedding_destroy(bad);
    edgefem_scene_destroy(scene2);

    /* normals: a unit square in z = 0 as two triangles wound counter-clockwise
     * seen from +z, and a fifth vertex no triangle uses */
    const int32_t tri[] = {0, 1, 2, 0, 2, 3};
    const double P[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 5, 5, 5};
    double N[15];
    CHECK_OK(edgefem_vertex_normals(tri, 2, P, 5, N));
    for (int v = 0; v < 4; ++v) CHECK(N[3 * v] == 0 && N[3 * v + 1] == 0 && fabs(N[3 * v + 2] - 1) < 1e-15);
    CHECK(N[12] == 0 && N[13] == 0 && N[14] == 0);
    const int32_t tri_bad[] = {0, 1, 5};
    expect_error(edgefem_vertex_normals(tri_bad, 1, P, 5, N), EDGEFEM_ERROR_INVALID_ARGUMENT, "triangles[2] = 5",
                 "normals of a triangle past the vertices");
    edgefem_embedding_destroy(e);
    edgefem_embedding_destroy(e); /* a second destroy is ignored */
    edgefem_embedding_destroy(NULL);
    edgefem_sim_destroy(sim);
    free(u);
    free(X);
    free(T);
}

int main(void) {
    printf("edgefem %s, C API %d\n", edgefem_version_string(), EDGEFEM_C_API_VERSION);
    /* A user's malloc tunables are left alone; else, with glibc's own malloc, it changes the settings. */
    setenv("GLIBC_TUNABLES", "glibc.malloc.check=0", 1);
    CHECK(edgefem_retain_freed_memory() == 0);
    unsetenv("GLIBC_TUNABLES");
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
    CHECK(edgefem_retain_freed_memory() == 1);
#endif
    double* X;
    int32_t* T;
    int32_t nv, nt;
    make_box(10, 5, 4, 0.01, &X, &nv, &T, &nt); /* 0.1 x 0.05 x 0.04 m, 1,200 tets */
    CHECK(nv == 11 * 6 * 5 && nt == 1200);

    /* ---- the happy path ---- */
    edgefem_scene* scene = NULL;
    CHECK_OK(edgefem_scene_create_from_arrays(X, nv, T, nt, &scene));
    CHECK(scene != NULL);
    int32_t cv = 0, ct = 0;
    CHECK_OK(edgefem_scene_counts(scene, &cv, &ct));
    CHECK(cv == nv && ct == nt);

    int32_t* fixed = malloc(sizeof(int32_t) * (size_t)nv);
    size_t nfixed = 0;
    double xmax = -1;
    for (int32_t v = 0; v < nv; ++v) {
        if (X[3 * v] < -0.0499) fixed[nfixed++] = v;
        if (X[3 * v] > xmax) xmax = X[3 * v];
    }
    CHECK(nfixed == 6 * 5);
    CHECK_OK(edgefem_scene_set_fixed(scene, fixed, nfixed));
    CHECK_OK(edgefem_scene_set_material(scene, 1e5, 0.3, 1000));
    CHECK_OK(edgefem_scene_set_gravity(scene, 0, 0, -9.81));
    CHECK_OK(edgefem_scene_set_dt(scene, 1e-3));
    CHECK_OK(edgefem_scene_set_integrator(scene, EDGEFEM_SEMI_IMPLICIT));
    CHECK_OK(edgefem_scene_set_cg(scene, 1e-6, 500, 0));
    CHECK_OK(edgefem_scene_set_preconditioner(scene, "block-jacobi"));

    edgefem_sim* sim = NULL;
    CHECK_OK(edgefem_sim_create(scene, &sim));
    if (!sim) {
        fprintf(stderr, "no simulation: giving up\n");
        return 1;
    }
    edgefem_step_stats stats;
    memset(&stats, 0, sizeof stats);
    for (int k = 0; k < 50; ++k) CHECK_OK(edgefem_sim_step(sim, &stats));
    CHECK(stats.solver_iterations > 0);
    double t = 0;
    int64_t steps = 0;
    CHECK_OK(edgefem_sim_time(sim, &t, &steps));
    CHECK(steps == 50 && fabs(t - 0.05) < 1e-12);

    const size_t n3 = 3 * (size_t)nv;
    double* x = malloc(sizeof(double) * n3);
    double* u = malloc(sizeof(double) * n3);
    CHECK_OK(edgefem_sim_get_positions(sim, x, n3));
    CHECK_OK(edgefem_sim_get_displacement(sim, u, n3));
    int finite = 1;
    double free_end_uz = 0, fixed_max = 0;
    int free_count = 0;
    for (size_t i = 0; i < n3; ++i) {
        if (!isfinite(x[i])) finite = 0;
        if (fabs(x[i] - (X[i] + u[i])) > 1e-12) finite = 0;
    }
    for (int32_t v = 0; v < nv; ++v) {
        if (X[3 * v] > xmax - 1e-9) {
            free_end_uz += u[3 * v + 2];
            ++free_count;
        }
    }
    for (size_t i = 0; i < nfixed; ++i)
        for (int r = 0; r < 3; ++r) fixed_max = fmax(fixed_max, fabs(u[3 * (size_t)fixed[i] + r]));
    free_end_uz /= free_count;
    printf("  after 50 steps: free end mean u_z = %.6g m, fixed max |u| = %g, CG its = %d\n", free_end_uz,
           fixed_max, stats.solver_iterations);
    CHECK(finite);
    CHECK(free_end_uz < -1e-4); /* moved down under gravity */
    CHECK(fixed_max == 0.0);

    edgefem_energies e;
    CHECK_OK(edgefem_sim_energies(sim, &e));
    CHECK(isfinite(e.total) && e.elastic > 0 && e.kinetic >= 0 && e.gravity < 0);

    /* External forces: push the free end up and see it respond. */
    double* f = calloc(n3, sizeof(double));
    for (int32_t v = 0; v < nv; ++v)
        if (X[3 * v] > xmax - 1e-9) f[3 * v + 2] = 0.05;
    CHECK_OK(edgefem_sim_set_external_forces(sim, f, n3));
    CHECK_OK(edgefem_sim_set_external_force(sim, 0, 0, 0, 0));
    for (int k = 0; k < 50; ++k) CHECK_OK(edgefem_sim_step(sim, NULL));
    CHECK_OK(edgefem_sim_get_displacement(sim, u, n3));
    double pushed_uz = 0;
    for (int32_t v = 0; v < nv; ++v)
        if (X[3 * v] > xmax - 1e-9) pushed_uz += u[3 * v + 2] / free_count;
    printf("  pushed up: free end mean u_z = %.6g m\n", pushed_uz);
    CHECK(pushed_uz > free_end_uz);
    CHECK_OK(edgefem_sim_clear_external_forces(sim));

    /* ---- run options: the reference back-end, the CPU back-end's serial
     * loops in the input numbering and the defaults (every core, rcm) give
     * the same trajectory (different summation orders: within 1e-9) ---- */
    {
        const char* backends[3] = {"reference", "serial", NULL};
        const char* orderings[3] = {NULL, "input", NULL};
        double* ur[3];
        for (int c = 0; c < 3; ++c) {
            edgefem_run_options run;
            edgefem_run_options_default(&run);
            CHECK(run.threads == 0 && run.adaptive == 1 && run.backend == NULL);
            run.backend = backends[c];
            run.ordering = orderings[c];
            edgefem_sim* s = NULL;
            CHECK_OK(edgefem_sim_create_with(scene, c == 2 ? NULL : &run, &s));
            ur[c] = calloc(n3, sizeof(double));
            if (!s) continue;
            for (int k = 0; k < 20; ++k) CHECK_OK(edgefem_sim_step(s, NULL));
            CHECK_OK(edgefem_sim_get_displacement(s, ur[c], n3));
            edgefem_sim_destroy(s);
        }
        double umax = 0, d1 = 0, d2 = 0;
        for (size_t i = 0; i < n3; ++i) {
            umax = fmax(umax, fabs(ur[0][i]));
            d1 = fmax(d1, fabs(ur[1][i] - ur[0][i]));
            d2 = fmax(d2, fabs(ur[2][i] - ur[0][i]));
        }
        printf("  run options: |u| %.3g, serial/input and default against reference: %.3g, %.3g\n", umax, d1, d2);
        CHECK(umax > 1e-5 && d1 <= 1e-9 * umax && d2 <= 1e-9 * umax);
        for (int c = 0; c < 3; ++c) free(ur[c]);
    }

    /* ---- error paths ---- */
    printf("error paths:\n");
    {
        edgefem_run_options run;
        edgefem_run_options_default(&run);
        edgefem_sim* s = (edgefem_sim*)0x1;
        run.backend = "cuda9";
        expect_error(edgefem_sim_create_with(scene, &run, &s), EDGEFEM_ERROR_INVALID_ARGUMENT, "backend",
                     "unknown backend");
        CHECK(s == NULL);
        edgefem_run_options_default(&run);
        run.ordering = "zigzag";
        expect_error(edgefem_sim_create_with(scene, &run, &s), EDGEFEM_ERROR_INVALID_ARGUMENT, "ordering",
                     "unknown ordering");
        edgefem_run_options_default(&run);
        run.adaptive = 2;
        expect_error(edgefem_sim_create_with(scene, &run, &s), EDGEFEM_ERROR_INVALID_ARGUMENT, "adaptive",
                     "adaptive neither 0 nor 1");
        edgefem_run_options_default(&run);
        run.threads = -3;
        expect_error(edgefem_sim_create_with(scene, &run, &s), EDGEFEM_ERROR_INVALID_ARGUMENT, "threads",
                     "negative threads");
    }
    edgefem_scene* bad = (edgefem_scene*)0x1;
    X[3 * 7 + 1] = NAN;
    expect_error(edgefem_scene_create_from_arrays(X, nv, T, nt, &bad), EDGEFEM_ERROR_MESH, NULL, "NaN coordinate");
    CHECK(bad == NULL); /* *out is cleared on failure */
    X[3 * 7 + 1] = 0;
    const int32_t saved = T[4 * 5 + 2];
    T[4 * 5 + 2] = nv + 3;
    expect_error(edgefem_scene_create_from_arrays(X, nv, T, nt, &bad), EDGEFEM_ERROR_MESH, NULL,
                 "index out of range");
    T[4 * 5 + 2] = saved;
    expect_error(edgefem_scene_set_dt(scene, -1e-3), EDGEFEM_ERROR_INVALID_ARGUMENT, "dt", "negative dt");
    expect_error(edgefem_scene_set_preconditioner(scene, "multigrid"), EDGEFEM_ERROR_INVALID_ARGUMENT,
                 "solver.preconditioner", "unknown preconditioner");
    expect_error(edgefem_scene_set_preconditioner(scene, NULL), EDGEFEM_ERROR_NULL_POINTER, "name",
                 "null preconditioner name");
    expect_error(edgefem_scene_set_dt(scene, NAN), EDGEFEM_ERROR_INVALID_ARGUMENT, "dt", "NaN dt");
    expect_error(edgefem_scene_set_material(scene, 1e5, 0.5, 1000), EDGEFEM_ERROR_INVALID_ARGUMENT, NULL,
                 "Poisson 0.5");
    const int32_t out_of_range = nv;
    expect_error(edgefem_scene_set_fixed(scene, &out_of_range, 1), EDGEFEM_ERROR_INVALID_ARGUMENT, "out of range",
                 "fixed vertex out of range");
    expect_error(edgefem_scene_create_from_arrays(NULL, nv, T, nt, &bad), EDGEFEM_ERROR_NULL_POINTER, "positions",
                 "NULL positions");
    expect_error(edgefem_scene_create_from_arrays(X, nv, T, nt, NULL), EDGEFEM_ERROR_NULL_POINTER, "out",
                 "NULL out");
    expect_error(edgefem_sim_step(NULL, NULL), EDGEFEM_ERROR_NULL_POINTER, "sim", "NULL sim");
    expect_error(edgefem_sim_get_positions(sim, NULL, n3), EDGEFEM_ERROR_NULL_POINTER, "out", "NULL buffer");
    expect_error(edgefem_sim_get_positions(sim, x, n3 - 1), EDGEFEM_ERROR_INVALID_ARGUMENT, "count",
                 "short buffer");
    expect_error(edgefem_sim_set_external_force(sim, -1, 0, 0, 1), EDGEFEM_ERROR_INVALID_ARGUMENT, "vertex",
                 "external force on vertex -1");
    f[5] = INFINITY;
    expect_error(edgefem_sim_set_external_forces(sim, f, n3), EDGEFEM_ERROR_INVALID_ARGUMENT, "not finite",
                 "infinite force");
    expect_error(edgefem_scene_create_from_mesh_file("/nonexistent/mesh.node", &bad), EDGEFEM_ERROR_MESH, NULL,
                 "missing mesh file");
    expect_error(edgefem_scene_create_from_json("/nonexistent/scene.json", &bad), EDGEFEM_ERROR_FILE, NULL,
                 "missing scene file");
    expect_error(edgefem_scene_set_newmark(scene, 0.7, 0.5), EDGEFEM_ERROR_INVALID_ARGUMENT, "newmark.beta",
                 "Newmark beta above 1/2");
    expect_error(edgefem_scene_set_generalized_alpha(scene, -0.1), EDGEFEM_ERROR_INVALID_ARGUMENT,
                 "generalized_alpha.rho_inf", "negative rho_inf");
    {
        const double times[2] = {0.0, 0.0}, values[2] = {0.0, 1.0};
        expect_error(edgefem_scene_set_prescribed_keyframes(scene, times, values, 2), EDGEFEM_ERROR_INVALID_ARGUMENT,
                     "increase", "keyframe times not increasing");
        expect_error(edgefem_scene_set_initial_state(scene, times, NULL, 2), EDGEFEM_ERROR_INVALID_ARGUMENT,
                     "3 x #V", "initial state of the wrong length");
    }
    CHECK_OK(edgefem_scene_set_integrator(scene, EDGEFEM_BDF2_LINEAR));
    CHECK_OK(edgefem_scene_set_generalized_alpha(scene, 0.5));
    CHECK_OK(edgefem_scene_set_integrator(scene, EDGEFEM_SEMI_IMPLICIT));
    /* Enumerations are integers, range-checked and named (issue #27). */
    expect_error(edgefem_scene_set_integrator(scene, 42), EDGEFEM_ERROR_INVALID_ARGUMENT, "integrator: 42",
                 "integrator 42");
    expect_error(edgefem_scene_set_integrator(scene, -1), EDGEFEM_ERROR_INVALID_ARGUMENT, "integrator: -1",
                 "integrator -1");
    expect_error(edgefem_scene_set_model(scene, -3), EDGEFEM_ERROR_INVALID_ARGUMENT, "model: -3", "model -3");
    expect_error(edgefem_scene_set_model(scene, 2), EDGEFEM_ERROR_INVALID_ARGUMENT, "model: 2", "model 2");
    /* One vector: the message names the component, not a "vertex". */
    expect_error(edgefem_scene_set_gravity(scene, 0, NAN, 0), EDGEFEM_ERROR_INVALID_ARGUMENT, "gravity[1] is not finite",
                 "NaN gravity");
    CHECK(strstr(edgefem_last_error(), "vertex") == NULL);
    expect_error(edgefem_sim_set_external_force(sim, 2, 0, NAN, 0), EDGEFEM_ERROR_INVALID_ARGUMENT,
                 "force on vertex 2 is not finite", "NaN force on one vertex");

    /* Mesh arrays out, and prescribed vertices (issue #26's "complete C API"). */
    {
        int32_t* tets_out = malloc(sizeof(int32_t) * 4 * (size_t)nt);
        CHECK_OK(edgefem_scene_get_tets(scene, tets_out, 4 * (size_t)nt));
        CHECK(memcmp(tets_out, T, sizeof(int32_t) * 4 * (size_t)nt) == 0);
        expect_error(edgefem_scene_get_tets(scene, tets_out, 4 * (size_t)nt - 1), EDGEFEM_ERROR_INVALID_ARGUMENT,
                     "4 x #T", "short tets buffer");
        free(tets_out);
        /* The boundary of the 4 x 2 x 2 box: 2 triangles per cube face, 4 (8 + 4 + 8) = 80. */
        edgefem_scene* box = NULL;
        CHECK_OK(edgefem_scene_create_box(4, 2, 2, 0.01, &box));
        size_t nb = 0;
        CHECK_OK(edgefem_scene_boundary_count(box, &nb));
        CHECK(nb == 80);
        int32_t tri[3 * 80];
        CHECK_OK(edgefem_scene_get_boundary(box, tri, 3 * nb));
        for (size_t k = 0; k < 3 * nb; ++k) CHECK(tri[k] >= 0 && tri[k] < 45);
        expect_error(edgefem_scene_get_boundary(box, tri, 3 * nb - 1), EDGEFEM_ERROR_INVALID_ARGUMENT,
                     "3 x (boundary triangles)", "short boundary buffer");
        edgefem_scene_destroy(box);
        edgefem_scene* pres = NULL;
        CHECK_OK(edgefem_scene_create_box(4, 2, 2, 0.01, &pres));
        const int32_t clamp[] = {0, 5, 10, 15};                     /* x = min end of the 5 x 3 x 3 grid */
        CHECK_OK(edgefem_scene_set_fixed(pres, clamp, 4));
        const int32_t tip = 4 + 5 * (2 + 3 * 2);                    /* (i, j, k) = (4, 2, 2) */
        double rest[3 * 45];
        CHECK_OK(edgefem_scene_get_rest_positions(pres, rest, 3 * 45));
        const double target[3] = {rest[3 * tip], rest[3 * tip + 1], rest[3 * tip + 2] - 0.005};
        expect_error(edgefem_scene_set_prescribed(pres, clamp, target, 1, 1), EDGEFEM_ERROR_INVALID_ARGUMENT,
                     "also fixed", "prescribed vertex also fixed");
        expect_error(edgefem_scene_set_prescribed(pres, &tip, target, 1, 0), EDGEFEM_ERROR_INVALID_ARGUMENT,
                     "steps", "prescribed over 0 steps");
        CHECK_OK(edgefem_scene_set_prescribed(pres, &tip, target, 1, 1));
        edgefem_sim* ps = NULL;
        CHECK_OK(edgefem_sim_create(pres, &ps));
        int32_t converged = 0;
        CHECK_OK(edgefem_sim_solve_static(ps, &converged));
        double xs[3 * 45];
        CHECK_OK(edgefem_sim_get_positions(ps, xs, 3 * 45));
        CHECK(converged == 1);
        CHECK(fabs(xs[3 * tip + 2] - target[2]) < 1e-12 && fabs(xs[3 * clamp[1] + 2] - rest[3 * clamp[1] + 2]) == 0);
        edgefem_sim_destroy(ps);
        edgefem_scene_destroy(pres);
    }

    /* An explicit step far beyond the stability limit fails as a simulation error. */
    edgefem_scene* stiff = NULL;
    CHECK_OK(edgefem_scene_create_box(4, 2, 2, 0.01, &stiff));
    CHECK_OK(edgefem_scene_set_material(stiff, 1e9, 0.3, 1000));
    CHECK_OK(edgefem_scene_set_integrator(stiff, EDGEFEM_EXPLICIT));
    CHECK_OK(edgefem_scene_set_dt(stiff, 1e-2));
    CHECK_OK(edgefem_scene_set_gravity(stiff, 0, 0, -9.81));
    edgefem_sim* unstable = NULL;
    CHECK_OK(edgefem_sim_create(stiff, &unstable));
    edgefem_status st = EDGEFEM_OK;
    for (int k = 0; k < 200 && st == EDGEFEM_OK; ++k) st = edgefem_sim_step(unstable, NULL);
    expect_error(st, EDGEFEM_ERROR_SIMULATION, "step", "unstable explicit step");
    /* The failed step left the state of the step before it: finite. */
    {
        int32_t unv = 0;
        CHECK_OK(edgefem_sim_num_vertices(unstable, &unv));
        double* ux = malloc(sizeof(double) * 3 * (size_t)unv);
        CHECK_OK(edgefem_sim_get_positions(unstable, ux, 3 * (size_t)unv));
        int finite = 1;
        for (int32_t i = 0; i < 3 * unv; ++i) finite = finite && isfinite(ux[i]);
        CHECK(finite);
        edgefem_energies ue;
        CHECK_OK(edgefem_sim_energies(unstable, &ue));
        CHECK(isfinite(ue.total));
        free(ux);
    }
    edgefem_sim_destroy(unstable);
    edgefem_scene_destroy(stiff);

    test_surfaces_regions_loads();
    test_embedding();

    /* The simulation still works after all that. */
    CHECK_OK(edgefem_sim_step(sim, NULL));

    /* ---- checkpoints: 3 BDF2 steps, a checkpoint, 3 more steps equal a new
     * simulation that loads it and takes 3 steps, bit for bit; a missing
     * file, another integrator and a truncated file are EDGEFEM_ERROR_FILE
     * and leave the state as it was ---- */
    {
        const char* ckpt = "edgefem_test_capi.ckpt";
        CHECK_OK(edgefem_scene_set_integrator(scene, EDGEFEM_BDF2));
        edgefem_sim *a = NULL, *b = NULL;
        CHECK_OK(edgefem_sim_create(scene, &a));
        CHECK_OK(edgefem_sim_create(scene, &b));
        for (int k = 0; k < 3; ++k) CHECK_OK(edgefem_sim_step(a, NULL));
        CHECK_OK(edgefem_sim_save_checkpoint(a, ckpt));
        for (int k = 0; k < 3; ++k) CHECK_OK(edgefem_sim_step(a, NULL));
        CHECK_OK(edgefem_sim_load_checkpoint(b, ckpt));
        for (int k = 0; k < 3; ++k) CHECK_OK(edgefem_sim_step(b, NULL));
        double* ua = calloc(n3, sizeof(double));
        double* ub = calloc(n3, sizeof(double));
        CHECK_OK(edgefem_sim_get_velocity(a, ua, n3));
        CHECK_OK(edgefem_sim_get_velocity(b, ub, n3));
        CHECK(memcmp(ua, ub, n3 * sizeof(double)) == 0);
        CHECK_OK(edgefem_sim_get_displacement(a, ua, n3));
        CHECK_OK(edgefem_sim_get_displacement(b, ub, n3));
        CHECK(memcmp(ua, ub, n3 * sizeof(double)) == 0);
        int64_t sa = 0, sb = 0;
        CHECK_OK(edgefem_sim_time(a, NULL, &sa));
        CHECK_OK(edgefem_sim_time(b, NULL, &sb));
        CHECK(sa == 6 && sb == 6);

        expect_error(edgefem_sim_load_checkpoint(b, "no_such_dir/x.ckpt"), EDGEFEM_ERROR_FILE, "cannot be opened",
                     "load a missing checkpoint");
        expect_error(edgefem_sim_load_checkpoint(b, NULL), EDGEFEM_ERROR_NULL_POINTER, "path", "load NULL path");
        expect_error(edgefem_sim_save_checkpoint(b, "no_such_dir/x.ckpt"), EDGEFEM_ERROR_FILE, "no_such_dir",
                     "save into a missing folder");
        CHECK_OK(edgefem_scene_set_integrator(scene, EDGEFEM_NEWMARK));
        edgefem_sim* other = NULL;
        CHECK_OK(edgefem_sim_create(scene, &other));
        expect_error(edgefem_sim_load_checkpoint(other, ckpt), EDGEFEM_ERROR_FILE, "integrator 'bdf2'",
                     "load into another integrator");
        /* Keep the first half of the file. */
        FILE* fp = fopen(ckpt, "rb");
        CHECK(fp != NULL);
        if (fp) {
            char* bytes = malloc(1 << 20);
            const size_t size = fread(bytes, 1, 1 << 20, fp);
            fclose(fp);
            CHECK(size > 100 && size < (1 << 20));
            fp = fopen(ckpt, "wb");
            CHECK(fp != NULL && fwrite(bytes, 1, size / 2, fp) == size / 2);
            if (fp) fclose(fp);
            free(bytes);
        }
        expect_error(edgefem_sim_load_checkpoint(b, ckpt), EDGEFEM_ERROR_FILE, "truncated", "load a truncated file");
        CHECK_OK(edgefem_sim_get_displacement(b, ub, n3));
        CHECK(memcmp(ua, ub, n3 * sizeof(double)) == 0);
        remove(ckpt);
        free(ua);
        free(ub);
        edgefem_sim_destroy(other);
        edgefem_sim_destroy(a);
        edgefem_sim_destroy(b);
    }

    edgefem_sim_destroy(sim);
    edgefem_scene_destroy(scene);
    edgefem_scene_destroy(NULL);
    edgefem_sim_destroy(NULL);
    /* Destroying twice, or what no create returned, does nothing. */
    edgefem_sim_destroy(sim);
    edgefem_scene_destroy(scene);
    {
        double not_a_handle[8] = {0};
        edgefem_sim_destroy((edgefem_sim*)not_a_handle);
        edgefem_scene_destroy((edgefem_scene*)not_a_handle);
    }
    free(f);
    free(u);
    free(x);
    free(fixed);
    free(X);
    free(T);
    if (failures) {
        printf("test_capi: %d failure(s)\n", failures);
        return 1;
    }
    printf("test_capi: ok\n");
    return 0;
}
