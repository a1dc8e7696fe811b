/* graupel-bench --core snow_deformation: a closed sphere of radius 1 m
 * (SPHERE_STACKS x SPHERE_SLICES, 9936 triangles, the target's "one object
 * of 10^4 triangles") ploughs at 2 m/s through 0.5 m of snow on flat ground,
 * its lowest point 0.2 m above the ground, 1/60 s steps; the grid spans 20 m
 * whatever its size (SlumpSpeed the default, 2 m/s, unless
 * GRAUPEL_BENCH_SLUMP_SPEED says otherwise). The report times the stages of ten more steps
 * separately and, in the same run, plain 5-point stencil passes over the
 * grid (the yardstick of the target). As pieces (--devices) each keeps a
 * ring of SNOW_BENCH_RING points, 4 talus launches between exchanges
 * (GRAUPEL_BENCH_SNOW_RING: another multiple of GR_SNOW_DEFORMATION_GHOST,
 * 8 for the core's narrow ring). GRAUPEL_BENCH_SNOW_BLOCKED=1 runs the
 * talus in blocked launches (a GPU's way, exchanges and all) on any device,
 * 0 in one launch an iteration. GRAUPEL_BENCH_SNOW_Y: the line the sphere
 * ploughs along (m, 0..20; default 10, on the cut between two pieces; 5
 * keeps it inside the first of two). */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define SPHERE_STACKS 70
#define SPHERE_SLICES 72
#define SPHERE_RADIUS 1.0
#define BENCH_PI 3.14159265358979323846
#define SNOW_BENCH_RING (4 * GR_SNOW_DEFORMATION_GHOST)

typedef struct snow_deformation_bench {
  gr_snow_deformation *sim;
  gr_mesh mesh;
  float *vertices;
  int *triangles;
  int n;
  double x, y, v[3], dt, x_end;
} snow_deformation_bench;

/* A latitude-longitude sphere: the poles and SPHERE_STACKS - 1 rings. */
static int snow_deformation_sphere(snow_deformation_bench *b) {
  const int st = SPHERE_STACKS, sl = SPHERE_SLICES;
  int nv = 2 + (st - 1) * sl, nt = 2 * sl * (st - 1);
  b->vertices = malloc((size_t)nv * 3 * sizeof(float));
  b->triangles = malloc((size_t)nt * 3 * sizeof(int));
  if (!b->vertices || !b->triangles)
    return 0;
  float *v = b->vertices;
  v[0] = v[1] = 0.0f;
  v[2] = (float)SPHERE_RADIUS;
  for (int a = 1; a < st; ++a)
    for (int c = 0; c < sl; ++c) {
      double th = BENCH_PI * a / st, ph = 2.0 * BENCH_PI * c / sl;
      float *p = v + 3 * (1 + (a - 1) * sl + c);
      p[0] = (float)(SPHERE_RADIUS * sin(th) * cos(ph));
      p[1] = (float)(SPHERE_RADIUS * sin(th) * sin(ph));
      p[2] = (float)(SPHERE_RADIUS * cos(th));
    }
  float *q = v + 3 * (nv - 1);
  q[0] = q[1] = 0.0f;
  q[2] = (float)-SPHERE_RADIUS;
  int *t = b->triangles, k = 0;
#define RING(a, c) (1 + ((a)-1) * sl + ((c) % sl))
  for (int c = 0; c < sl; ++c) {
    t[k++] = 0, t[k++] = RING(1, c), t[k++] = RING(1, c + 1);
    t[k++] = nv - 1, t[k++] = RING(st - 1, c + 1), t[k++] = RING(st - 1, c);
  }
  for (int a = 1; a < st - 1; ++a)
    for (int c = 0; c < sl; ++c) {
      t[k++] = RING(a, c), t[k++] = RING(a + 1, c), t[k++] = RING(a + 1, c + 1);
      t[k++] = RING(a, c), t[k++] = RING(a + 1, c + 1), t[k++] = RING(a, c + 1);
    }
#undef RING
  b->mesh.vertices = v;
  b->mesh.nvertices = nv;
  b->mesh.triangles = t;
  b->mesh.ntriangles = k / 3;
  return 1;
}

static void snow_deformation_teardown(void *state) {
  snow_deformation_bench *b = state;
  if (b) {
    gr_snow_deformation_destroy(b->sim);
    free(b->vertices);
    free(b->triangles);
  }
  free(b);
}

static gr_status snow_deformation_place(snow_deformation_bench *b) {
  double *T = b->mesh.transform;
  for (int k = 0; k < 16; ++k)
    T[k] = (k % 5 == 0) ? 1.0 : 0.0;
  T[12] = b->x;
  T[13] = b->y;
  T[14] = 0.2 + SPHERE_RADIUS;
  return gr_snow_deformation_set_objects(b->sim, &b->mesh, 1, b->v);
}

/* The pieces' ring: SNOW_BENCH_RING, or GRAUPEL_BENCH_SNOW_RING's (the
 * core refuses a width it does not take). */
