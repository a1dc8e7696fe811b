/* What the files of the rain runoff test program share (test_rain_runoff.c
 * has main and the subtests' table): the includes, the context, the
 * helpers, and every subtest and helper one file defines for another. */
#ifndef TEST_RAIN_RUNOFF_H
#define TEST_RAIN_RUNOFF_H

/* One pair of CHECK counters for the whole program (gr_test.h). */
#define GR_TEST_SHARED_COUNTERS
#include "graupel/cl_runtime.h"
#include "graupel/rain_runoff.h"
#include "gr_test.h"
#include "gr_test_team.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The context every subtest uses (setup makes it). */
extern gr_context *ctx;

/* The names of the flow models, by gr_flow_model. */
extern const char *const model_names[2];

/* A progress callback's record (on_progress). */
typedef struct progress_log {
  int calls, increasing, stop_at;
  double last, stopped_at_wall;
} progress_log;

/* test_rain_runoff.c */
double hash01(int i, int j, uint32_t seed);
size_t cells_of(const gr_grid *g);
float *alloc_field(const gr_grid *g, int components);
void set_edges(gr_rain_runoff_params *p, gr_boundary kind);
gr_rain_runoff_params params_with(double rain, double perm, gr_boundary boundary);
gr_rain_runoff *make_sim(const gr_grid *g, const gr_rain_runoff_params *p, const float *b,
                         const float *depth);
float *get(gr_rain_runoff *s, const gr_grid *g, gr_field f);
gr_rain_runoff_ledger ledger(gr_rain_runoff *s);
void run_stable(gr_rain_runoff *s, int chunks, int chunk);
int bad_depths(const float *h, size_t n);
int bad_values(const float *v, size_t n);
double sum_of(const float *v, size_t n);

/* test_rain_runoff_li.c */
void test_rain_gain(void);
void test_infiltration(void);
gr_rain_runoff *make_bumpy(const gr_grid *g, gr_boundary boundary);
void test_conservation(void);
float *make_bowl(const gr_grid *g, double a);
void test_bowl(void);
void test_tilted_plane(void);
void test_tilted_plane_uncapped(void);
void test_symmetry(void);
void test_determinism(void);
void test_lake_at_rest(void);
void test_column(void);
void test_advance_dry_start(void);
void test_advance(void);
void test_reset(void);
void test_long_run(int steps);

/* test_rain_runoff_api.c */
int has(const char *text, const char *word);
void test_devices_agree(void);
void test_errors(void);
double wall_now(void);
int on_progress(void *user, double time);
void test_memcheck(void);
void test_long_run_default(void);
void test_sw_devices_agree(void);
void test_param_table(void);
int same_bits(gr_rain_runoff *a, gr_rain_runoff *b, const gr_grid *g, const char *what);
void test_checkpoint(void);
void test_checkpoint_v6(void);
void test_progress(void);
void test_shared_context(void);
void test_ledger_fixed_point(void);

/* test_rain_runoff_maps.c */
float *get_map(gr_rain_runoff *s, const gr_grid *g, gr_rain_runoff_map m);
void test_maps_every_step(void);
void test_maps_wet_spells(void);
void test_maps_arrival(void);
void test_maps_hazard(void);
void test_maps_reset(void);
void test_gauges(void);

/* test_rain_runoff_pieces.c: the launch paths the pieces tests take
 * (gr_rain_runoff_set_sw_fused, gr_rain_runoff_set_fused; -1: the
 * default). */
extern int piece_sw_fused, piece_fused;
void test_pieces_x(void);
void test_pieces_y(void);
void test_advance_pieces_x(void);
void test_advance_pieces_y(void);
void test_advance_pieces_abort(void);
void test_piece_checkpoint(void);
void test_pieces_wet_spells(void);
void test_memcheck_subset(void);
void test_sw_pieces_x(void);
void test_sw_pieces_y(void);
void test_sw_advance_pieces_x(void);
void test_sw_advance_pieces_y(void);
void test_sw_piece_checkpoint(void);
void run_with_edges(void (*test)(void));
void test_pieces_edges_x(void);
void test_pieces_edges_y(void);
void test_advance_pieces_edges_y(void);
void test_sw_pieces_edges_x(void);
void test_sw_pieces_edges_y(void);
void test_sw_advance_pieces_edges_x(void);

/* test_rain_runoff_sw.c */
void test_sw_ritter(void);
void test_sw_stoker(void);
void test_sw_lake_at_rest(void);
void test_sw_conservation(void);
void test_sw_determinism(void);
void test_sw_thacker(void);
void test_sw_bump(void);
void test_sw_tilted_plane(void);
void test_sw_inputs(void);
void test_sw_thin_films(void);

/* test_rain_runoff_paths.c */
void test_sw_pieces_paths(void);
void test_sw_fused(void);
void test_pieces_paths(void);
void test_li_fused(void);
void test_device_forms(void);
void test_specialised(void);

/* test_rain_runoff_boundaries.c */
gr_rain_runoff_params edge_params(int m);
void test_edges_wall(void);
void test_edges_level(void);
void test_edges_transmissive(void);
void test_edges_mirror(void);

/* test_rain_runoff_inputs.c */
void test_inflow_point(void);
void test_inflow_edge(void);
void test_inflow_errors(void);
void test_hyetograph(void);
void test_manning_map(void);
void test_no_data(void);

#endif
