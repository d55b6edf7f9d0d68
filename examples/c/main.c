/*
 * The synovia C API from C: a 2D rounded punch (a block whose bottom is an arc of radius 2)
 * pressed onto a rigid plane with Coulomb friction, its top moved in three quasi-static steps;
 * then the documented error codes for NULL pointers, invalid handles and wrong sizes.
 *
 *   usage: synovia_example [F0 F1 F2]
 *
 * F0..F2 are the normal contact forces after each step computed through the Rust API
 * (crates/synovia-capi/examples/reference.rs); when given, the program exits 0 only if its
 * forces agree with them to 1e-12 relative and every error check passes. examples/c/run.sh
 * builds everything and runs it. The mesh is built with the same formulas as
 * crates/synovia-capi/tests/common/mod.rs (keep them in sync).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "synovia.h"

enum { NX = 24, NY = 10, N_NODES = (NX + 1) * (NY + 1), N_ELEMENTS = 2 * NX * NY, N_FACETS = 2 * NX };
static const double RADIUS = 2.0, YOUNG = 1000.0, POISSON = 0.3, FRICTION = 0.3;
enum { TAG_BOTTOM = 1, TAG_TOP = 2 };
static const double TIMES[3] = {0.0, 1.0, 2.0};
static const double TOP[3][2] = {{0.0, -0.05}, {0.004, -0.06}, {0.01, -0.06}};

static double coords[2 * N_NODES];
static int32_t elements[3 * N_ELEMENTS];
static int32_t element_body[N_ELEMENTS];
static int32_t facets[2 * N_FACETS];
static int32_t facet_tags[N_FACETS];

static int failures = 0;

static int32_t id(int i, int j) { return (int32_t)(j * (NX + 1) + i); }

static void build_mesh(void) {
    for (int j = 0; j <= NY; j++) {
        for (int i = 0; i <= NX; i++) {
            double x = -1.0 + 2.0 * (double)i / (double)NX;
            double b = RADIUS - sqrt(RADIUS * RADIUS - x * x);
            double y = b + (1.0 - b) * (double)j / (double)NY;
            coords[2 * id(i, j)] = x;
            coords[2 * id(i, j) + 1] = y;
        }
    }
    int e = 0;
    for (int j = 0; j < NY; j++) {
        for (int i = 0; i < NX; i++) {
            int32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            int32_t tri[6] = {a, b, c, a, c, d};
            memcpy(&elements[3 * e], tri, sizeof tri);
            element_body[e] = element_body[e + 1] = 0;
            e += 2;
        }
    }
    for (int i = 0; i < NX; i++) {
        facets[2 * i] = id(i, 0);
        facets[2 * i + 1] = id(i + 1, 0);
        facet_tags[i] = TAG_BOTTOM;
        facets[2 * (NX + i)] = id(i, NY);
        facets[2 * (NX + i) + 1] = id(i + 1, NY);
        facet_tags[NX + i] = TAG_TOP;
    }
}

static SynMeshArrays mesh_arrays(void) {
    SynMeshArrays a = {
        .dimension = 2,
        .coords = coords,
        .coords_len = 2 * N_NODES,
        .elements = elements,
        .elements_len = 3 * N_ELEMENTS,
        .element_body = element_body,
        .element_body_len = N_ELEMENTS,
        .facets = facets,
        .facets_len = 2 * N_FACETS,
        .facet_tags = facet_tags,
        .facet_tags_len = N_FACETS,
        .young = &YOUNG,
        .young_len = 1,
        .poisson = &POISSON,
        .poisson_len = 1,
    };
    return a;
}

static void print_error(const char *what, SynStatus s) {
    char msg[512];
    size_t n = syn_last_error_message(msg, sizeof msg);
    fprintf(stderr, "%s: %s (%d): %s%s\n", what, syn_status_name(s), (int)s, msg, n >= sizeof msg ? "..." : "");
}

/* Calls that must succeed: print the message and leave if they do not. */
#define CHECK(call)                                  \
    do {                                             \
        SynStatus s_ = (call);                       \
        if (s_ != SYN_STATUS_OK) {                   \
            print_error(#call, s_);                  \
            exit(1);                                 \
        }                                            \
    } while (0)

/* Calls that must fail with a given status (and leave a message). */
static void expect(const char *what, SynStatus got, SynStatus want) {
    char msg[256];
    syn_last_error_message(msg, sizeof msg);
    if (got != want || msg[0] == '\0') {
        fprintf(stderr, "FAIL %-48s got %s, expected %s (message: \"%s\")\n", what, syn_status_name(got),
                syn_status_name(want), msg);
        failures++;
    } else {
        printf("ok   %-48s %s: %s\n", what, syn_status_name(got), msg);
    }
}

static int solve_punch(int n_ref, const double *reference) {
    SynMeshArrays arrays = mesh_arrays();
    SynModel *model = NULL;
    CHECK(syn_model_from_arrays(&arrays, &model));
    CHECK(syn_model_set_displacement(model, TAG_TOP, TOP[0], 2));
    const double point[2] = {0.0, 0.0}, normal[2] = {0.0, 1.0};
    size_t pair = 99;
    CHECK(syn_model_add_contact_plane(model, TAG_BOTTOM, point, normal, 2, FRICTION, &pair));

    printf("synovia %s: rounded punch on a rigid plane, %d nodes, %d triangles, friction %.1f\n", syn_version(),
           N_NODES, N_ELEMENTS, FRICTION);
    double worst = 0.0;
    for (int step = 0; step < 3; step++) {
        /* the prescribed motion changes between solves; the factorisation is reused */
        CHECK(syn_model_set_displacement(model, TAG_TOP, TOP[step], 2));
        if (step == 0)
            CHECK(syn_model_solve_static(model, TIMES[step]));
        else
            CHECK(syn_model_solve_step(model, TIMES[step]));
        double fn = 0.0, force[3];
        CHECK(syn_model_get_pair_force(model, pair, &fn, force));
        SynSolveInfo info;
        CHECK(syn_model_get_solve_info(model, &info));
        printf("step %d  t = %.1f  top = (%.3f, %.3f)  normal force %.17g  force (%.6g, %.6g)  iterations %zu  "
               "KKT %.2e\n",
               step, info.time, TOP[step][0], TOP[step][1], fn, force[0], force[1], info.iterations,
               info.kkt_residual);
        if (step < n_ref) {
            double rel = fabs(fn - reference[step]) / fabs(reference[step]);
            if (rel > worst) worst = rel;
            printf("         Rust API    %.17g  relative difference %.3e\n", reference[step], rel);
            if (!(rel <= 1e-12)) {
                fprintf(stderr, "FAIL step %d: C API force %.17g differs from the Rust API's %.17g (%.3e)\n", step,
                       fn, reference[step], rel);
                failures++;
            }
        }
    }

    /* contact pressures of the last step */
    size_t n = 0;
    CHECK(syn_model_num_contact_nodes(model, &n));
    int32_t *node = malloc(n * sizeof *node);
    double *xy = malloc(2 * n * sizeof *xy);
    double *p = malloc(n * sizeof *p);
    if (!node || !xy || !p) return 1;
    CHECK(syn_model_get_contact_nodes(model, n, NULL, node, xy, p));
    printf("contact nodes in contact (of %zu):\n     node        x        y     pressure\n", n);
    for (size_t r = 0; r < n; r++)
        if (p[r] > 0.0) printf("  %7d  %7.4f  %7.4f  %11.5g\n", node[r], xy[2 * r], xy[2 * r + 1], p[r]);
    free(node);
    free(xy);
    free(p);

    double *u = malloc(2 * N_NODES * sizeof *u);
    if (!u) return 1;
    CHECK(syn_model_get_displacements(model, u, 2 * N_NODES));
    printf("displacement of the bottom centre node: (%.6g, %.6g)\n", u[2 * id(NX / 2, 0)], u[2 * id(NX / 2, 0) + 1]);
    /* wrong buffer size, pair index out of range */
    expect("get_displacements with a short buffer", syn_model_get_displacements(model, u, 2 * N_NODES - 1),
           SYN_STATUS_SIZE_MISMATCH);
    free(u);
    double fn;
    expect("get_pair_force of pair 5", syn_model_get_pair_force(model, 5, &fn, NULL), SYN_STATUS_INDEX_OUT_OF_RANGE);
    expect("get_pair_force into NULL", syn_model_get_pair_force(model, 0, NULL, NULL), SYN_STATUS_NULL_POINTER);
    expect("solve_step back in time", syn_model_solve_step(model, 0.5), SYN_STATUS_INVALID_ARGUMENT);

    CHECK(syn_model_free(model));
    /* the handle is dead now */
    expect("solve with a freed handle", syn_model_solve_static(model, 0.0), SYN_STATUS_INVALID_HANDLE);
    expect("free a freed handle", syn_model_free(model), SYN_STATUS_INVALID_HANDLE);
    if (n_ref > 0) printf("largest relative difference to the Rust API: %.3e (limit 1e-12)\n", worst);
    return 0;
}

static void error_codes(void) {
    SynMeshArrays arrays = mesh_arrays();
    SynModel *model = (SynModel *)(uintptr_t)0x1;

    /* NULL pointers */
    expect("from_arrays(NULL, &model)", syn_model_from_arrays(NULL, &model), SYN_STATUS_NULL_POINTER);
    if (model != NULL) {
        fprintf(stderr, "FAIL the out-parameter was not set to NULL on failure\n");
        failures++;
    }
    expect("from_arrays(&arrays, NULL)", syn_model_from_arrays(&arrays, NULL), SYN_STATUS_NULL_POINTER);
    expect("from_scenario(NULL, &model)", syn_model_from_scenario(NULL, &model), SYN_STATUS_NULL_POINTER);
    SynMeshArrays no_coords = arrays;
    no_coords.coords = NULL;
    expect("from_arrays with coords NULL", syn_model_from_arrays(&no_coords, &model), SYN_STATUS_NULL_POINTER);

    /* wrong sizes and indices */
    int32_t saved = elements[7];
    elements[7] = N_NODES; /* one past the last node */
    expect("element node index out of range", syn_model_from_arrays(&arrays, &model), SYN_STATUS_INDEX_OUT_OF_RANGE);
    elements[7] = -3;
    expect("negative element node index", syn_model_from_arrays(&arrays, &model), SYN_STATUS_INDEX_OUT_OF_RANGE);
    elements[7] = saved;
    SynMeshArrays short_bodies = arrays;
    short_bodies.element_body_len = N_ELEMENTS - 1;
    expect("element_body count mismatch", syn_model_from_arrays(&short_bodies, &model), SYN_STATUS_SIZE_MISMATCH);
    SynMeshArrays odd = arrays;
    odd.coords_len = 2 * N_NODES - 1;
    expect("coords not a multiple of the dimension", syn_model_from_arrays(&odd, &model), SYN_STATUS_SIZE_MISMATCH);
    SynMeshArrays tags = arrays;
    tags.facet_tags_len = N_FACETS + 1;
    expect("facet_tags count mismatch", syn_model_from_arrays(&tags, &model), SYN_STATUS_SIZE_MISMATCH);
    element_body[0] = 1;
    expect("body id out of range", syn_model_from_arrays(&arrays, &model), SYN_STATUS_INDEX_OUT_OF_RANGE);
    element_body[0] = 0;
    SynMeshArrays dim = arrays;
    dim.dimension = 5;
    expect("dimension 5", syn_model_from_arrays(&dim, &model), SYN_STATUS_INVALID_ARGUMENT);
    expect("missing scenario file", syn_model_from_scenario("/nonexistent/scenario.toml", &model), SYN_STATUS_SCENARIO);

    /* invalid handles */
    SynModel *fake = (SynModel *)(uintptr_t)0xdeadbee0;
    expect("solve_static with a made-up handle", syn_model_solve_static(fake, 0.0), SYN_STATUS_INVALID_HANDLE);
    expect("free a made-up handle", syn_model_free(fake), SYN_STATUS_INVALID_HANDLE);
    expect("solve_static(NULL)", syn_model_solve_static(NULL, 0.0), SYN_STATUS_NULL_POINTER);
    if (syn_model_free(NULL) != SYN_STATUS_OK) {
        fprintf(stderr, "FAIL syn_model_free(NULL) is not a no-op\n");
        failures++;
    }

    /* conditions on a live model */
    CHECK(syn_model_from_arrays(&arrays, &model));
    const double v3[3] = {0.0, 0.0, 0.0};
    expect("3 displacement components in 2D", syn_model_set_displacement(model, TAG_TOP, v3, 3),
           SYN_STATUS_SIZE_MISMATCH);
    expect("displacement value NULL", syn_model_set_displacement(model, TAG_TOP, NULL, 2), SYN_STATUS_NULL_POINTER);
    expect("unknown part tag 42", syn_model_clamp(model, 42), SYN_STATUS_INVALID_ARGUMENT);
    expect("contact kind 9", syn_model_add_contact(model, TAG_BOTTOM, TAG_TOP, 9, 0.0, NULL),
           SYN_STATUS_INVALID_ARGUMENT);
    CHECK(syn_model_clamp(model, TAG_TOP));
    expect("pressure on a clamped part", syn_model_set_pressure(model, TAG_TOP, 1.0), SYN_STATUS_MODEL_REJECTED);
    static double u[2 * N_NODES];
    expect("results before a solve", syn_model_get_displacements(model, u, 2 * N_NODES), SYN_STATUS_NO_SOLUTION);
    CHECK(syn_model_free(model));
}

int main(int argc, char **argv) {
    double reference[3];
    int n_ref = argc - 1;
    if (n_ref != 0 && n_ref != 3) {
        fprintf(stderr, "usage: %s [F0 F1 F2]\n", argv[0]);
        return 2;
    }
    for (int i = 0; i < n_ref; i++) {
        char *end = NULL;
        reference[i] = strtod(argv[i + 1], &end);
        if (end == argv[i + 1] || *end != '\0') {
            fprintf(stderr, "not a number: %s\n", argv[i + 1]);
            return 2;
        }
    }
    build_mesh();
    if (solve_punch(n_ref, reference) != 0) return 1;
    error_codes();
    if (failures > 0) {
        fprintf(stderr, "%d check(s) failed\n", failures);
        return 1;
    }
    printf("all C API checks passed\n");
    return 0;
}