static int snow_deformation_ring(void) {
  const char *ring = getenv("GRAUPEL_BENCH_SNOW_RING");
  return ring && *ring ? atoi(ring) : SNOW_BENCH_RING;
}

/* Rows j0 .. j0 + ny - 1 of the n by n set-up (the whole grid for j0 = 0,
 * ny = n), with a ring toward each neighbouring strip: the snow is the
 * parameters' uniform cover on flat ground, and every piece sets the same
 * sphere, which ploughs along y = 10 m, across the middle strips' edges
 * (GRAUPEL_BENCH_SNOW_Y: another line). */
static gr_status snow_deformation_setup_piece(gr_context *ctx, int n, int j0, int ny,
                                              const gr_bench_link *link, void **state) {
  double d = 20.0 / (n > 1 ? n - 1 : 1);
  int whole = j0 == 0 && ny == n;
  gr_grid g = {.nx = n, .ny = ny, .dx = d, .dy = d, .j0 = j0};
  if (!whole) {
    g.global_nx = n;
    g.global_ny = n;
    g.ghost = snow_deformation_ring();
  }
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  /* GRAUPEL_BENCH_SLUMP_SPEED: another SlumpSpeed (m/s; 0: instant relaxation) */
  const char *slump = getenv("GRAUPEL_BENCH_SLUMP_SPEED");
  if (slump && *slump)
    p.slump_speed = atof(slump);
  snow_deformation_bench *b = calloc(1, sizeof(*b));
  if (!b)
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  b->n = n;
  if (!snow_deformation_sphere(b)) {
    snow_deformation_teardown(b);
    return gr_set_error(ctx, GR_ERR_OUT_OF_MEMORY, "Out of host memory.");
  }
  b->x = 2.0;
  b->x_end = 18.0;
  const char *y = getenv("GRAUPEL_BENCH_SNOW_Y");
  b->y = y && *y ? atof(y) : 10.0;
  if (!(b->y >= 0.0 && b->y <= 20.0)) {
    snow_deformation_teardown(b);
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "GRAUPEL_BENCH_SNOW_Y is %s: it takes a line between 0 and 20 m.", y);
  }
  b->v[0] = 2.0;
  b->dt = 1.0 / 60.0;
  gr_status st = gr_snow_deformation_create(ctx, &g, &p, &b->sim);
  /* GRAUPEL_BENCH_SNOW_BLOCKED: 1, the talus in blocked launches (a GPU's
   * way) on any device; 0, one launch an iteration (a CPU's) */
  const char *blocked = getenv("GRAUPEL_BENCH_SNOW_BLOCKED");
  if (st == GR_OK && blocked && *blocked)
    gr_snow_deformation_set_blocked(b->sim, atoi(blocked));
  if (st == GR_OK && !whole && link) {
    gr_snow_deformation_set_allreduce(b->sim, link->allreduce, link->allreduce_user);
    gr_snow_deformation_set_halo_exchange(b->sim, link->exchange, link->exchange_user);
  }
  if (st == GR_OK)
    st = snow_deformation_place(b);
  if (st != GR_OK) {
    snow_deformation_teardown(b);
    return st;
  }
  *state = b;
  return GR_OK;
}

static gr_status snow_deformation_setup(gr_context *ctx, int n, void **state) {
  return snow_deformation_setup_piece(ctx, n, 0, n, NULL, state);
}

/* The step waits (its per-object totals are read back): the bench times
 * whole steps, which is what a caller pays. */
static gr_status snow_deformation_step(void *state) {
  snow_deformation_bench *b = state;
  b->x += b->v[0] * b->dt;
  if (b->x > b->x_end)
    b->x = 2.0;
  gr_status st = snow_deformation_place(b);
  if (st == GR_OK)
    st = gr_snow_deformation_step(b->sim, b->dt);
  return st;
}

