/* What every Graupel fuzz harness shares. */
#ifndef GR_FUZZ_COMMON_H
#define GR_FUZZ_COMMON_H

#include "graupel/graupel.h"

#include <stddef.h>
#include <stdint.h>
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

#endif
