/* Snow accumulation core, host side: what the host files share, and
 * nothing of the public API (graupel/snow_accumulation.h): the limits and
 * checkpoint layout, the parameter table's rows, the handle's state, the
 * kernel arguments' helpers, and the private functions of
 * snow_accumulation.c (parameters, device arrays, life cycle),
 * snow_accumulation_objects.c, snow_accumulation_view.c (the direction and
 * the exposure view), snow_accumulation_step.c and
 * snow_accumulation_pieces.c (rows, halos, checkpoints). */
#ifndef GRAUPEL_SNOW_ACCUMULATION_INTERNAL_H
#define GRAUPEL_SNOW_ACCUMULATION_INTERNAL_H

#include "graupel/snow_accumulation.h"
#include "graupel/cl_runtime.h"
#include "graupel/reduce.h"
#include "snow_accumulation_shared.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define GR_SNAC_MAX_ELEVATION 1.0e6
#define GR_SNAC_MAX_DEPTH 1.0e4
#define GR_SNAC_MIN_DT 1.0e-6
#define GR_SNAC_MAX_DT 86400.0
#define GR_SNAC_PI 3.14159265358979323846
/* Checkpoints: "GSA1". */
#define GR_SNAC_STATE_MAGIC 0x31415347u
#define GR_SNAC_STATE_VERSION 4u /* 3: a piece's j0 and the initial snow per row; 4: per face */
/* Per-point arrays of the state: depth, its low part, fallen and shed
 * snow (pairs) and the exposure. */
#define GR_SNAC_ARRAYS 7
/* The largest accumulation texture, texels across. */
#define GR_SNAC_MAX_TEXTURE 4096
/* The step waits for the device every this many steps, so that a long
 * loop of steps does not queue without bound. */
#define GR_SNAC_SYNC_EVERY 8

enum {
  GR_SNAC_P_FLUTTER,
  GR_SNAC_P_RATE,
  GR_SNAC_P_AMPLITUDE,
  GR_SNAC_P_SCALE,
  GR_SNAC_P_SEED,
  GR_SNAC_P_RESOLUTION,
  GR_SNAC_P_BLUR,
  GR_SNAC_P_DILATION,
  GR_SNAC_P_MAX_DEPTH,
  GR_SNAC_P_STABILITY,
  GR_SNAC_P_DENSITY,
  GR_SNAC_P_TEXTURE,
  GR_SNAC_P_COUNT
};

