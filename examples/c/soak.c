/*
 * Soak through the C API: does memory stay flat over thousands of re-solves?
 *
 *   usage: synovia_soak [STEPS]        (default 2000)
 *
 * A navigation tool calls syn_model_solve_step at 10–60 Hz for hours. This program builds a
 * frictional 3D model of about 43 000 DOFs through syn_model_from_arrays — a block
 * [-1/2, 1/2]^2 x [b(x, y), 1/2] whose bottom b = R - sqrt(R^2 - x^2 - y^2) is a spherical cap
 * (R = 2), 30 x 30 x 15 hexahedra split into 6 tetrahedra each (Kuhn), E = 1000, nu = 0.3 —
 * on a rigid plane z = 0 with Coulomb friction 0.3, its top moved periodically (press
 * 0.01 (1 + sin(wt)/2), sideways shift 0.004 cos(wt), period 37 steps), and runs STEPS
 * quasi-static steps (syn_model_solve_step), changing the prescribed displacement before each.
 *
 * It samples the resident set size (VmRSS of /proc/self/status, Linux) after the first step,
 * after step 1000 and at the end, checks every step's KKT residual (SynSolveInfo) and ends with
 * one JSON line: steps, dofs, rss_start_mb, rss_1000_mb (null for shorter runs), rss_end_mb,
 * growth_mb (end - step 1000, or end - start for shorter runs), max_kkt. examples/c/run.sh
 * builds it and runs a few steps; the 10 000-step measurement is in docs/reliability.md.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "synovia.h"

enum { NX = 30, NY = 30, NZ = 15 };
enum { N_NODES = (NX + 1) * (NY + 1) * (NZ + 1), N_TETS = 6 * NX * NY * NZ, N_FACETS = 2 * 2 * NX * NY };
enum { TAG_BOTTOM = 1, TAG_TOP = 2 };
static const double RADIUS = 2.0, YOUNG = 1000.0, POISSON = 0.3, FRICTION = 0.3;
static const double DEPTH = 0.01, SHIFT = 0.004, PERIOD_STEPS = 37.0;
static const double TWO_PI = 6.283185307179586;

static double *coords;
static int32_t *tets, *tet_body, *facets, *facet_tags;

static int32_t id(int i, int j, int k) { return (int32_t)((k * (NY + 1) + j) * (NX + 1) + i); }

/* six times the signed volume of a tetrahedron */
static double volume6(const int32_t *t) {
    const double *a = &coords[3 * t[0]], *b = &coords[3 * t[1]], *c = &coords[3 * t[2]], *d = &coords[3 * t[3]];
    double u[3], v[3], w[3];
    for (int q = 0; q < 3; q++) {
        u[q] = b[q] - a[q];
        v[q] = c[q] - a[q];
        w[q] = d[q] - a[q];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

static int build_mesh(void) {
    coords = malloc(3 * (size_t)N_NODES * sizeof *coords);
    tets = malloc(4 * (size_t)N_TETS * sizeof *tets);
    tet_body = calloc((size_t)N_TETS, sizeof *tet_body);
    facets = malloc(3 * (size_t)N_FACETS * sizeof *facets);
    facet_tags = malloc((size_t)N_FACETS * sizeof *facet_tags);
    if (!coords || !tets || !tet_body || !facets || !facet_tags) return 1;
    for (int k = 0; k <= NZ; k++)
        for (int j = 0; j <= NY; j++)
            for (int i = 0; i <= NX; i++) {
                double x = -0.5 + (double)i / NX, y = -0.5 + (double)j / NY;
                double b = RADIUS - sqrt(RADIUS * RADIUS - x * x - y * y);
                double *p = &coords[3 * id(i, j, k)];
                p[0] = x;
                p[1] = y;
                p[2] = b + (0.5 - b) * (double)k / NZ;
            }
    /* Kuhn: the 6 paths from corner (0,0,0) to (1,1,1) of each hexahedron, one axis at a time */
    static const int axes[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    size_t e = 0;
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++)
                for (int p = 0; p < 6; p++) {
                    int c[3] = {i, j, k};
                    int32_t *t = &tets[4 * e];
                    t[0] = id(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[axes[p][s]]++;
                        t[s + 1] = id(c[0], c[1], c[2]);
                    }
                    if (volume6(t) < 0.0) {
                        int32_t tmp = t[1];
                        t[1] = t[2];
                        t[2] = tmp;
                    }
                    e++;
                }
    /* bottom (k = 0) and top (k = NZ) quads split along the Kuhn diagonal (i,j)-(i+1,j+1) */
    size_t f = 0;
    for (int side = 0; side < 2; side++) {
        int k = side == 0 ? 0 : NZ;
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++) {
                int32_t a = id(i, j, k), b = id(i + 1, j, k), c = id(i + 1, j + 1, k), d = id(i, j + 1, k);
                int32_t tri[6] = {a, b, c, a, c, d};
                memcpy(&facets[3 * f], tri, sizeof tri);
                facet_tags[f] = facet_tags[f + 1] = side == 0 ? TAG_BOTTOM : TAG_TOP;
                f += 2;
            }
    }
    return 0;
}

/* resident set size in MiB (VmRSS), -1 where /proc is not available */
static double rss_mb(void) {
    FILE *fp = fopen("/proc/self/status", "r");
    if (!fp) return -1.0;
    char line[256];
    double mb = -1.0;
    while (fgets(line, sizeof line, fp))
        if (strncmp(line, "VmRSS:", 6) == 0) {
            mb = strtod(line + 6, NULL) / 1024.0;
            break;
        }
    fclose(fp);
    return mb;
}

static void print_error(const char *what, SynStatus s) {
    char msg[512];
    syn_last_error_message(msg, sizeof msg);
    fprintf(stderr, "%s: %s (%d): %s\n", what, syn_status_name(s), (int)s, msg);
}

#define CHECK(call)                                  \
    do {                                             \
        SynStatus s_ = (call);                       \
        if (s_ != SYN_STATUS_OK) {                   \
            print_error(#call, s_);                  \
            return 1;                                \
        }                                            \
    } while (0)

static void top_motion(double t, double out[3]) {
    double w = TWO_PI / PERIOD_STEPS;
    out[0] = SHIFT * cos(w * t);
    out[1] = 0.0;
    out[2] = -DEPTH * (1.0 + 0.5 * sin(w * t));
}

int main(int argc, char **argv) {
    long steps = 2000;
    if (argc > 1) {
        char *end = NULL;
        steps = strtol(argv[1], &end, 10);
        if (end == argv[1] || *end != '\0' || steps < 1) {
            fprintf(stderr, "STEPS must be a whole number >= 1, got \"%s\"\n", argv[1]);
            return 2;
        }
    }
    if (build_mesh() != 0) {
        fprintf(stderr, "out of memory building the mesh\n");
        return 1;
    }
    SynMeshArrays arrays = {
        .dimension = 3,
        .coords = coords,
        .coords_len = 3 * (size_t)N_NODES,
        .elements = tets,
        .elements_len = 4 * (size_t)N_TETS,
        .element_body = tet_body,
        .element_body_len = N_TETS,
        .facets = facets,
        .facets_len = 3 * (size_t)N_FACETS,
        .facet_tags = facet_tags,
        .facet_tags_len = N_FACETS,
        .young = &YOUNG,
        .young_len = 1,
        .poisson = &POISSON,
        .poisson_len = 1,
    };
    SynModel *model = NULL;
    CHECK(syn_model_from_arrays(&arrays, &model));
    double top[3];
    top_motion(0.0, top);
    CHECK(syn_model_set_displacement(model, TAG_TOP, top, 3));
    const double point[3] = {0.0, 0.0, 0.0}, normal[3] = {0.0, 0.0, 1.0};
    CHECK(syn_model_add_contact_plane(model, TAG_BOTTOM, point, normal, 3, FRICTION, NULL));
    /* the free DOFs: all nodes but the top layer */
    long dofs = 3L * (N_NODES - (NX + 1) * (NY + 1));

    double rss_start = -1.0, rss_1000 = -1.0, max_kkt = 0.0;
    for (long step = 1; step <= steps; step++) {
        top_motion((double)step, top);
        CHECK(syn_model_set_displacement(model, TAG_TOP, top, 3));
        CHECK(syn_model_solve_step(model, (double)step));
        SynSolveInfo info;
        CHECK(syn_model_get_solve_info(model, &info));
        if (!(info.kkt_residual <= 1e-6)) {
            fprintf(stderr, "step %ld: KKT residual %.3e\n", step, info.kkt_residual);
            return 1;
        }
        if (info.kkt_residual > max_kkt) max_kkt = info.kkt_residual;
        if (step == 1) rss_start = rss_mb();
        if (step == 1000) rss_1000 = rss_mb();
        if (step % 500 == 0)
            fprintf(stderr, "step %6ld: rss %.1f MB, %zu iterations, kkt %.1e\n", step, rss_mb(), info.iterations,
                    info.kkt_residual);
    }
    double rss_end = rss_mb();
    double growth = rss_end - (rss_1000 >= 0.0 ? rss_1000 : rss_start);
    CHECK(syn_model_free(model));
    free(coords);
    free(tets);
    free(tet_body);
    free(facets);
    free(facet_tags);
    char at_1000[32] = "null";
    if (rss_1000 >= 0.0) snprintf(at_1000, sizeof at_1000, "%.2f", rss_1000);
    printf("{\"example\":\"soak_c\",\"steps\":%ld,\"dofs\":%ld,\"rss_start_mb\":%.2f,\"rss_1000_mb\":%s,"
           "\"rss_end_mb\":%.2f,\"growth_mb\":%.2f,\"max_kkt\":%.3e}\n",
           steps, dofs, rss_start, at_1000, rss_end, growth, max_kkt);
    return 0;
}
