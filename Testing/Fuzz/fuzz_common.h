/* What every Graupel fuzz harness shares. */
#ifndef GR_FUZZ_COMMON_H
#define GR_FUZZ_COMMON_H

#include "graupel/graupel.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* An invariant that must hold: a violation is a crash libFuzzer records. */
#define REQUIRE(cond)                                                                              \
  do {                                                                                             \
    if (!(cond))                                                                                   \
      __builtin_trap();                                                                            \
  } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The fuzz input, read front to back; bytes past its end read as 0. */
typedef struct reader {
  const uint8_t *p;
  size_t n;
} reader;

/* Copies up to len bytes into dst, zero-filling what the input lacks. */
static inline void take(reader *r, void *dst, size_t len) {
  size_t k = r->n < len ? r->n : len;
  memset(dst, 0, len);
  if (k)
    memcpy(dst, r->p, k);
  r->p += k;
  r->n -= k;
}

static inline uint8_t take_byte(reader *r) {
  uint8_t b;
  take(r, &b, 1);
  return b;
}

/* A validator's answer: OK, or INVALID_ARGUMENT with a sentence ending in '.'. */
static inline void check_message(gr_status st, const char *msg) {
  size_t n;
  REQUIRE(st == GR_OK || st == GR_ERR_INVALID_ARGUMENT);
  if (st == GR_OK)
    return;
  n = strlen(msg);
  REQUIRE(n > 0 && msg[n - 1] == '.');
}

/* The row of a core's parameter table (n rows) for a property; every
 * property a harness names must be there. */
static inline const gr_param_bound *fuzz_row(const gr_param_bound *t, int n, const char *property) {
  for (int r = 0; r < n; ++r)
    if (strcmp(t[r].property, property) == 0)
      return &t[r];
  REQUIRE(!"a parameter is missing from the table");
  return NULL;
}

/* Accepted by a row: within [min, max] times to_core (min excluded when
 * open), a whole number when the row says so. The harnesses' own statement
 * of the rule, independent of the core's gr_param_accepts. */
static inline int fuzz_in_row(const gr_param_bound *row, double v) {
  const double lo = row->min * row->to_core, hi = row->max * row->to_core;
  return (row->min_open ? v > lo : v >= lo) && v <= hi && (!row->integer || v == floor(v));
}

/* An edge value for a fuzzed parameter picked by b: NaN, the infinities and
 * extremes, one of the harness's fixed values, or for a row of the table
 * (core units) its min, max, default, or one ulp either side of min and max. */
static inline double fuzz_table_edge(const gr_param_bound *t, int n, const double *fixed,
                                     size_t nfixed, uint8_t b) {
  const size_t nrow = 7 * (size_t)n, special = 6;
  size_t k = b % (special + nfixed + nrow);
  switch (k) {
  case 0:
    return NAN;
  case 1:
    return INFINITY;
  case 2:
    return -INFINITY;
  case 3:
    return DBL_MAX;
  case 4:
    return nextafter(0.0, 1.0);
  case 5:
    return DBL_MIN;
  default:
    break;
  }
  k -= special;
  if (k < nfixed)
    return fixed[k];
  k -= nfixed;
  const gr_param_bound *row = &t[k / 7];
  const double lo = row->min * row->to_core, hi = row->max * row->to_core;
  switch (k % 7) {
  case 0:
    return lo;
  case 1:
    return hi;
  case 2:
    return row->default_value * row->to_core;
  case 3:
    return nextafter(lo, -HUGE_VAL);
  case 4:
    return nextafter(lo, HUGE_VAL);
  case 5:
    return nextafter(hi, -HUGE_VAL);
  default:
    return nextafter(hi, HUGE_VAL);
  }
}

/* A field of a parameter struct for fuzz_fill: 'd' double or 'i' int, at
 * its offset (FUZZ_FIELD_D / FUZZ_FIELD_I). */
typedef struct fuzz_field {
  char kind;
  size_t offset;
} fuzz_field;
#define FUZZ_FIELD_D(type, member)                                                                 \
  { 'd', offsetof(type, member) }
#define FUZZ_FIELD_I(type, member)                                                                 \
  { 'i', offsetof(type, member) }

static inline double fuzz_field_value(const void *p, const fuzz_field *f) {
  const char *at = (const char *)p + f->offset;
  if (f->kind == 'd') {
    double v;
    memcpy(&v, at, sizeof v);
    return v;
  }
  int v;
  memcpy(&v, at, sizeof v);
  return v;
}

/* Fills a parameter struct p of nf fields as the parameter harnesses'
 * input layout says, in mode (0..2): 0 every field from raw bytes (4 per
 * int, 8 per double), so NaN, infinities, subnormals and huge values
 * appear; 1 the fields whose bit is set in the next 2 bytes read raw, the
 * others left as p holds them (the caller's defaults); 2 one byte per
 * field picks fuzz_table_edge's value (an int takes it when finite and
 * small, else -1). */
static inline void fuzz_fill(reader *r, int mode, void *p, const fuzz_field *fields, int nf,
                             const gr_param_bound *table, int n, const double *fixed,
                             size_t nfixed) {
  char *base = (char *)p;
  if (mode == 1) {
    uint8_t bits[2];
    take(r, bits, sizeof bits);
    for (int f = 0; f < nf && f < 16; ++f)
      if (bits[f / 8] & (1u << (f % 8)))
        take(r, base + fields[f].offset, fields[f].kind == 'd' ? sizeof(double) : sizeof(int));
    return;
  }
  for (int f = 0; f < nf; ++f) {
    char *at = base + fields[f].offset;
    if (mode == 0) {
      take(r, at, fields[f].kind == 'd' ? sizeof(double) : sizeof(int));
      continue;
    }
    double v = fuzz_table_edge(table, n, fixed, nfixed, take_byte(r));
    if (fields[f].kind == 'd') {
      memcpy(at, &v, sizeof v);
    } else {
      int iv = isfinite(v) && fabs(v) < 2e9 ? (int)v : -1;
      memcpy(at, &iv, sizeof iv);
    }
  }
}

/* A parameter validator behind a harness's wrapper (p NULL included). */
typedef gr_status (*fuzz_validate_fn)(const void *p, char *msg, size_t len);

/* A validator's answers for p: GR_OK exactly when documented, else a
 * sentence; the same answer with no buffer, and with a short buffer of
 * small_len bytes that it never overruns and always terminates; a sentence
 * for no parameters at all. */
static inline void fuzz_check_validator(fuzz_validate_fn validate, const void *p, int documented,
                                        size_t small_len) {
  char msg[1024];
  msg[0] = '\0';
  gr_status sp = validate(p, msg, sizeof msg);
  check_message(sp, msg);
  REQUIRE((sp == GR_OK) == documented);
  REQUIRE(validate(p, NULL, 0) == sp);
  REQUIRE(validate(p, NULL, 64) == sp);
  char *small = (char *)malloc(small_len > 0 ? small_len : 1);
  REQUIRE(small != NULL);
  if (small_len > 0) {
    memset(small, 'x', small_len);
    REQUIRE(validate(p, small, small_len) == sp);
    if (sp != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
  }
  free(small);
  msg[0] = '\0';
  check_message(validate(NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
}

#endif