struct gr_snow_accumulation {
  gr_context *ctx;
  gr_grid grid;
  gr_snow_accumulation_params params;
  cl_kernel raster_terrain, raster_objects, exposure_k, noise_k, slope_k, blur, dilate, apply,
      objects_k, reduce, surface, row_sums, object_surface, object_exposure;
  /* A piece (graupel.h's contract, "Pieces of a split domain"): grid.nx,
   * grid.ny count the local arrays (own rows and rings); the domain has
   * gnx x gny points, local row 0 is its row row0, the own rows are local
   * rows ring_s .. ring_s + own_ny - 1. A whole grid: no rings, row0 0. */
  int gnx, gny, row0, own_ny, ring_s, ring_n;
  gr_allreduce_fn allreduce; /* NULL: this simulation is the whole domain */
  void *allreduce_user;
  gr_halo_exchange_fn halo_exchange;
  void *halo_user;
  /* The ledger's initial grid snow per own row (m, per unit area), and the
   * objects' (m^3): see "Pieces" in the header for why per row. */
  double *init_rows, initial_objects;
  /* Per local row, the row sums' 6 floats; per face or sample, the
   * snow surface under it or its exposure (pieces only). */
  cl_mem rows_buf, o_surface;
  size_t o_surface_cap;
  /* Pieces, the steps with the terrain in the view: which view rows the
   * pieces combine (1) this step, and whether the objects' exposure is
   * combined per point instead of through the view rows under them. */
  unsigned char *view_rows;
  double *view_cover;
  size_t view_rows_cap;
  int objects_by_point;
  /* The grid: ground, initial snow, the state pairs, exposure, growth and
   * a scratch array, the blur weights and the view. */
  cl_mem ground, depth0, arr[GR_SNAC_ARRAYS], growth, scratch, weights, view;
  /* The grid's noise and what it was made for (seed, then the lattice's
   * origin and spacing); noise_made 0 until the first step. */
  cl_mem noise;
  int noise_made;
  cl_uint noise_seed;
  float noise_key[4];
  size_t view_cap; /* ints */
  /* The objects: world triangles, per face (triangle) the world position
   * of its centroid and its normal, the noise coordinates, the area and
   * the state arrays: snow lives on the faces (object o's are trifirst[o]
   * .. trifirst[o + 1] - 1), the mesh points show it (gr_snac_points). */
  int nobjects, nv, ntri;
  int first[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1], nverts[GR_SNOW_ACCUMULATION_MAX_OBJECTS];
  gr_mesh_memo memo[GR_SNOW_ACCUMULATION_MAX_OBJECTS]; /* each object's mesh as last checked */
  cl_mem o_tri, o_pos, o_nrm, o_local, o_area, o_arr[GR_SNAC_ARRAYS];
  /* Accumulation textures: per object its size (0: none) and UVs, its
   * samples (first .. first + count - 1 of the sample arrays) and per
   * sample its texel, triangle and barycentric weights; the samples'
   * world positions (absolute) and the device arrays, like the mesh
   * points'. hlocal: the mesh points in their objects' frames. */
  int tsize[GR_SNOW_ACCUMULATION_MAX_OBJECTS], tfirst[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  int trifirst[GR_SNOW_ACCUMULATION_MAX_OBJECTS + 1];
  float *tuv[GR_SNOW_ACCUMULATION_MAX_OBJECTS];
  int ns, tobjects, *stexel, *stri;
  float *sbar, *hlocal;
  double *sv;
  cl_mem t_pos, t_nrm, t_local, t_arr[GR_SNAC_ARRAYS];
  double *hv;                /* world vertices, 3 per mesh point, absolute */
  int *ht;                   /* triangles, indices into hv */
  float *hnrm;               /* world normals, 3 per face */
  float *harea;              /* face areas (the object's own frame) */
  double ob_lo[3], ob_hi[3]; /* the objects' world box */
  gr_reduction red, red_slope;
  double zref, bmin, bmax, init_max, snow_bound;
  double time, retired_fall, retired_shed, dropped;
  long long steps;
  gr_progress_fn progress;
  void *progress_user;
  int aborted;
  int timing;
  double t_mark;
  gr_snow_accumulation_timing tm;
  char error[1024];
};

#define GR_SNAC_KEEP_ERROR(s, st) gr_error_keep((s)->error, sizeof((s)->error), (st))

/* A named kernel argument. */
typedef struct gr_snac_arg {
  const char *name;
  size_t size;
  const void *value;
} gr_snac_arg;

#define GR_SNAC_MEM(name, m)                                                                       \
  { (name), sizeof(cl_mem), &(m) }
#define GR_SNAC_VAL(name, v)                                                                       \
  { (name), sizeof(v), &(v) }

/* snow_accumulation.c: the parameter table (the one place each range is
 * written) first. */
extern const gr_param_bound gr_snac_bounds[GR_SNAC_P_COUNT];
gr_status gr_snac_args(gr_snow_accumulation *s, cl_kernel k, const gr_snac_arg *args, size_t n);
double gr_snac_now_ms(void);
gr_status gr_snac_mark(gr_snow_accumulation *s, double *acc);
size_t gr_snac_cells(const gr_snow_accumulation *s);
gr_status gr_snac_fill(gr_snow_accumulation *s, cl_mem buf, size_t n, float value);
gr_status gr_snac_sums(gr_snow_accumulation *s, int objects, int first, int n,
                       double sums[GR_SNAC_SUMS]);
void gr_snac_release_objects(gr_snow_accumulation *s);
gr_status gr_snac_upload_geometry(gr_snow_accumulation *s);

/* snow_accumulation_objects.c */
void gr_snac_release_textures(cl_mem *pos, cl_mem *nrm, cl_mem *local, cl_mem *arr);

/* snow_accumulation_view.c */
/* The view of one step: where rays along d cross z = 0 (tau), the extent
 * of the terrain's and the objects' crossings, and the texel. */
typedef struct gr_snac_view {
  float tau_x, tau_y, qx0, qy0, inv_texel, texel;
  int vw, vh;
} gr_snac_view;

/* This step's unit snow direction: SnowDirection turned by up to Flutter. */
void gr_snac_direction(const gr_snow_accumulation *s, double d[3]);
/* The view of a step along d. */
void gr_snac_view_of(const gr_snow_accumulation *s, const double d[3], gr_snac_view *v);
/* The view rows [lo, hi] a piece draws the objects into when the views are
 * combined: its band (the rows its own grid points read), from row 0 on
 * for the first piece and up to the last row for the last, so that every
 * row has the objects in at least one piece's view. */
void gr_snac_object_rows(const gr_snow_accumulation *s, const gr_snac_view *v, int *lo, int *hi);
/* A piece's view combined with the other pieces' where it matters, and
 * with objects_by_point the faces' and samples' exposure in the combined
 * view into s->o_surface (faces first, then samples), in one allreduce
 * (snow direction dir). Waits. */
gr_status gr_snac_view_reduce(gr_snow_accumulation *s, const gr_snac_view *v, const float dir[3]);
/* This piece's exposure of nv faces (or samples) at pos, nrm from its own
 * view into s->o_surface from first on. Enqueues only. */
gr_status gr_snac_object_exposure(gr_snow_accumulation *s, cl_mem pos, cl_mem nrm, cl_int nv,
                                  cl_int first, const gr_snac_view *v, const float dir[3]);
/* The snow surface under nv faces (or samples) at pos, nrm into
 * s->o_surface, over the pieces. Waits. */
gr_status gr_snac_object_surface(gr_snow_accumulation *s, cl_mem pos, cl_mem nrm, cl_int nv,
                                 float texel);

/* snow_accumulation_pieces.c */
gr_status gr_snac_piece_check(const gr_grid *g, const gr_snow_accumulation_params *p, int *ring_s,
                              int *ring_n, char *msg, size_t len);
int gr_snac_pieced(const gr_snow_accumulation *s);
gr_status gr_snac_allreduce(gr_snow_accumulation *s, double *v, size_t n, gr_reduce_op op);
gr_status gr_snac_rows(gr_snow_accumulation *s, double *out);
gr_status gr_snac_grid_sums(gr_snow_accumulation *s, double sums[4]);

#endif
