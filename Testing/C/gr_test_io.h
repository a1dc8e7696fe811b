/* File helper shared by the C tests and the fuzz harnesses. */
#ifndef GR_TEST_IO_H
#define GR_TEST_IO_H

#include <stdio.h>
#include <stdlib.h>

/* The whole file in a malloc'd buffer (caller frees), its size in *n; NULL
 * (and *n = 0) when it cannot be read or is empty. */
static inline unsigned char *gr_test_load_file(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  unsigned char *buf = NULL;
  long sz;
  *n = 0;
  if (f == NULL)
    return NULL;
  if (fseek(f, 0, SEEK_END) == 0 && (sz = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0) {
    buf = (unsigned char *)malloc((size_t)sz);
    if (buf != NULL && fread(buf, 1, (size_t)sz, f) == (size_t)sz) {
      *n = (size_t)sz;
    } else {
      free(buf);
      buf = NULL;
    }
  }
  fclose(f);
  return buf;
}

#endif
