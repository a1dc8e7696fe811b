/* What every Graupel fuzz harness shares. */
#ifndef GR_FUZZ_COMMON_H
#define GR_FUZZ_COMMON_H

#include <stddef.h>
#include <stdint.h>

/* An invariant that must hold: a violation is a crash libFuzzer records. */
#define REQUIRE(cond)                                                                              \
  do {                                                                                             \
    if (!(cond))                                                                                   \
      __builtin_trap();                                                                            \
  } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#endif
