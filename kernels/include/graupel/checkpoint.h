/**
 * @file checkpoint.h
 * @brief The checkpoint manifest: the JSON file that names a checkpoint's pieces.
 *
 * A simulation filter's CheckpointFile writes one piece per rank (its output
 * with the core's state bytes, gr_<core>_state_save) and then this manifest
 * beside them, which a RestartFile names. The text, as gr_checkpoint_format
 * writes it (any order of keys, any JSON whitespace reads the same):
 *
 *     {
 *       "format": "graupel-checkpoint",
 *       "version": 1,
 *       "simulation": "Rain Runoff",
 *       "class": "vtkRainRunoffFilter",
 *       "output_index": 4,
 *       "time": 40.0,
 *       "output_interval": 10.0,
 *       "steps": 812.0,
 *       "grid": [40, 104],
 *       "split": true,
 *       "ranks": 2,
 *       "pieces": [
 *         {"rank": 0, "rows": [0, 51], "file": "run.4.0.vti", "bytes": 70448},
 *         {"rank": 1, "rows": [52, 103], "file": "run.4.1.vti", "bytes": 70448}
 *       ]
 *     }
 *
 * "steps" is optional (a simulation whose output counts none leaves it out);
 * every other key is required, and a key the reader does not know is
 * skipped. The reader is strict JSON (RFC 8259) with two allowances for
 * what other tools write: NaN, Infinity and -Infinity are read as numbers
 * (Python's json.dump writes them) only to be refused as values, and a
 * whole-number key may be written as 40.0 or 4e1. It refuses, with one
 * sentence: text that is not JSON, nests deeper than GR_CHECKPOINT_MAX_DEPTH
 * or exceeds GR_CHECKPOINT_MAX_TEXT; a key given twice; a key missing or of
 * the wrong type; another format or version; and every value outside the
 * ranges gr_checkpoint documents (gr_checkpoint_validate). The reader never
 * recurses deeper than GR_CHECKPOINT_MAX_DEPTH; it allocates a table of the
 * text's values (20 bytes each, at most 2^21 of them, freed before it
 * returns) and the pieces, at most GR_CHECKPOINT_MAX_RANKS of them.
 *
 * What needs the simulation (its label, its grid, this run's ranks and
 * rows, its output times, the pieces' files and bytes) is checked by the
 * caller against the struct.
 */
#ifndef GRAUPEL_CHECKPOINT_H
#define GRAUPEL_CHECKPOINT_H

#include "graupel/graupel.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The manifest's "format". */
#define GR_CHECKPOINT_FORMAT "graupel-checkpoint"
/** The manifest's "version" this library writes and reads. */
#define GR_CHECKPOINT_VERSION 1
/** The most ranks (and pieces) a manifest may list. */
#define GR_CHECKPOINT_MAX_RANKS 65536
/** The largest state a piece may hold, in bytes (2^40, 1 TiB). */
#define GR_CHECKPOINT_MAX_BYTES (1LL << 40)
/** The longest string value kept (simulation, class, file), in bytes. */
#define GR_CHECKPOINT_MAX_STRING 255
/** The deepest nesting of arrays and objects read (the manifest needs 3). */
#define GR_CHECKPOINT_MAX_DEPTH 32
/** The longest manifest read, in bytes (16 MiB). */
#define GR_CHECKPOINT_MAX_TEXT ((size_t)1 << 24)

/** One rank's piece. */
typedef struct gr_checkpoint_piece {
  int rank;    /**< the rank that wrote it: its index in pieces */
  int rows[2]; /**< its own rows, first and last: 0 <= rows[0] <= rows[1] < grid[1] */
  /** The piece's file, beside the manifest: not empty, no '/', '\\', ".." or control character. */
  char file[GR_CHECKPOINT_MAX_STRING + 1];
  long long bytes; /**< the state's bytes, 0 to GR_CHECKPOINT_MAX_BYTES */
} gr_checkpoint_piece;

