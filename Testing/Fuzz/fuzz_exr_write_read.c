/* libFuzzer harness: gr_exr_write, then gr_exr_read and gr_exr_read_memory.
 *
 * Input layout (missing bytes read as 0):
 *   byte 0      width - 1 (mod 64)
 *   byte 1      height - 1 (mod 64)
 *   byte 2      bits 0-1: channels - 1; bit 2: HALF (else FLOAT)
 *   per channel a length byte L, then the name's bytes: L < 128 gives
 *               L mod 40 bytes, L >= 128 gives (L - 128) * 3 bytes (so names
 *               over 31 and over 255 characters appear). A 0 byte ends a
 *               name early: names may be empty, duplicated or anything else.
 *   the rest    float samples, 4 raw bytes each (every bit pattern: NaN with
 *               payloads, infinities, subnormals), repeated cyclically to fill
 *               width * height * channels samples (0 when there are none).
 *
 * A failed write must come with an error sentence. A successful one must read
 * back, from the file and from its bytes in memory, with the same size and
 * names: FLOAT bit for bit (any NaN for a NaN), HALF within half precision
 * (rounded to nearest, overflow to infinity, NaN stays NaN). The file is one
 * per process, made by mkstemp in /tmp and removed at exit. */
#include "fuzz_common.h"
#include "../C/gr_test_io.h"
#include "graupel/exr_io.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MAX_SIDE 64
#define MAX_CHANNELS 4
#define MAX_NAME_BYTES (127 * 3)

static char g_path[64];

static void remove_temp(void) {
  if (g_path[0] != '\0')
    remove(g_path);
}

static const char *temp_path(void) {
  if (g_path[0] == '\0') {
    int fd;
    snprintf(g_path, sizeof g_path, "/tmp/graupel_fuzz_exr_XXXXXX");
    fd = mkstemp(g_path);
    if (fd < 0) {
      perror("mkstemp");
      abort();
    }
    close(fd);
    atexit(&remove_temp);
  }
  return g_path;
}

/* got is what HALF storage of v may read back as. */
static int half_ok(float v, float got) {
  double av = fabs((double)v), tol;
  if (isnan(v))
    return isnan(got);
  if (av >= 65520.0) /* rounds to infinity, as do infinities themselves */
    return isinf(got) && signbit(got) == signbit(v);
  if (!isfinite(got) || (got != 0.0f && signbit(got) != signbit(v)))
    return 0;
  /* Half's spacing is 2^-10 of the power of two below |v| (2^-24 for its
   * subnormals); rounding to nearest is off by at most half of it. */
  tol = av >= 0x1p-14 ? av * 0x1p-11 : 0x1p-25;
  return fabs((double)got - (double)v) <= tol;
}

static int float_ok(float v, float got) {
  if (isnan(v))
    return isnan(got);
  return memcmp(&v, &got, sizeof v) == 0;
}

static void check_same_image(const gr_exr_image *a, const gr_exr_image *b) {
  size_t npix = (size_t)a->width * (size_t)a->height;
  int c;
  REQUIRE(a->width == b->width && a->height == b->height && a->nchannels == b->nchannels);
  for (c = 0; c < a->nchannels; ++c) {
    REQUIRE(strcmp(a->names[c], b->names[c]) == 0 && a->types[c] == b->types[c]);
    REQUIRE(memcmp(a->data[c], b->data[c], npix * sizeof(float)) == 0);
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static char name_buf[MAX_CHANNELS][MAX_NAME_BYTES + 1];
  static float planes[MAX_CHANNELS][MAX_SIDE * MAX_SIDE];
  const char *names[MAX_CHANNELS];
  const float *plane_ptrs[MAX_CHANNELS];
  reader r;
  int w, h, nch, c, k;
  gr_exr_pixel_type type;
  size_t npix, i, rest, pos;
  char err[2048];
  gr_status st;
  const char *path = temp_path();
  gr_exr_image img, mem;
  unsigned char *bytes;
  size_t nbytes;

  r.p = data;
  r.n = size;
  w = take_byte(&r) % MAX_SIDE + 1;
  h = take_byte(&r) % MAX_SIDE + 1;
  {
    uint8_t b = take_byte(&r);
    nch = (b & 3) + 1;
    type = (b & 4) ? GR_EXR_HALF : GR_EXR_FLOAT;
  }
  for (c = 0; c < nch; ++c) {
    uint8_t L = take_byte(&r);
    size_t len = L < 128 ? (size_t)(L % 40) : (size_t)(L - 128) * 3;
    for (i = 0; i < len; ++i)
      name_buf[c][i] = (char)take_byte(&r);
    name_buf[c][len] = '\0';
    names[c] = name_buf[c];
  }
  npix = (size_t)w * (size_t)h;
  rest = r.n / 4 * 4;
  for (c = 0, pos = 0; c < nch; ++c) {
    for (i = 0; i < npix; ++i) {
      float v = 0.0f;
      if (rest > 0) {
        memcpy(&v, r.p + pos, sizeof v);
        pos = (pos + 4) % rest;
      }
      planes[c][i] = v;
    }
    plane_ptrs[c] = planes[c];
  }

  err[0] = '\0';
  st = gr_exr_write(path, w, h, nch, names, plane_ptrs, type, err, sizeof err);
  if (st != GR_OK) {
    size_t n = strlen(err);
    REQUIRE(n > 0 && err[n - 1] == '.');
    return 0;
  }

  memset(&img, 0, sizeof img);
  err[0] = '\0';
  st = gr_exr_read(path, &img, err, sizeof err);
  if (st != GR_OK) {
    fprintf(stderr, "a file gr_exr_write wrote does not read back: %s\n", err);
    __builtin_trap();
  }
  REQUIRE(img.width == w && img.height == h && img.nchannels == nch);
  for (c = 0; c < nch; ++c) {
    k = gr_exr_find_channel(&img, names[c]);
    REQUIRE(k >= 0);
    REQUIRE(img.types[k] == type);
    for (i = 0; i < npix; ++i) {
      float v = planes[c][i], got = img.data[k][i];
      if (!(type == GR_EXR_FLOAT ? float_ok(v, got) : half_ok(v, got))) {
        fprintf(stderr, "channel '%s' sample %zu: wrote %a, read %a (%s)\n", names[c], i, (double)v,
                (double)got, type == GR_EXR_FLOAT ? "FLOAT" : "HALF");
        __builtin_trap();
      }
    }
  }

  /* The same bytes from memory read the same. */
  bytes = gr_test_load_file(path, &nbytes);
  REQUIRE(bytes != NULL);
  memset(&mem, 0, sizeof mem);
  st = gr_exr_read_memory(bytes, nbytes, "written", &mem, err, sizeof err);
  REQUIRE(st == GR_OK);
  check_same_image(&img, &mem);
  gr_exr_image_free(&mem);
  gr_exr_image_free(&img);
  free(bytes);
  return 0;
}