static gr_status snow_deformation_report(void *state, gr_context *ctx) {
  snow_deformation_bench *b = state;
  gr_snow_deformation_ledger l;
  gr_snow_deformation_timing tm;
  double f[3], a, stencil = 0.0;
  const int timed = 10;
  gr_status st = gr_snow_deformation_ledger_get(b->sim, &l);
  if (st == GR_OK)
    st = gr_snow_deformation_object_forces(b->sim, f, &a, 1);
  if (st == GR_OK)
    printf("snow_deformation: %lld steps; talus iterations in the last %d; mass balance %.3g of "
           "the snow; force %.4g N on %.4g m^2; %d triangles\n",
           l.steps, l.relax_iterations, fabs(l.balance_error) / l.initial_mass, f[0], a,
           b->mesh.ntriangles);
  /* The stages, each waited for (so their sum is a little above a step). */
  gr_snow_deformation_set_timing(b->sim, 1);
  for (int k = 0; st == GR_OK && k < timed; ++k)
    st = snow_deformation_step(b);
  if (st == GR_OK)
    st = gr_snow_deformation_timing_get(b->sim, &tm);
  gr_snow_deformation_set_timing(b->sim, 0);
  /* Setting the objects (the host's part of a step: the mesh check, its
   * triangles to the grid's frame, their upload), after the device is idle. */
  double place_ms = 0.0;
  if (st == GR_OK)
    st = gr_finish(ctx);
  for (int k = 0; st == GR_OK && k < timed; ++k) {
    double t0 = gr_bench_now_s();
    st = snow_deformation_place(b);
    if (st == GR_OK)
      st = gr_finish(ctx);
    place_ms += (gr_bench_now_s() - t0) * 1e3 / timed;
  }
  if (st == GR_OK)
    st = gr_bench_stencil_ms(ctx, b->n, b->n, &stencil);
  if (st == GR_OK) {
    double q = 1.0 / (double)tm.steps;
    double total =
        (tm.raster_ms + tm.press_ms + tm.contour_ms + tm.distribution_ms + tm.relax_ms) * q;
    printf("snow_deformation stages (ms/step over %lld steps): raster %.3f, overlap+compression "
           "%.3f, contour %.3f, distribution %.3f, relaxation %.3f (%.1f iterations/step, %.3f "
           "ms each); total %.3f; the objects set (host, waited for) %.3f\n",
           tm.steps, tm.raster_ms * q, tm.press_ms * q, tm.contour_ms * q, tm.distribution_ms * q,
           tm.relax_ms * q, (double)tm.relax_iterations * q,
           tm.relax_iterations ? tm.relax_ms / (double)tm.relax_iterations : 0.0, total, place_ms);
    printf("snow_deformation: 5-point stencil pass %.4f ms at %d x %d: a step costs %.1f passes "
           "(the target at 1024^2: under 30)\n",
           stencil, b->n, b->n, stencil > 0.0 ? total / stencil : 0.0);
  }
  return st;
}

/* ------------------------------------------------------------ as pieces */

static gr_status snow_deformation_halo_size(void *state, int side, size_t *bytes) {
  return gr_snow_deformation_halo_size(((snow_deformation_bench *)state)->sim, side, bytes);
}

static gr_status snow_deformation_halo_get(void *state, int side, void *host, size_t bytes) {
  return gr_snow_deformation_halo_get(((snow_deformation_bench *)state)->sim, side, host, bytes);
}

static gr_status snow_deformation_halo_set(void *state, int side, const void *host, size_t bytes) {
  return gr_snow_deformation_halo_set(((snow_deformation_bench *)state)->sim, side, host, bytes);
}

_Static_assert((int)GR_SNOW_DEFORMATION_SOUTH == (int)GR_BENCH_SOUTH &&
                   (int)GR_SNOW_DEFORMATION_NORTH == (int)GR_BENCH_NORTH,
               "bench.h's sides are the core's");

static const gr_field verify_fields[] = {GR_FIELD_SNOW_DEPTH, GR_FIELD_SNOW_DENSITY,
                                         GR_FIELD_SNOW_SURFACE, GR_FIELD_OVERLAP, GR_FIELD_CONTACT};

static gr_status snow_deformation_output(void *state, int i, const char **name, int *components,
                                         float *host) {
  *name = gr_field_name(verify_fields[i]);
  *components = 1;
  return host ? gr_snow_deformation_get_field(((snow_deformation_bench *)state)->sim,
                                              verify_fields[i], host)
              : GR_OK;
}

static gr_status snow_deformation_summary(void *state, char *line, size_t len) {
  snow_deformation_bench *b = state;
  gr_snow_deformation_ledger l;
  gr_status st = gr_snow_deformation_ledger_get(b->sim, &l);
  if (st == GR_OK)
    snprintf(line, len,
             "snow_deformation: %lld steps; %.6g m^3 of snow, %.6g m^3 compressed; mass balance "
             "%.3g of the snow",
             l.steps, l.snow_volume, l.compressed_volume, fabs(l.balance_error) / l.initial_mass);
  return st;
}

static const char *snow_deformation_last_error(void *state) {
  return gr_snow_deformation_last_error(((snow_deformation_bench *)state)->sim);
}

static const gr_bench_split split = {
    snow_deformation_setup_piece, snow_deformation_ring,
    snow_deformation_halo_size,   snow_deformation_halo_get,
    snow_deformation_halo_set,    (int)(sizeof(verify_fields) / sizeof(verify_fields[0])),
    snow_deformation_output,      snow_deformation_summary,
    snow_deformation_last_error,  NULL};

/* Per point and step, roughly: raster writes U (4 B), overlap reads 3 and
 * writes 1 array, contour reads D and writes cw, the reduction reads 6, the
 * apply reads 6 and writes 5, and each talus iteration reads 4 and writes 4
 * arrays (twice the rate pass's). Counted without talus iterations. */
static const gr_bench_core bench = {
    "a box ploughing through snow: raster, press, contour, distribution, talus (seed 000)",
    snow_deformation_setup,
    snow_deformation_step,
    snow_deformation_teardown,
    96.0,
    snow_deformation_report,
    &split};

const gr_bench_core *gr_bench_snow_deformation(void) {
  return &bench;
}