/** A manifest's contents. */
typedef struct gr_checkpoint {
  int version; /**< GR_CHECKPOINT_VERSION */
  /** The simulation's label ("Rain Runoff") and VTK class; any text without a control character. */
  char simulation[GR_CHECKPOINT_MAX_STRING + 1];
  char class_name[GR_CHECKPOINT_MAX_STRING + 1];
  int output_index;       /**< the output the state is at, 0 or more */
  double time;            /**< its time, s: finite, 0 or more */
  double output_interval; /**< s: finite, above 0 */
  int has_steps;          /**< 1: steps holds the manifest's "steps" */
  double steps;           /**< the steps taken: finite, 0 or more (a double, as VTK keeps it) */
  int grid[2];            /**< the whole grid's points in x and y, each 1 or more */
  int split;              /**< 1: split over ranks, each with its own rows; 0: whole on rank 0 */
  int ranks;              /**< 1 to GR_CHECKPOINT_MAX_RANKS; 1 when not split */
  gr_checkpoint_piece *pieces; /**< ranks pieces, piece r of rank r */
} gr_checkpoint;

/**
 * Zeroes c and makes it a manifest of the current version with ranks
 * pieces (zeroed, rank r at index r) to fill in. GR_ERR_INVALID_ARGUMENT
 * for ranks outside 1 to GR_CHECKPOINT_MAX_RANKS, GR_ERR_OUT_OF_MEMORY; a
 * sentence goes to msg. Free with gr_checkpoint_free.
 */
GR_API gr_status gr_checkpoint_init(gr_checkpoint *c, int ranks, char *msg, size_t msg_len);

/** Frees the pieces and zeroes c. NULL is fine. */
GR_API void gr_checkpoint_free(gr_checkpoint *c);

/**
 * Checks every value of c against the ranges above, and that pieces holds
 * ranks pieces in rank order. label is the sentence's subject (NULL: "The
 * checkpoint manifest"); on the first fault, GR_ERR_FORMAT and one
 * sentence "<label> gives ...; give the .json a CheckpointFile wrote." in
 * msg (when msg and msg_len) and as the calling thread's latest error
 * (gr_last_error).
 */
GR_API gr_status gr_checkpoint_validate(const gr_checkpoint *c, const char *label, char *msg,
                                        size_t msg_len);

/**
 * Reads a manifest from len bytes of text (need not end in '\0'). On
 * success *out holds it (its previous contents are overwritten, not freed:
 * free them first); on failure *out is untouched, the status is
 * GR_ERR_FORMAT (GR_ERR_INVALID_ARGUMENT for no text or no out,
 * GR_ERR_OUT_OF_MEMORY) and one sentence whose subject is label (NULL:
 * "The checkpoint manifest") goes to msg and to gr_last_error, e.g.
 * "Rain Runoff's RestartFile run.json is not a Graupel checkpoint manifest
 * (not JSON: line 3, column 9 has 'x' where a value belongs); give the
 * .json a CheckpointFile wrote."
 */
GR_API gr_status gr_checkpoint_parse(const char *text, size_t len, const char *label,
                                     gr_checkpoint *out, char *msg, size_t msg_len);

/**
 * Writes c as a manifest: *text (ending in '\n' and '\0'; free it with
 * gr_checkpoint_text_free) of *len bytes without the '\0'. Doubles are
 * written with the fewest digits that read back to the same bits, whatever
 * the C locale. A c that gr_checkpoint_validate refuses is not written:
 * its status and sentence (subject "The checkpoint to write"), *text NULL.
 * gr_checkpoint_parse of the text gives c back, value for value.
 */
GR_API gr_status gr_checkpoint_format(const gr_checkpoint *c, char **text, size_t *len, char *msg,
                                      size_t msg_len);

/** Frees what gr_checkpoint_format wrote. NULL is fine. */
GR_API void gr_checkpoint_text_free(char *text);

#ifdef __cplusplus
}
#endif

#endif
