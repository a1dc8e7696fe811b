/* Private to the core library (no symbol here is exported): the checks
 * every core's parameter validation shares. */
#ifndef GRAUPEL_RUNTIME_INTERNAL_H
#define GRAUPEL_RUNTIME_INTERNAL_H

#include "graupel/graupel.h"
#include "graupel/runtime.h"

#include <stddef.h>
#include <stdint.h>

/* How gr_params_check_table words a refused row. */
typedef enum gr_param_wording {
  /* gr_param_explain's: "<what>: <Property> must lie between <min> and <max>
   * <unit> (got <value> <unit>).", the value in the user's unit. */
  GR_PARAM_SAY_GOT,
  /* "<what>: <Property><hint> is <value> but must ...", every number %.15g
   * and the value the core's; the three differ only in which rows say "a
   * whole number": */
  GR_PARAM_SAY_IS_WHOLE_FIRST, /* every whole-number row, from its first accepted value */
  GR_PARAM_SAY_IS_OPEN_FIRST,  /* whole-number rows with a closed minimum */
  GR_PARAM_SAY_IS_RANGE        /* none: an open minimum or the range */
} gr_param_wording;

/* Checks values[k] against row rows[k] of table (row k when rows is NULL),
 * k = 0 .. n - 1, in that order: GR_OK when every row accepts its value
 * (gr_param_accepts); otherwise GR_ERR_INVALID_ARGUMENT with the first
 * refused row's sentence in msg (when msg and msg_len), worded as wording
 * says, what its start ("Invalid rain runoff parameters") and hints (NULL,
 * or per table row NULL or the words after the property) its additions. */
gr_status gr_params_check_table(const gr_param_bound *table, const int *rows, int n,
                                const double *values, const char *what, const char *const *hints,
                                gr_param_wording wording, char *msg, size_t msg_len);

/* "<what>: no parameters were given." in msg (when msg and msg_len);
 * returns GR_ERR_INVALID_ARGUMENT. */
gr_status gr_params_missing(const char *what, char *msg, size_t msg_len);

/* The piece contract of the cores that split a domain along x and y
 * (graupel.h): ring[4] (west, east, south, north) gets `need` toward each
 * side with a neighbour, 0 elsewhere; a piece with any neighbour must have
 * ghost == need and at least need points across each ring's axis. core
 * names the simulation ("rain runoff"), need_for follows "a ghost ring of
 * <need> points" (" for FlowModel 1", or ""). With origin_checked, i0 and
 * j0 are also checked to be 0 or more, and 0 along an axis not split.
 * Otherwise a sentence goes to msg (when msg and msg_len). */
gr_status gr_grid_piece_check(const gr_grid *g, const char *core, int need, const char *need_for,
                              int origin_checked, int ring[4], char *msg, size_t msg_len);

/* The most steps a saved state may count: every core adds to its count as
 * it steps (an int64; 2^53 also keeps it exact as the double the ledgers
 * give). */
#define GR_STATE_MAX_STEPS (INT64_C(1) << 53)

/* A part of a saved state (gr_<core>_state_load's bytes) that
 * gr_state_check reads: count values from byte offset, float32 ('f'),
 * float64 ('d') or int64 ('l'), each finite and from lo to hi. */
typedef struct gr_state_part {
  const char *name; /* what it holds, for the sentence: "water depth" */
  size_t offset, count;
  char kind;
  double lo, hi;
} gr_state_part;

/* The check every core's state_load makes before it writes any of the
 * bytes to the device, so that a refused state leaves the simulation as it
 * was: every value of every part (which the caller has checked lie within
 * the bytes; any alignment) finite and within its range. GR_OK, or
 * GR_ERR_FORMAT with the sentence "The <core> state's <name> has the value
 * <v> at entry k of n, where every value is finite [and from lo to hi]:
 * the bytes are damaged; pass the bytes gr_<fn>_state_save wrote." as the
 * thread's error (gr_set_error). core names the simulation ("rain
 * runoff"), fn its functions ("rain_runoff"). */
gr_status gr_state_check(const char *core, const char *fn, const void *bytes,
                         const gr_state_part *parts, int nparts);

#endif
