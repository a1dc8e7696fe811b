/* EXR I/O tests: FLOAT and HALF round trips in odd sizes, row orientation
 * (row 0 south in memory, north first in the file), tiled and offset inputs
 * written with OpenEXR's C API, hostile and broken files, and argument
 * errors; reads from memory equal reads from the file, and broken buffers
 * fail as broken files do. Every failure must be a sentence naming the file
 * (or the buffer's label), and must leave the output image untouched.
 *
 * Header attributes: spacing, origin and field data round trip bit for bit,
 * and hostile values fail with a sentence.
 *
 * Usage: test_exr --scratch DIR [SUBTEST...]   (DIR existing and writable;
 * `test_exr DIR` as before; --list names the subtests) */
#include "gr_test_io.h"
#include "gr_test.h"
#include "graupel/exr_io.h"

#include <openexr.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static const char *g_dir = ".";

/* ------------------------------------------------------------------------ */
/* Small helpers                                                            */
/* ------------------------------------------------------------------------ */

static void scratch_path(char *buf, size_t len, const char *name) {
  snprintf(buf, len, "%s/%s", g_dir, name);
}

/* A sentence: starts with a capital letter, ends with a period, names the
 * file. */
static int is_sentence_with(const char *s, const char *path) {
  size_t n = strlen(s);
  return n > 10 && s[0] >= 'A' && s[0] <= 'Z' && s[n - 1] == '.' &&
         (path == NULL || strstr(s, path) != NULL);
}

static int save_bytes(const char *path, const void *buf, size_t n) {
  FILE *f = fopen(path, "wb");
  int ok;
  if (f == NULL)
    return 0;
  ok = n == 0 || fwrite(buf, 1, n, f) == n;
  ok = (fclose(f) == 0) && ok;
  return ok;
}

static long file_size(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

static int file_exists(const char *path) {
  FILE *f = fopen(path, "rb");
  if (f == NULL)
    return 0;
  fclose(f);
  return 1;
}

static uint32_t lcg(uint32_t *s) {
  *s = *s * 1664525u + 1013904223u;
  return *s >> 8;
}

/* Reference float -> half, round to nearest even (independent of OpenEXR). */
static uint16_t ref_f2h(float f) {
  uint32_t x, ax, mant, h, rem;
  uint16_t sign;
  memcpy(&x, &f, sizeof x);
  sign = (uint16_t)((x >> 16) & 0x8000u);
  ax = x & 0x7fffffffu;
  if (ax >= 0x7f800000u)
    return (uint16_t)(sign | (ax > 0x7f800000u ? 0x7e00u : 0x7c00u));
  if (ax >= 0x477ff000u) /* >= 65520 rounds to infinity */
    return (uint16_t)(sign | 0x7c00u);
  if (ax < 0x38800000u) {                          /* below 2^-14: subnormal half or zero */
    double q = rint(fabs((double)f) * 16777216.0); /* units of 2^-24 */
    return (uint16_t)(sign | (uint16_t)q);
  }
  mant = ax & 0x7fffffu;
  h = ((((ax >> 23) - 127u + 15u)) << 10) | (mant >> 13);
  rem = mant & 0x1fffu;
  if (rem > 0x1000u || (rem == 0x1000u && (h & 1u)))
    ++h;
  return (uint16_t)(sign | h);
}

static float ref_h2f(uint16_t h) {
  int e = (h >> 10) & 31, m = h & 1023;
  double v;
  if (e == 0)
    v = ldexp((double)m, -24);
  else if (e == 31)
    v = m ? NAN : INFINITY;
  else
    v = ldexp((double)(1024 + m), e - 25);
  return (float)((h & 0x8000u) ? -v : v);
}

static float to_half_precision(float f) {
  return ref_h2f(ref_f2h(f));
}

static int same_bits(float a, float b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

/* A sentinel image: a failed read must leave it exactly as it was. */
static void sentinel(gr_exr_image *img) {
  memset(img, 0, sizeof *img);
  img->width = -7;
  img->height = -9;
  img->nchannels = 12345;
}

static int is_sentinel(const gr_exr_image *img) {
  return img->width == -7 && img->height == -9 && img->nchannels == 12345 && img->names == NULL &&
         img->types == NULL && img->data == NULL;
}

/* ------------------------------------------------------------------------ */
/* Writing and reading with OpenEXR's C API directly                        */
/* ------------------------------------------------------------------------ */

static void quiet_handler(exr_const_context_t ctxt, exr_result_t code, const char *msg) {
  (void)ctxt;
  (void)code;
  (void)msg;
}

/* Value of channel c at absolute file pixel (x, y) on mip level lvl. */
static float capi_value(int c, int x, int y, int lvl) {
  if (lvl > 0)
    return -1000.0f - (float)lvl;
  return (float)(c * 10000 + y * 100 + x) + 0.25f;
}

typedef struct capi_spec {
  exr_storage_t storage;
  exr_attr_box2i_t dw;
  exr_lineorder_t lineorder;
  exr_compression_t compression;
  uint32_t tile_w, tile_h;
  exr_tile_level_mode_t levels;
  int nchannels;
  const char *names[4];
  exr_pixel_type_t types[4];
  int xsamp; /* sampling of every channel (1 normally) */
  /* Adds header attributes before the header is written (NULL: none). */
  exr_result_t (*attrs)(exr_context_t ctxt, int part, int which);
  int which;
} capi_spec;

static capi_spec capi_default(void) {
  capi_spec s;
  memset(&s, 0, sizeof s);
  s.storage = EXR_STORAGE_SCANLINE;
  s.dw.min.x = 0;
  s.dw.min.y = 0;
  s.dw.max.x = 7;
  s.dw.max.y = 5;
  s.lineorder = EXR_LINEORDER_INCREASING_Y;
  s.compression = EXR_COMPRESSION_ZIP;
  s.tile_w = 16;
  s.tile_h = 8;
  s.levels = EXR_TILE_ONE_LEVEL;
  s.nchannels = 1;
  s.names[0] = "h";
  s.types[0] = EXR_PIXEL_FLOAT;
  s.xsamp = 1;
  return s;
}

/* Fills and encodes one chunk whose first pixel is (x0, y0) of level lvl. */
static exr_result_t capi_encode_chunk(exr_context_t ctxt, const exr_chunk_info_t *ci,
                                      exr_encode_pipeline_t *enc, int *live, const capi_spec *s,
                                      int x0, int y0, int lvl, unsigned char *buf) {
  exr_result_t rv;
  int c, i, j;
  size_t plane = (size_t)ci->width * (size_t)ci->height * 4u;
  if (!*live) {
    rv = exr_encoding_initialize(ctxt, 0, ci, enc);
    if (rv != EXR_ERR_SUCCESS)
      return rv;
    *live = 1;
  } else {
    rv = exr_encoding_update(ctxt, 0, ci, enc);
    if (rv != EXR_ERR_SUCCESS)
      return rv;
  }
  for (c = 0; c < enc->channel_count; ++c) {
    exr_coding_channel_info_t *ch = &enc->channels[c];
    int k;
    unsigned char *dst = buf + (size_t)c * plane;
    for (k = 0; k < s->nchannels; ++k)
      if (strcmp(s->names[k], ch->channel_name) == 0)
        break;
    for (j = 0; j < ch->height; ++j) {
      for (i = 0; i < ch->width; ++i) {
        float v = capi_value(k, x0 + i * s->xsamp, y0 + j * s->xsamp, lvl);
        if (s->types[k] == EXR_PIXEL_UINT) {
          uint32_t u = (uint32_t)(v < 0 ? 0 : v);
          memcpy(dst + ((size_t)j * (size_t)ch->width + (size_t)i) * 4u, &u, 4);
        } else {
          memcpy(dst + ((size_t)j * (size_t)ch->width + (size_t)i) * 4u, &v, 4);
        }
      }
    }
    ch->encode_from_ptr = dst;
    ch->user_pixel_stride = 4;
    ch->user_line_stride = ch->width * 4;
    ch->user_bytes_per_element = 4;
    ch->user_data_type = s->types[k] == EXR_PIXEL_UINT ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT;
  }
  rv = exr_encoding_choose_default_routines(ctxt, 0, enc);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_encoding_run(ctxt, 0, enc);
  return rv;
}

/* Writes a file described by s; returns 1 on success. */
static int capi_write(const char *path, const capi_spec *s) {
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  exr_context_t ctxt = NULL;
  exr_encode_pipeline_t enc;
  exr_result_t rv;
  int live = 0, part = 0, c;
  int w = s->dw.max.x - s->dw.min.x + 1, h = s->dw.max.y - s->dw.min.y + 1;
  unsigned char *buf = NULL;
  memset(&enc, 0, sizeof enc);
  init.error_handler_fn = &quiet_handler;
  rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_add_part(ctxt, NULL, s->storage, &part);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_initialize_required_attr_simple(ctxt, part, w, h, s->compression);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_set_data_window(ctxt, part, &s->dw);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_set_display_window(ctxt, part, &s->dw);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_set_lineorder(ctxt, part, s->lineorder);
  if (rv == EXR_ERR_SUCCESS && s->storage == EXR_STORAGE_TILED)
    rv = exr_set_tile_descriptor(ctxt, part, s->tile_w, s->tile_h, s->levels, EXR_TILE_ROUND_DOWN);
  for (c = 0; c < s->nchannels && rv == EXR_ERR_SUCCESS; ++c)
    rv = exr_add_channel(ctxt, part, s->names[c], s->types[c], EXR_PERCEPTUALLY_LINEAR, s->xsamp,
                         s->xsamp);
  if (rv == EXR_ERR_SUCCESS && s->attrs != NULL)
    rv = exr_set_longname_support(ctxt, 1);
  if (rv == EXR_ERR_SUCCESS && s->attrs != NULL)
    rv = s->attrs(ctxt, part, s->which);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_write_header(ctxt);
  if (rv == EXR_ERR_SUCCESS) {
    size_t cap = (size_t)(w + 64) * (size_t)(h + 64) * 4u * 4u;
    buf = (unsigned char *)malloc(cap);
    if (buf == NULL)
      rv = EXR_ERR_OUT_OF_MEMORY;
  }
  if (rv == EXR_ERR_SUCCESS && s->storage == EXR_STORAGE_SCANLINE) {
    int32_t lines = 1, nchunks, k;
    rv = exr_get_scanlines_per_chunk(ctxt, part, &lines);
    nchunks = (h + lines - 1) / lines;
    for (k = 0; k < nchunks && rv == EXR_ERR_SUCCESS; ++k) {
      exr_chunk_info_t ci;
      int y = s->dw.min.y + k * lines;
      rv = exr_write_scanline_chunk_info(ctxt, part, y, &ci);
      if (rv == EXR_ERR_SUCCESS)
        rv = capi_encode_chunk(ctxt, &ci, &enc, &live, s, s->dw.min.x, y, 0, buf);
    }
  } else if (rv == EXR_ERR_SUCCESS) {
    int32_t nlx = 1, nly = 1, lvl;
    rv = exr_get_tile_levels(ctxt, part, &nlx, &nly);
    for (lvl = 0; lvl < nlx && rv == EXR_ERR_SUCCESS; ++lvl) {
      int32_t lw = 0, lh = 0, tx, ty, ntx, nty;
      rv = exr_get_level_sizes(ctxt, part, lvl, lvl, &lw, &lh);
      ntx = (lw + (int32_t)s->tile_w - 1) / (int32_t)s->tile_w;
      nty = (lh + (int32_t)s->tile_h - 1) / (int32_t)s->tile_h;
      for (ty = 0; ty < nty && rv == EXR_ERR_SUCCESS; ++ty) {
        for (tx = 0; tx < ntx && rv == EXR_ERR_SUCCESS; ++tx) {
          exr_chunk_info_t ci;
          rv = exr_write_tile_chunk_info(ctxt, part, tx, ty, lvl, lvl, &ci);
          if (rv == EXR_ERR_SUCCESS)
            rv = capi_encode_chunk(ctxt, &ci, &enc, &live, s, s->dw.min.x + tx * (int)s->tile_w,
                                   s->dw.min.y + ty * (int)s->tile_h, lvl, buf);
        }
      }
    }
  }
  if (live)
    exr_encoding_destroy(ctxt, &enc);
  if (ctxt != NULL) {
    exr_result_t frv = exr_finish(&ctxt);
    if (rv == EXR_ERR_SUCCESS)
      rv = frv;
  }
  free(buf);
  if (rv != EXR_ERR_SUCCESS)
    fprintf(stderr, "capi_write(%s): %s\n", path, exr_get_default_error_message(rv));
  return rv == EXR_ERR_SUCCESS;
}

/* Decodes channel 0 of the file's first scanline chunk, the first scanline
 * stored in the file, into row[0..w). Returns the data window width, or -1. */
static int capi_first_scanline(const char *path, float *row, int maxw) {
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  exr_context_t ctxt = NULL;
  exr_decode_pipeline_t dec;
  exr_attr_box2i_t dw;
  exr_chunk_info_t ci;
  exr_result_t rv;
  int live = 0, w = -1, c;
  float *buf = NULL;
  memset(&dec, 0, sizeof dec);
  init.error_handler_fn = &quiet_handler;
  rv = exr_start_read(&ctxt, path, &init);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_data_window(ctxt, 0, &dw);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_read_scanline_chunk_info(ctxt, 0, dw.min.y, &ci);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_decoding_initialize(ctxt, 0, &ci, &dec);
  if (rv == EXR_ERR_SUCCESS) {
    live = 1;
    w = ci.width;
    buf = (float *)calloc((size_t)ci.width * (size_t)ci.height, sizeof(float));
    if (buf == NULL || w > maxw)
      rv = EXR_ERR_OUT_OF_MEMORY;
  }
  for (c = 0; c < dec.channel_count && rv == EXR_ERR_SUCCESS; ++c) {
    exr_coding_channel_info_t *ch = &dec.channels[c];
    ch->decode_to_ptr = c == 0 ? (uint8_t *)buf : NULL;
    ch->user_pixel_stride = 4;
    ch->user_line_stride = ci.width * 4;
    ch->user_bytes_per_element = 4;
    ch->user_data_type = EXR_PIXEL_FLOAT;
  }
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_decoding_choose_default_routines(ctxt, 0, &dec);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_decoding_run(ctxt, 0, &dec);
  if (rv == EXR_ERR_SUCCESS)
    memcpy(row, buf, (size_t)w * sizeof(float));
  if (live)
    exr_decoding_destroy(ctxt, &dec);
  if (ctxt != NULL)
    exr_finish(&ctxt);
  free(buf);
  return rv == EXR_ERR_SUCCESS ? w : -1;
}

/* Offset of the first byte after the header's attribute list (the start of
 * the chunk offset table) in a single-part file, or 0. */
static size_t header_end(const unsigned char *b, size_t n) {
  size_t p = 8;
  while (p < n) {
    size_t name = p, type;
    uint32_t sz;
    while (p < n && b[p] != 0)
      ++p;
    if (p >= n)
      return 0;
    if (p == name)
      return p + 1;
    type = ++p;
    while (p < n && b[p] != 0)
      ++p;
    if (p >= n || p == type || p + 5 > n)
      return 0;
    ++p;
    sz = (uint32_t)b[p] | ((uint32_t)b[p + 1] << 8) | ((uint32_t)b[p + 2] << 16) |
         ((uint32_t)b[p + 3] << 24);
    p += 4 + (size_t)sz;
  }
  return 0;
}

static size_t find_bytes(const unsigned char *b, size_t n, const void *pat, size_t m) {
  size_t i;
  for (i = 0; i + m <= n; ++i)
    if (memcmp(b + i, pat, m) == 0)
      return i;
  return (size_t)-1;
}

static void put_i32(unsigned char *p, int32_t v) {
  uint32_t u = (uint32_t)v;
  p[0] = (unsigned char)(u & 0xff);
  p[1] = (unsigned char)((u >> 8) & 0xff);
  p[2] = (unsigned char)((u >> 16) & 0xff);
  p[3] = (unsigned char)((u >> 24) & 0xff);
}

/* Reads path expecting a failure: GR_ERR_FORMAT or GR_ERR_IO, the output
 * untouched, and a sentence naming the file. */
static void expect_bad(const char *path, const char *what) {
  gr_exr_image img;
  char err[1024];
  gr_status st;
  sentinel(&img);
  err[0] = '\0';
  st = gr_exr_read(path, &img, err, sizeof err);
  CHECK_MSG(st == GR_ERR_FORMAT || st == GR_ERR_IO, "%s: status %s (%d)", what,
            gr_status_string(st), (int)st);
  CHECK_MSG(is_sentinel(&img), "%s: output was modified", what);
  CHECK_MSG(is_sentence_with(err, path), "%s: error '%s'", what, err);
  if (st == GR_OK)
    gr_exr_image_free(&img);
}

/* Reads bytes[0..n) with gr_exr_read_memory expecting GR_ERR_FORMAT, the
 * output untouched, and a sentence naming the label. */
static void expect_bad_memory(const void *bytes, size_t n, const char *label, const char *what) {
  gr_exr_image img;
  char err[1024];
  gr_status st;
  sentinel(&img);
  err[0] = '\0';
  st = gr_exr_read_memory(bytes, n, label, &img, err, sizeof err);
  CHECK_MSG(st == GR_ERR_FORMAT, "%s (memory): status %s (%d)", what, gr_status_string(st),
            (int)st);
  CHECK_MSG(is_sentinel(&img), "%s (memory): output was modified", what);
  CHECK_MSG(is_sentence_with(err, label), "%s (memory): error '%s'", what, err);
  if (st == GR_OK)
    gr_exr_image_free(&img);
}

/* Two images are equal: sizes, names, types and every value bit for bit. */
static int same_image(const gr_exr_image *a, const gr_exr_image *b) {
  int c;
  size_t npix;
  if (a->width != b->width || a->height != b->height || a->nchannels != b->nchannels)
    return 0;
  npix = (size_t)a->width * (size_t)a->height;
  for (c = 0; c < a->nchannels; ++c) {
    if (strcmp(a->names[c], b->names[c]) != 0 || a->types[c] != b->types[c] ||
        memcmp(a->data[c], b->data[c], npix * sizeof(float)) != 0)
      return 0;
  }
  return 1;
}

/* gr_exr_read_memory of the bytes of path gives what gr_exr_read gives, and
 * leaves the bytes as they were. The label is the path of no file at all. */
static void check_memory_equals_file(const char *path) {
  gr_exr_image from_file, from_mem;
  unsigned char *bytes, *before;
  size_t n = 0;
  char err[1024];
  gr_status st;
  memset(&from_file, 0, sizeof from_file);
  memset(&from_mem, 0, sizeof from_mem);
  bytes = gr_test_load_file(path, &n);
  before = (unsigned char *)malloc(n > 0 ? n : 1);
  CHECK_MSG(bytes != NULL && before != NULL, "%s: cannot load the file", path);
  if (bytes == NULL || before == NULL)
    goto done;
  memcpy(before, bytes, n);
  err[0] = '\0';
  st = gr_exr_read(path, &from_file, err, sizeof err);
  CHECK_MSG(st == GR_OK, "%s: %s", path, err);
  err[0] = '\0';
  st = gr_exr_read_memory(bytes, n, "no/such/file.exr", &from_mem, err, sizeof err);
  CHECK_MSG(st == GR_OK, "%s (memory): %s", path, err);
  CHECK_MSG(same_image(&from_file, &from_mem), "%s: the memory read differs from the file read",
            path);
  CHECK_MSG(memcmp(before, bytes, n) == 0, "%s: the memory read changed the buffer", path);
done:
  gr_exr_image_free(&from_file);
  gr_exr_image_free(&from_mem);
  free(bytes);
  free(before);
}

/* ------------------------------------------------------------------------ */
/* Round trips                                                              */
/* ------------------------------------------------------------------------ */

static float field_value(int c, int i, int j, int w, int h) {
  switch (c) {
  case 0: /* smooth terrain-like, many magnitudes */
    return (float)(sin(0.37 * i + 1.3 * j) * 1234.5 + 0.001 * (i * h + j));
  case 1: /* exactly representable in half: multiples of 1/4 below 512 */
    return (float)((i * 7 + j * 3) % 2048) * 0.25f - 100.0f;
  case 2: /* row index: orientation */
    (void)w;
    return (float)j;
  default: /* tiny (half subnormal) to large values, both signs */
    return (float)(ldexp(1.0 + 0.01 * (i % 100), (j % 30) - 20) * ((i + j) % 2 ? -1 : 1));
  }
}

static void test_roundtrip(int w, int h, int nch, gr_exr_pixel_type type) {
  static const char *all_names[4] = {"elevation", "snow_depth", "row", "Z"};
  const char *names[4];
  float *data[4] = {NULL, NULL, NULL, NULL};
  char path[1024], fname[128], err[1024];
  gr_exr_image img;
  gr_status st;
  int c, i, j, bad = 0;

  snprintf(fname, sizeof fname, "rt_%dx%d_%d_%s.exr", w, h, nch,
           type == GR_EXR_HALF ? "half" : "float");
  scratch_path(path, sizeof path, fname);
  /* One channel: the orientation channel, so every size checks it. */
  for (c = 0; c < nch; ++c) {
    int f = nch == 1 ? 2 : c;
    names[c] = all_names[f];
    data[c] = (float *)malloc((size_t)w * (size_t)h * sizeof(float));
    if (data[c] == NULL) {
      CHECK(!"out of memory");
      goto done;
    }
    for (j = 0; j < h; ++j)
      for (i = 0; i < w; ++i)
        data[c][(size_t)j * w + i] = field_value(f, i, j, w, h);
  }
  err[0] = '\0';
  st = gr_exr_write(path, w, h, nch, names, (const float *const *)data, type, err, sizeof err);
  CHECK_MSG(st == GR_OK, "write %s: %s", fname, err);
  memset(&img, 0, sizeof img);
  st = gr_exr_read(path, &img, err, sizeof err);
  CHECK_MSG(st == GR_OK, "read %s: %s", fname, err);
  if (st != GR_OK)
    goto done;
  CHECK(img.width == w && img.height == h && img.nchannels == nch);
  for (c = 0; c < nch && img.nchannels == nch; ++c) {
    int k = gr_exr_find_channel(&img, names[c]);
    int f = nch == 1 ? 2 : c;
    CHECK_MSG(k >= 0, "%s: channel '%s' missing", fname, names[c]);
    if (k < 0)
      continue;
    CHECK(img.types[k] == type);
    for (j = 0; j < h; ++j) {
      for (i = 0; i < w; ++i) {
        float v = data[c][(size_t)j * w + i];
        float got = img.data[k][(size_t)j * w + i];
        int ok;
        if (type == GR_EXR_FLOAT) {
          ok = same_bits(got, v);
        } else {
          float ref = to_half_precision(v);
          double tol = fabs(v) >= 6.103515625e-05 ? fabs(v) * ldexp(1, -11) : ldexp(1, -25);
          ok = same_bits(got, ref) && fabs((double)got - v) <= tol;
          if (f == 1 || f == 2) /* exactly representable in half */
            ok = ok && got == v;
        }
        if (!ok && bad++ < 5)
          CHECK_MSG(0, "%s: channel %s (%d,%d): wrote %.9g, read %.9g", fname, names[c], i, j, v,
                    got);
      }
    }
    if (f == 2) { /* orientation: memory row 0 is south, value 0 */
      CHECK(img.data[k][0] == 0.0f);
      CHECK(img.data[k][(size_t)(h - 1) * w] == (float)(h - 1));
    }
  }
  CHECK_MSG(bad == 0, "%s: %d values differ", fname, bad);
  gr_exr_image_free(&img);
  CHECK(img.data == NULL && img.names == NULL && img.nchannels == 0);
  check_memory_equals_file(path);
done:
  for (c = 0; c < nch; ++c)
    free(data[c]);
}

static void test_roundtrips(void) {
  static const int sizes[][2] = {{1, 1}, {3, 5}, {37, 19}, {257, 129}, {1, 40}, {40, 1}};
  size_t s;
  int nch;
  for (s = 0; s < sizeof sizes / sizeof sizes[0]; ++s)
    for (nch = 1; nch <= 4; nch += 3) {
      test_roundtrip(sizes[s][0], sizes[s][1], nch, GR_EXR_FLOAT);
      test_roundtrip(sizes[s][0], sizes[s][1], nch, GR_EXR_HALF);
    }
}

/* The file's first scanline is the northern edge (highest j). */
static void test_file_orientation(void) {
  enum { H = 21 };
  float col[H], row[4];
  const char *names[1] = {"elevation"};
  const float *data[1] = {col};
  char path[1024], err[512];
  gr_exr_image img;
  int j, w;
  gr_exr_pixel_type t;
  for (j = 0; j < H; ++j)
    col[j] = (float)j;
  for (t = GR_EXR_HALF; t <= GR_EXR_FLOAT; t = (gr_exr_pixel_type)(t + 1)) {
    scratch_path(path, sizeof path, "column.exr");
    CHECK(gr_exr_write(path, 1, H, 1, names, data, t, err, sizeof err) == GR_OK);
    row[0] = -1.0f;
    w = capi_first_scanline(path, row, 4);
    CHECK(w == 1);
    CHECK_NEAR(row[0], H - 1, 0.0);
    memset(&img, 0, sizeof img);
    CHECK(gr_exr_read(path, &img, err, sizeof err) == GR_OK);
    if (img.data != NULL) {
      for (j = 0; j < H; ++j)
        CHECK_NEAR(img.data[0][j], j, 0.0);
    }
    gr_exr_image_free(&img);
  }
}

/* Half rounding: ties to even, overflow to infinity, subnormals, NaN. */
static void test_half_rounding(void) {
  static const float in[] = {
      1.0f + 0x1p-11f,        /* tie -> 1 */
      1.0f + 3.0f * 0x1p-11f, /* tie -> 1 + 2^-9 */
      2049.0f,                /* tie -> 2048 */
      2051.0f,                /* tie -> 2052 */
      65504.0f,               /* largest half */
      65519.0f,               /* -> 65504 */
      65520.0f,               /* -> inf */
      1.0e6f,                 /* -> inf */
      -1.0e6f,                /* -> -inf */
      0x1p-24f,               /* smallest subnormal */
      0x1p-25f,               /* tie -> 0 */
      3.0f * 0x1p-25f,        /* tie -> 2^-23 */
      0x1p-14f,               /* smallest normal */
      -0.0f,
      0.1f,
      -3.14159265f,
  };
  enum { N = sizeof in / sizeof in[0] };
  float expect[N];
  const char *names[1] = {"v"};
  const float *data[1] = {in};
  char path[1024], err[512];
  gr_exr_image img;
  int k;
  expect[0] = 1.0f;
  expect[1] = 1.0f + 0x1p-9f;
  expect[2] = 2048.0f;
  expect[3] = 2052.0f;
  expect[4] = 65504.0f;
  expect[5] = 65504.0f;
  expect[6] = INFINITY;
  expect[7] = INFINITY;
  expect[8] = -INFINITY;
  expect[9] = 0x1p-24f;
  expect[10] = 0.0f;
  expect[11] = 0x1p-23f;
  expect[12] = 0x1p-14f;
  expect[13] = -0.0f;
  expect[14] = 0.0999755859375f;
  expect[15] = -3.140625f;
  scratch_path(path, sizeof path, "half_rounding.exr");
  CHECK(gr_exr_write(path, N, 1, 1, names, data, GR_EXR_HALF, err, sizeof err) == GR_OK);
  memset(&img, 0, sizeof img);
  CHECK_MSG(gr_exr_read(path, &img, err, sizeof err) == GR_OK, "%s", err);
  if (img.data != NULL && img.width == N) {
    for (k = 0; k < N; ++k) {
      CHECK_MSG(same_bits(img.data[0][k], expect[k]), "half of %.9g: got %.9g, want %.9g", in[k],
                img.data[0][k], expect[k]);
      CHECK(same_bits(expect[k], to_half_precision(in[k])));
    }
  }
  gr_exr_image_free(&img);

  /* FLOAT keeps special values bit for bit. */
  {
    float sp[6];
    sp[0] = NAN;
    sp[1] = INFINITY;
    sp[2] = -INFINITY;
    sp[3] = -0.0f;
    sp[4] = 1e-40f; /* subnormal float */
    sp[5] = 3.4028235e38f;
    data[0] = sp;
    scratch_path(path, sizeof path, "float_special.exr");
    CHECK(gr_exr_write(path, 6, 1, 1, names, data, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
    memset(&img, 0, sizeof img);
    CHECK(gr_exr_read(path, &img, err, sizeof err) == GR_OK);
    if (img.data != NULL && img.width == 6) {
      CHECK(isnan(img.data[0][0]));
      for (k = 1; k < 6; ++k)
        CHECK(same_bits(img.data[0][k], sp[k]));
    }
    gr_exr_image_free(&img);
    /* HALF keeps NaN a NaN. */
    CHECK(gr_exr_write(path, 6, 1, 1, names, data, GR_EXR_HALF, err, sizeof err) == GR_OK);
    memset(&img, 0, sizeof img);
    CHECK(gr_exr_read(path, &img, err, sizeof err) == GR_OK);
    if (img.data != NULL && img.width == 6) {
      CHECK(isnan(img.data[0][0]));
      CHECK(img.data[0][1] == INFINITY && img.data[0][2] == -INFINITY);
      CHECK(same_bits(img.data[0][4], 0.0f));
      CHECK(img.data[0][5] == INFINITY);
    }
    gr_exr_image_free(&img);
  }
}

/* A chunk whose ZIP data is exactly as long as its raw data must be stored
 * raw: the reader takes packed size == unpacked size for "not compressed".
 * OpenEXRCore 3.1 writes the compressed bytes in that case; gr_exr_write must
 * not. A 1x40 FLOAT column of 0..39 hits it: its last chunk is 8 rows, 32
 * bytes raw, and zlib makes 32 bytes of it. */
static void test_equal_size_chunk(void) {
  float col[40];
  const char *names[1] = {"row"};
  const float *data[1] = {col};
  char path[1024], err[512];
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  exr_context_t ctxt = NULL;
  exr_chunk_info_t ci;
  gr_exr_image img;
  int j;
  for (j = 0; j < 40; ++j)
    col[j] = (float)j;
  scratch_path(path, sizeof path, "equal_size_chunk.exr");
  CHECK(gr_exr_write(path, 1, 40, 1, names, data, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
  init.error_handler_fn = &quiet_handler;
  CHECK(exr_start_read(&ctxt, path, &init) == EXR_ERR_SUCCESS);
  memset(&ci, 0, sizeof ci);
  CHECK(exr_read_scanline_chunk_info(ctxt, 0, 32, &ci) == EXR_ERR_SUCCESS);
  CHECK(ci.unpacked_size == 32 && ci.packed_size == 32);
  exr_finish(&ctxt);
  memset(&img, 0, sizeof img);
  CHECK(gr_exr_read(path, &img, err, sizeof err) == GR_OK);
  if (img.data != NULL && img.height == 40)
    for (j = 0; j < 40; ++j)
      CHECK_NEAR(img.data[0][j], j, 0.0);
  gr_exr_image_free(&img);
}

/* Long names (over EXR's 31-character short limit) round trip; the order of
 * channels read is EXR's sorted order. */
static void test_names_roundtrip(void) {
  char longname[201];
  const char *names[3];
  float a[6] = {1, 2, 3, 4, 5, 6}, b[6] = {7, 8, 9, 10, 11, 12}, c[6] = {0, 0, 0, 0, 0, 1};
  const float *data[3] = {a, b, c};
  char path[1024], err[512];
  gr_exr_image img;
  memset(longname, 'q', 200);
  longname[200] = '\0';
  names[0] = "zeta";
  names[1] = longname;
  names[2] = "alpha.beta";
  scratch_path(path, sizeof path, "names.exr");
  CHECK_MSG(gr_exr_write(path, 3, 2, 3, names, data, GR_EXR_FLOAT, err, sizeof err) == GR_OK, "%s",
            err);
  memset(&img, 0, sizeof img);
  CHECK_MSG(gr_exr_read(path, &img, err, sizeof err) == GR_OK, "%s", err);
  CHECK(img.nchannels == 3);
  if (img.nchannels == 3) {
    CHECK(strcmp(img.names[0], "alpha.beta") == 0);
    CHECK(strcmp(img.names[1], longname) == 0);
    CHECK(strcmp(img.names[2], "zeta") == 0);
    CHECK(gr_exr_find_channel(&img, "zeta") == 2);
    CHECK(gr_exr_find_channel(&img, longname) == 1);
    CHECK(img.data[2][0] == 1.0f && img.data[2][5] == 6.0f);
    CHECK(img.data[1][4] == 11.0f);
    CHECK(img.data[0][5] == 1.0f);
  }
  gr_exr_image_free(&img);
}

/* ------------------------------------------------------------------------ */
/* Inputs written with the C API: tiled, offset data windows, line order    */
/* ------------------------------------------------------------------------ */

/* Checks img against capi_value over the data window of s. */
static void check_capi_image(const gr_exr_image *img, const capi_spec *s, const char *what) {
  int w = s->dw.max.x - s->dw.min.x + 1, h = s->dw.max.y - s->dw.min.y + 1;
  int c, i, j, bad = 0;
  CHECK_MSG(img->width == w && img->height == h, "%s: %dx%d, want %dx%d", what, img->width,
            img->height, w, h);
  CHECK_MSG(img->nchannels == s->nchannels, "%s: %d channels", what, img->nchannels);
  if (img->width != w || img->height != h || img->nchannels != s->nchannels)
    return;
  for (c = 0; c < s->nchannels; ++c) {
    int k = gr_exr_find_channel(img, s->names[c]);
    CHECK_MSG(k >= 0, "%s: channel %s missing", what, s->names[c]);
    if (k < 0)
      continue;
    CHECK(img->types[k] == (s->types[c] == EXR_PIXEL_HALF ? GR_EXR_HALF : GR_EXR_FLOAT));
    for (j = 0; j < h; ++j) {
      for (i = 0; i < w; ++i) {
        /* memory row j is file row h-1-j */
        float want = capi_value(c, s->dw.min.x + i, s->dw.min.y + (h - 1 - j), 0);
        float got = img->data[k][(size_t)j * w + i];
        if (s->types[c] == EXR_PIXEL_HALF)
          want = to_half_precision(want);
        if (!same_bits(got, want) && bad++ < 5)
          CHECK_MSG(0, "%s: %s (%d,%d) = %.9g, want %.9g", what, s->names[c], i, j, got, want);
      }
    }
  }
  CHECK_MSG(bad == 0, "%s: %d values differ", what, bad);
}

static void read_capi_case(const capi_spec *s, const char *fname) {
  char path[1024], err[1024];
  gr_exr_image img;
  gr_status st;
  scratch_path(path, sizeof path, fname);
  CHECK_MSG(capi_write(path, s), "could not write %s with the C API", fname);
  memset(&img, 0, sizeof img);
  err[0] = '\0';
  st = gr_exr_read(path, &img, err, sizeof err);
  CHECK_MSG(st == GR_OK, "%s: %s", fname, err);
  if (st == GR_OK)
    check_capi_image(&img, s, fname);
  gr_exr_image_free(&img);
  check_memory_equals_file(path);
}

static void test_capi_inputs(void) {
  capi_spec s;

  /* Tiled FLOAT, 37x19 with 16x8 tiles (partial edge tiles), data window
   * starting at (3, -5). */
  s = capi_default();
  s.storage = EXR_STORAGE_TILED;
  s.dw.min.x = 3;
  s.dw.min.y = -5;
  s.dw.max.x = 3 + 37 - 1;
  s.dw.max.y = -5 + 19 - 1;
  s.nchannels = 2;
  s.names[0] = "height";
  s.types[0] = EXR_PIXEL_FLOAT;
  s.names[1] = "b";
  s.types[1] = EXR_PIXEL_FLOAT;
  read_capi_case(&s, "tiled_float.exr");

  /* Tiled, one tile larger than the image, uncompressed, HALF + FLOAT. */
  s.compression = EXR_COMPRESSION_NONE;
  s.tile_w = 64;
  s.tile_h = 64;
  s.types[1] = EXR_PIXEL_HALF;
  read_capi_case(&s, "tiled_one_tile.exr");

  /* Mipmapped tiled: only level 0 is read. */
  s = capi_default();
  s.storage = EXR_STORAGE_TILED;
  s.dw.max.x = 20;
  s.dw.max.y = 12;
  s.tile_w = 8;
  s.tile_h = 4;
  s.levels = EXR_TILE_MIPMAP_LEVELS;
  read_capi_case(&s, "tiled_mipmap.exr");

  /* Scanline, offset data window, decreasing line order, PIZ. */
  s = capi_default();
  s.dw.min.x = -10;
  s.dw.min.y = 100;
  s.dw.max.x = -10 + 23 - 1;
  s.dw.max.y = 100 + 45 - 1;
  s.lineorder = EXR_LINEORDER_DECREASING_Y;
  s.compression = EXR_COMPRESSION_PIZ;
  s.nchannels = 2;
  s.names[0] = "B";
  s.types[0] = EXR_PIXEL_HALF;
  s.names[1] = "A";
  s.types[1] = EXR_PIXEL_FLOAT;
  read_capi_case(&s, "scan_offset_decreasing.exr");

  /* Scanline, RLE and uncompressed. */
  s = capi_default();
  s.dw.max.x = 30;
  s.dw.max.y = 2;
  s.compression = EXR_COMPRESSION_RLE;
  read_capi_case(&s, "scan_rle.exr");
  s.compression = EXR_COMPRESSION_NONE;
  read_capi_case(&s, "scan_none.exr");
}

/* ------------------------------------------------------------------------ */
/* Broken and hostile files                                                 */
/* ------------------------------------------------------------------------ */

static void test_bad_files(void) {
  char path[1024], good[1024], err[1024];
  unsigned char *bytes = NULL, *copy = NULL;
  size_t n = 0, k, off;
  uint32_t seed = 12345u;
  capi_spec s;
  gr_exr_image img;
  gr_status st;
  int t, bad_trunc = 0;
  float vals[37 * 19 * 2];
  const float *data[2] = {vals, vals + 37 * 19};
  const char *names[2] = {"elevation", "snow_depth"};

  /* Missing file. */
  scratch_path(path, sizeof path, "does_not_exist.exr");
  remove(path);
  expect_bad(path, "missing file");
  {
    /* Missing file with no error buffer, and with a zero-length one. */
    char small[8];
    sentinel(&img);
    CHECK(gr_exr_read(path, &img, NULL, 0) == GR_ERR_IO);
    CHECK(is_sentinel(&img));
    memcpy(small, "xxxxxxx", 8);
    CHECK(gr_exr_read(path, &img, small, 0) == GR_ERR_IO);
    CHECK(memcmp(small, "xxxxxxx", 8) == 0);
    CHECK(gr_exr_read(path, &img, small, sizeof small) == GR_ERR_IO);
    CHECK(strlen(small) == sizeof small - 1);
    CHECK(is_sentinel(&img));
  }
  /* A directory. */
  expect_bad(g_dir, "a directory");

  /* Empty file. */
  scratch_path(path, sizeof path, "empty.exr");
  CHECK(save_bytes(path, "", 0));
  expect_bad(path, "empty file");

  /* A text file. */
  scratch_path(path, sizeof path, "text.exr");
  {
    static const char text[] = "This is not an image.\nIt is a text file pretending to be one.\n";
    CHECK(save_bytes(path, text, sizeof text - 1));
  }
  expect_bad(path, "text file");

  /* A valid file to break. Sine data does not compress much, so most of the
   * file is pixel data. */
  for (k = 0; k < 37 * 19 * 2; ++k)
    vals[k] = (float)sin((double)k * 0.7) * 100.0f;
  scratch_path(good, sizeof good, "good.exr");
  CHECK(gr_exr_write(good, 37, 19, 2, names, data, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
  bytes = gr_test_load_file(good, &n);
  CHECK(bytes != NULL && n > 1000);
  if (bytes == NULL || n <= 1000)
    goto done;
  copy = (unsigned char *)malloc(n);
  if (copy == NULL)
    goto done;

  /* Truncated at named lengths, then at every length. */
  scratch_path(path, sizeof path, "truncated.exr");
  {
    size_t lens[6];
    lens[0] = 10;
    lens[1] = 4;
    lens[2] = header_end(bytes, n);
    lens[3] = n / 2;
    lens[4] = n - 8;
    lens[5] = n - 1;
    CHECK(lens[2] > 8 && lens[2] < n);
    for (t = 0; t < 6; ++t) {
      char what[64];
      snprintf(what, sizeof what, "truncated to %zu of %zu bytes", lens[t], n);
      CHECK(save_bytes(path, bytes, lens[t]));
      expect_bad(path, what);
    }
  }
  /* Every length through the header and offset table and near the end;
   * every 7th through the pixel data. */
  for (k = 0; k < n; ++k) {
    if (k > header_end(bytes, n) + 64 && k + 64 < n && k % 7 != 0)
      continue;
    CHECK(save_bytes(path, bytes, k));
    sentinel(&img);
    st = gr_exr_read(path, &img, err, sizeof err);
    if (st == GR_OK || !is_sentinel(&img)) {
      if (bad_trunc++ < 5)
        CHECK_MSG(0, "truncated to %zu of %zu bytes: status %d", k, n, (int)st);
      if (st == GR_OK)
        gr_exr_image_free(&img);
    }
  }
  CHECK_MSG(bad_trunc == 0, "%d truncated lengths were accepted", bad_trunc);

  /* Random bytes after a valid magic number (and version). */
  scratch_path(path, sizeof path, "random.exr");
  for (t = 0; t < 40; ++t) {
    size_t len = 16 + (size_t)(lcg(&seed) % 2000u);
    memcpy(copy, bytes, 8 < n ? 8 : n);
    for (k = t % 2 ? 8 : 4; k < len && k < n; ++k)
      copy[k] = (unsigned char)(lcg(&seed) & 0xff);
    CHECK(save_bytes(path, copy, len < n ? len : n));
    expect_bad(path, "random bytes after the magic number");
  }

  /* Random bytes over the pixel data (after the offset table). */
  off = header_end(bytes, n);
  if (off > 8) {
    size_t table_end = off + 8u * (size_t)((19 + 15) / 16);
    memcpy(copy, bytes, n);
    for (k = table_end + 8; k < n; ++k)
      copy[k] = (unsigned char)(lcg(&seed) & 0xff);
    CHECK(save_bytes(path, copy, n));
    sentinel(&img);
    st = gr_exr_read(path, &img, err, sizeof err);
    /* The first chunk is stored raw (sine data does not compress), so its
     * noise reads as numbers; the second is ZIP, and noise cannot inflate to
     * the right size. */
    CHECK_MSG(st == GR_ERR_FORMAT && is_sentinel(&img) && is_sentence_with(err, path),
              "noise pixels: %d '%s'", (int)st, err);
    if (st == GR_OK)
      gr_exr_image_free(&img);

    /* Offset table entries pointing past the end, and into the header. */
    memcpy(copy, bytes, n);
    memset(copy + off, 0x7f, 8);
    CHECK(save_bytes(path, copy, n));
    expect_bad(path, "chunk offset past the end");
    memcpy(copy, bytes, n);
    memset(copy + off, 0, 8);
    copy[off] = 8;
    CHECK(save_bytes(path, copy, n));
    expect_bad(path, "chunk offset into the header");
  }

  /* Absurd dimensions in the dataWindow attribute. */
  {
    static const char tag[] = "dataWindow\0box2i\0";
    size_t at = find_bytes(bytes, n, tag, sizeof tag - 1);
    static const int32_t boxes[][4] = {
        {0, 0, (1 << 30) - 1, 18}, /* 2^30 wide */
        {0, 0, 36, (1 << 30) - 1}, /* 2^30 tall */
        {0, 0, 65536, 18},         /* one more than GR_EXR_MAX_DIM */
        {-(1 << 30), -(1 << 30), (1 << 30), (1 << 30)},
        {INT32_MIN, 0, INT32_MAX, 18}, /* width overflows int32 */
        {10, 0, 9, 18},                /* empty */
        {0, 0, 36, -5},                /* negative height */
        {0, 0, 36, 20},                /* 2 more rows than the file holds */
        {0, 0, 65535, 65535},          /* 2^32 samples: over the limit */
        {0, 0, 65535, 16383},          /* 2^30 samples: allowed, not there */
    };
    CHECK(at != (size_t)-1 && at + (sizeof tag - 1) + 4 + 16 <= n);
    if (at != (size_t)-1 && at + (sizeof tag - 1) + 4 + 16 <= n) {
      unsigned char *box = copy + at + (sizeof tag - 1) + 4;
      for (t = 0; t < (int)(sizeof boxes / sizeof boxes[0]); ++t) {
        char what[96];
        int q;
        memcpy(copy, bytes, n);
        for (q = 0; q < 4; ++q)
          put_i32(box + 4 * q, boxes[t][q]);
        CHECK(save_bytes(path, copy, n));
        snprintf(what, sizeof what, "dataWindow (%d,%d)-(%d,%d)", (int)boxes[t][0],
                 (int)boxes[t][1], (int)boxes[t][2], (int)boxes[t][3]);
        expect_bad(path, what);
      }
    }
  }

  /* Only channel is UINT. */
  s = capi_default();
  s.types[0] = EXR_PIXEL_UINT;
  scratch_path(path, sizeof path, "uint.exr");
  CHECK(capi_write(path, &s));
  expect_bad(path, "UINT channel");
  sentinel(&img);
  CHECK(gr_exr_read(path, &img, err, sizeof err) == GR_ERR_FORMAT);
  CHECK_MSG(strstr(err, "UINT") != NULL, "'%s'", err);
  /* A FLOAT channel beside a UINT one. */
  s.nchannels = 2;
  s.names[1] = "g";
  s.types[1] = EXR_PIXEL_FLOAT;
  CHECK(capi_write(path, &s));
  expect_bad(path, "FLOAT and UINT channels");
  /* Subsampled channel. */
  s = capi_default();
  s.dw.max.x = 7;
  s.dw.max.y = 7;
  s.xsamp = 2;
  scratch_path(path, sizeof path, "subsampled.exr");
  if (capi_write(path, &s)) {
    expect_bad(path, "subsampled channel");
  }

done:
  free(bytes);
  free(copy);
}

/* ------------------------------------------------------------------------ */
/* Chunks that claim far more pixels than their bytes can hold              */
/* ------------------------------------------------------------------------ */

/* Overwrites the value of the header attribute "name\0type\0" with vals
 * (little-endian int32s); returns 0 when it is not there. */
static int patch_attr(unsigned char *b, size_t n, const char *tag, size_t tag_len,
                      const int32_t *vals, int nvals) {
  size_t at = find_bytes(b, n, tag, tag_len);
  int q;
  if (at == (size_t)-1 || at + tag_len + 4 + 4 * (size_t)nvals > n)
    return 0;
  for (q = 0; q < nvals; ++q)
    put_i32(b + at + tag_len + 4 + 4 * (size_t)q, vals[q]);
  return 1;
}

/* Expects a refusal that names the chunk's claim, from the file and from its
 * bytes in memory: refused while checking chunk descriptions, before the
 * image (or OpenEXR's buffer for the chunk) is allocated. */
static void expect_implausible(const char *path, const unsigned char *b, size_t n,
                               const char *what) {
  gr_exr_image img;
  char err[1024];
  gr_status st;
  CHECK(save_bytes(path, b, n));
  expect_bad(path, what);
  sentinel(&img);
  st = gr_exr_read(path, &img, err, sizeof err);
  CHECK_MSG(st == GR_ERR_FORMAT && strstr(err, "claims") != NULL, "%s: %d '%s'", what, (int)st,
            err);
  expect_bad_memory(b, n, "hostile", what);
  st = gr_exr_read_memory(b, n, "hostile", &img, err, sizeof err);
  CHECK_MSG(st == GR_ERR_FORMAT && strstr(err, "claims") != NULL, "%s (memory): '%s'", what, err);
  CHECK(is_sentinel(&img));
}

static void test_implausible_chunks(void) {
  static const char dw_tag[] = "dataWindow\0box2i\0";
  static const char tiles_tag[] = "tiles\0tiledesc\0";
  const int32_t huge_box[4] = {0, 0, 65535, 32767}; /* 2^31 samples: the most allowed */
  char path[1024], err[512];
  unsigned char *bytes = NULL, *hostile = NULL;
  size_t n = 0, hend, k;
  capi_spec s;

  /* One tile of a ZIP file grown to 65536 x 32768 pixels: 8 GiB claimed by a
   * few dozen compressed bytes (Testing/Fuzz/regressions/exr_read/
   * zip_single_tile_claims_8GiB.exr is the same in 360 bytes). */
  s = capi_default();
  s.storage = EXR_STORAGE_TILED;
  s.dw.max.x = 5;
  s.dw.max.y = 5;
  s.tile_w = 8;
  s.tile_h = 8;
  scratch_path(path, sizeof path, "huge_tile.exr");
  CHECK(capi_write(path, &s));
  bytes = gr_test_load_file(path, &n);
  CHECK(bytes != NULL);
  if (bytes != NULL) {
    const int32_t tile[2] = {65536, 32768};
    CHECK(patch_attr(bytes, n, dw_tag, sizeof dw_tag - 1, huge_box, 4));
    CHECK(patch_attr(bytes, n, tiles_tag, sizeof tiles_tag - 1, tile, 2));
    expect_implausible(path, bytes, n, "one ZIP tile claiming 8 GiB");
  }
  free(bytes);
  bytes = NULL;

  /* A ZIP scanline file of 65536 x 32768 pixels whose 2048 chunks hold one
   * byte each: 35 kB asking for 8 GiB (regressions/exr_read/
   * zip_scanline_chunks_of_1_byte_claim_8GiB.exr). */
  {
    float v[6] = {1, 2, 3, 4, 5, 6};
    const float *data[1] = {v};
    const char *names[1] = {"elevation"};
    const size_t nchunks = 32768 / 16;
    scratch_path(path, sizeof path, "one_byte_chunks.exr");
    CHECK(gr_exr_write(path, 3, 2, 1, names, data, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
    bytes = gr_test_load_file(path, &n);
    hend = bytes != NULL ? header_end(bytes, n) : 0;
    CHECK(hend > 8);
    hostile = (unsigned char *)malloc(hend + nchunks * (8 + 9));
    if (hend > 8 && hostile != NULL) {
      unsigned char *table = hostile + hend, *chunk = table + 8 * nchunks;
      memcpy(hostile, bytes, hend);
      CHECK(patch_attr(hostile, hend, dw_tag, sizeof dw_tag - 1, huge_box, 4));
      for (k = 0; k < nchunks; ++k) {
        uint64_t off = (uint64_t)(chunk - hostile);
        int b;
        for (b = 0; b < 8; ++b)
          table[8 * k + (size_t)b] = (unsigned char)((off >> (8 * b)) & 0xff);
        put_i32(chunk, (int32_t)(16 * k)); /* first scanline */
        put_i32(chunk + 4, 1);             /* packed size */
        chunk[8] = 0x78;                   /* the first byte of a zlib stream */
        chunk += 9;
      }
      expect_implausible(path, hostile, (size_t)(chunk - hostile),
                         "2048 ZIP chunks of 1 byte claiming 8 GiB");
    }
    free(bytes);
    free(hostile);
    bytes = NULL;
  }

  /* Real data compressed about 1000 to 1 (zeros, ZIP; zlib's limit is
   * 1032:1) is still read: the bound leaves a margin. */
  {
    enum { W = 4096, H = 64 };
    float *zeros = (float *)calloc((size_t)W * H, sizeof(float));
    const float *data[1];
    const char *names[1] = {"zero"};
    gr_exr_pixel_type t;
    data[0] = zeros;
    scratch_path(path, sizeof path, "zeros.exr");
    for (t = GR_EXR_HALF; zeros != NULL && t <= GR_EXR_FLOAT; t = (gr_exr_pixel_type)(t + 1)) {
      gr_exr_image img;
      exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
      exr_context_t ctxt = NULL;
      exr_chunk_info_t ci;
      CHECK(gr_exr_write(path, W, H, 1, names, data, t, err, sizeof err) == GR_OK);
      init.error_handler_fn = &quiet_handler;
      CHECK(exr_start_read(&ctxt, path, &init) == EXR_ERR_SUCCESS);
      memset(&ci, 0, sizeof ci);
      CHECK(exr_read_scanline_chunk_info(ctxt, 0, 0, &ci) == EXR_ERR_SUCCESS);
      CHECK_MSG(ci.packed_size > 0 && ci.unpacked_size / ci.packed_size > 500,
                "zeros compress only %llu -> %llu", (unsigned long long)ci.unpacked_size,
                (unsigned long long)ci.packed_size);
      exr_finish(&ctxt);
      memset(&img, 0, sizeof img);
      CHECK_MSG(gr_exr_read(path, &img, err, sizeof err) == GR_OK, "%s", err);
      CHECK(img.width == W && img.height == H);
      gr_exr_image_free(&img);
    }
    free(zeros);
  }
}

/* A ZIP chunk relabelled DWAA or DWAB: refused with a sentence whatever the
 * library makes of it. OpenEXRCore 3.1.5 (Debian 12) has no DWA decoder;
 * the sentence then names the compression. One chunk of 10 rows, so that the
 * chunk table is the same for 16 (ZIP), 32 (DWAA) and 256 (DWAB) rows per
 * chunk. */
static void test_undecodable_compression(void) {
  static const char tag[] = "compression\0compression\0";
  static const char *const names_dwa[2] = {"DWAA", "DWAB"};
  float v[37 * 10];
  const float *data[1] = {v};
  const char *names[1] = {"elevation"};
  char path[1024], err[1024];
  unsigned char *bytes;
  size_t n = 0, at, k;
  int t;
  for (k = 0; k < 37 * 10; ++k)
    v[k] = (float)(k / 37);
  scratch_path(path, sizeof path, "relabelled_dwa.exr");
  CHECK(gr_exr_write(path, 37, 10, 1, names, data, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
  bytes = gr_test_load_file(path, &n);
  at = bytes != NULL ? find_bytes(bytes, n, tag, sizeof tag - 1) : (size_t)-1;
  CHECK(at != (size_t)-1 && at + sizeof tag - 1 + 5 <= n);
  if (at == (size_t)-1 || at + sizeof tag - 1 + 5 > n) {
    free(bytes);
    return;
  }
  for (t = 0; t < 2; ++t) {
    gr_exr_image img;
    bytes[at + sizeof tag - 1 + 4] = (unsigned char)(EXR_COMPRESSION_DWAA + t);
    CHECK(save_bytes(path, bytes, n));
    expect_bad(path, names_dwa[t]);
    expect_bad_memory(bytes, n, "relabelled", names_dwa[t]);
    sentinel(&img);
    if (gr_exr_read(path, &img, err, sizeof err) != GR_OK && strstr(err, "not yet implemented"))
      CHECK_MSG(strstr(err, "cannot decode") != NULL && strstr(err, names_dwa[t]) != NULL, "'%s'",
                err);
  }
  free(bytes);
}

/* ------------------------------------------------------------------------ */
/* Reading from memory                                                      */
/* ------------------------------------------------------------------------ */

static void test_memory_reads(void) {
  static const char label[] = "in-memory terrain.exr";
  char path[1024], other[1024], err[1024];
  unsigned char *bytes = NULL, *copy = NULL;
  size_t n = 0, k, hend;
  uint32_t seed = 777u;
  gr_exr_image img;
  gr_status st;
  int t, bad_trunc = 0;
  float vals[37 * 19 * 2], ones[4] = {1, 1, 1, 1};
  const float *data[2] = {vals, vals + 37 * 19};
  const float *data1[1] = {ones};
  const char *names[2] = {"elevation", "snow_depth"};
  capi_spec s;

  for (k = 0; k < 37 * 19 * 2; ++k)
    vals[k] = (float)cos((double)k * 0.3) * 50.0f;
  scratch_path(path, sizeof path, "memory_good.exr");
  CHECK(gr_exr_write(path, 37, 19, 2, names, data, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
  bytes = gr_test_load_file(path, &n);
  CHECK(bytes != NULL && n > 1000);
  if (bytes == NULL || n <= 1000)
    goto done;
  copy = (unsigned char *)malloc(n + 1);
  if (copy == NULL)
    goto done;
  check_memory_equals_file(path);

  /* The label is only a name: naming another, existing file reads the
   * buffer all the same. */
  scratch_path(other, sizeof other, "memory_other.exr");
  CHECK(gr_exr_write(other, 2, 2, 1, names, data1, GR_EXR_HALF, err, sizeof err) == GR_OK);
  memset(&img, 0, sizeof img);
  CHECK(gr_exr_read_memory(bytes, n, other, &img, err, sizeof err) == GR_OK);
  CHECK(img.width == 37 && img.height == 19 && img.nchannels == 2);
  gr_exr_image_free(&img);
  /* A buffer at an odd address. */
  memcpy(copy + 1, bytes, n);
  memset(&img, 0, sizeof img);
  CHECK(gr_exr_read_memory(copy + 1, n, label, &img, err, sizeof err) == GR_OK);
  CHECK(img.width == 37 && img.height == 19 && img.nchannels == 2);
  if (img.nchannels == 2)
    CHECK(memcmp(img.data[0], vals, 37 * 19 * sizeof(float)) == 0 &&
          memcmp(img.data[1], vals + 37 * 19, 37 * 19 * sizeof(float)) == 0);
  gr_exr_image_free(&img);

  /* No bytes. */
  expect_bad_memory(NULL, n, label, "NULL data");
  expect_bad_memory(NULL, 0, label, "NULL data, size 0");
  expect_bad_memory(bytes, 0, label, "size 0");
  /* No label, or an empty one: the buffer is "<memory>". */
  expect_bad_memory(bytes, 0, NULL, "NULL label");
  sentinel(&img);
  CHECK(gr_exr_read_memory(NULL, 0, NULL, &img, err, sizeof err) == GR_ERR_FORMAT);
  CHECK_MSG(is_sentence_with(err, "<memory>"), "'%s'", err);
  CHECK(gr_exr_read_memory(bytes, 4, "", &img, err, sizeof err) == GR_ERR_FORMAT);
  CHECK_MSG(is_sentence_with(err, "<memory>"), "'%s'", err);
  CHECK(is_sentinel(&img));
  memset(&img, 0, sizeof img);
  CHECK(gr_exr_read_memory(bytes, n, NULL, &img, err, sizeof err) == GR_OK);
  gr_exr_image_free(&img);
  /* No output image; no or a short error buffer. */
  CHECK(gr_exr_read_memory(bytes, n, label, NULL, err, sizeof err) == GR_ERR_INVALID_ARGUMENT);
  CHECK(is_sentence_with(err, NULL));
  sentinel(&img);
  CHECK(gr_exr_read_memory(bytes, 10, label, &img, NULL, 0) == GR_ERR_FORMAT);
  CHECK(gr_exr_read_memory(bytes, 10, label, &img, err, 8) == GR_ERR_FORMAT);
  CHECK(strlen(err) == 7);
  CHECK(is_sentinel(&img));

  /* Truncated: every length through the header and offset table and near
   * the end, every 7th through the pixel data. Each is a fresh allocation
   * of exactly that many bytes, so a read past the end would be caught by
   * a sanitizer. */
  hend = header_end(bytes, n);
  CHECK(hend > 8 && hend < n);
  expect_bad_memory(bytes, hend, label, "truncated after the header");
  expect_bad_memory(bytes, n - 1, label, "truncated by one byte");
  for (k = 1; k < n; ++k) {
    unsigned char *part;
    if (k > hend + 64 && k + 64 < n && k % 7 != 0)
      continue;
    part = (unsigned char *)malloc(k);
    if (part == NULL)
      break;
    memcpy(part, bytes, k);
    sentinel(&img);
    err[0] = '\0';
    st = gr_exr_read_memory(part, k, label, &img, err, sizeof err);
    if (st != GR_ERR_FORMAT || !is_sentinel(&img) || !is_sentence_with(err, label)) {
      if (bad_trunc++ < 5)
        CHECK_MSG(0, "truncated to %zu of %zu bytes: status %d, '%s'", k, n, (int)st, err);
      if (st == GR_OK)
        gr_exr_image_free(&img);
    }
    free(part);
  }
  CHECK_MSG(bad_trunc == 0, "%d truncated buffers were accepted", bad_trunc);

  /* A tiled file, truncated at every length. */
  s = capi_default();
  s.storage = EXR_STORAGE_TILED;
  s.dw.max.x = 20;
  s.dw.max.y = 12;
  s.tile_w = 8;
  s.tile_h = 4;
  scratch_path(other, sizeof other, "memory_tiled.exr");
  if (capi_write(other, &s)) {
    size_t tn = 0;
    unsigned char *tiled = gr_test_load_file(other, &tn);
    CHECK(tiled != NULL && tn > 100);
    check_memory_equals_file(other);
    bad_trunc = 0;
    for (k = 1; tiled != NULL && k < tn; ++k) {
      unsigned char *part = (unsigned char *)malloc(k);
      if (part == NULL)
        break;
      memcpy(part, tiled, k);
      sentinel(&img);
      st = gr_exr_read_memory(part, k, label, &img, err, sizeof err);
      if (st != GR_ERR_FORMAT || !is_sentinel(&img) || !is_sentence_with(err, label)) {
        if (bad_trunc++ < 5)
          CHECK_MSG(0, "tiled, truncated to %zu of %zu bytes: status %d", k, tn, (int)st);
        if (st == GR_OK)
          gr_exr_image_free(&img);
      }
      free(part);
    }
    CHECK_MSG(bad_trunc == 0, "%d truncated tiled buffers were accepted", bad_trunc);
    free(tiled);
  }

  /* Garbage: text, zeros, the magic number alone, random bytes after the
   * magic number (and version). */
  {
    static const char text[] = "This is not an image.\nIt is a text file pretending to be one.\n";
    expect_bad_memory(text, sizeof text - 1, label, "text");
    memset(copy, 0, n);
    expect_bad_memory(copy, n, label, "zeros");
    expect_bad_memory(bytes, 4, label, "magic number only");
    expect_bad_memory(bytes, 8, label, "magic number and version only");
  }
  for (t = 0; t < 40; ++t) {
    size_t len = 16 + (size_t)(lcg(&seed) % 2000u);
    if (len > n)
      len = n;
    memcpy(copy, bytes, 8);
    for (k = t % 2 ? 8 : 4; k < len; ++k)
      copy[k] = (unsigned char)(lcg(&seed) & 0xff);
    expect_bad_memory(copy, len, label, "random bytes after the magic number");
  }
  /* Chunk offsets past the end of the buffer, and into the header. */
  memcpy(copy, bytes, n);
  memset(copy + hend, 0x7f, 8);
  expect_bad_memory(copy, n, label, "chunk offset past the end");
  memcpy(copy, bytes, n);
  memset(copy + hend, 0, 8);
  copy[hend] = 8;
  expect_bad_memory(copy, n, label, "chunk offset into the header");

done:
  free(bytes);
  free(copy);
}

/* ------------------------------------------------------------------------ */
/* Writer argument errors                                                   */
/* ------------------------------------------------------------------------ */

static void expect_write_error(gr_status want, const char *path, int w, int h, int nch,
                               const char *const *names, const float *const *data,
                               gr_exr_pixel_type t, const char *what) {
  char err[1024];
  gr_status st;
  err[0] = '\0';
  st = gr_exr_write(path, w, h, nch, names, data, t, err, sizeof err);
  CHECK_MSG(st == want, "%s: status %s, want %s", what, gr_status_string(st),
            gr_status_string(want));
  CHECK_MSG(is_sentence_with(err, path != NULL && path[0] ? path : NULL), "%s: error '%s'", what,
            err);
}

static void test_write_errors(void) {
  float v[12] = {0};
  const float *d2[2] = {v, v};
  const float *dnull[2] = {v, NULL};
  const char *ok2[2] = {"a", "b"};
  const char *dup[2] = {"a", "a"};
  const char *empty[2] = {"a", ""};
  const char *nulln[2] = {NULL, "b"};
  const char *toolong[1];
  char longname[GR_EXR_MAX_NAME + 2];
  char path[1024], bad[1024], err[64];
  const gr_status A = GR_ERR_INVALID_ARGUMENT;

  memset(longname, 'x', sizeof longname - 1);
  longname[sizeof longname - 1] = '\0';
  toolong[0] = longname;
  scratch_path(path, sizeof path, "write_errors.exr");
  remove(path);
  expect_write_error(A, path, 3, 2, 2, NULL, d2, GR_EXR_FLOAT, "NULL names");
  expect_write_error(A, path, 3, 2, 2, ok2, NULL, GR_EXR_FLOAT, "NULL data");
  expect_write_error(A, path, 3, 2, 2, nulln, d2, GR_EXR_FLOAT, "NULL name");
  expect_write_error(A, path, 3, 2, 2, empty, d2, GR_EXR_FLOAT, "empty name");
  expect_write_error(A, path, 3, 2, 2, dup, d2, GR_EXR_HALF, "duplicate name");
  expect_write_error(A, path, 3, 2, 2, ok2, dnull, GR_EXR_FLOAT, "NULL plane");
  expect_write_error(A, path, 3, 2, 1, toolong, d2, GR_EXR_FLOAT, "long name");
  expect_write_error(A, path, 3, 2, 0, ok2, d2, GR_EXR_FLOAT, "0 channels");
  expect_write_error(A, path, 3, 2, -1, ok2, d2, GR_EXR_FLOAT, "-1 channels");
  expect_write_error(A, path, 0, 2, 2, ok2, d2, GR_EXR_FLOAT, "width 0");
  expect_write_error(A, path, 3, 0, 2, ok2, d2, GR_EXR_FLOAT, "height 0");
  expect_write_error(A, path, -3, 2, 2, ok2, d2, GR_EXR_FLOAT, "width -3");
  expect_write_error(A, path, GR_EXR_MAX_DIM + 1, 1, 2, ok2, d2, GR_EXR_FLOAT, "width too large");
  expect_write_error(A, path, 3, 2, 2, ok2, d2, (gr_exr_pixel_type)7, "pixel type 7");
  expect_write_error(A, NULL, 3, 2, 2, ok2, d2, GR_EXR_FLOAT, "NULL path");
  expect_write_error(A, "", 3, 2, 2, ok2, d2, GR_EXR_FLOAT, "empty path");
  CHECK(!file_exists(path));

  /* A directory that does not exist. */
  scratch_path(bad, sizeof bad, "no_such_dir/sub/x.exr");
  expect_write_error(GR_ERR_IO, bad, 3, 2, 2, ok2, d2, GR_EXR_FLOAT, "unwritable path");
  CHECK(!file_exists(bad));
  /* A directory in place of the file. */
  expect_write_error(GR_ERR_IO, g_dir, 3, 2, 2, ok2, d2, GR_EXR_FLOAT, "directory as path");

  /* NULL and short error buffers are fine. */
  CHECK(gr_exr_write(path, 0, 2, 2, ok2, d2, GR_EXR_FLOAT, NULL, 0) == A);
  CHECK(gr_exr_write(path, 0, 2, 2, ok2, d2, GR_EXR_FLOAT, err, sizeof err) == A);
  CHECK(strlen(err) < sizeof err);

  /* Read argument errors. */
  {
    gr_exr_image img;
    char e2[256];
    sentinel(&img);
    CHECK(gr_exr_read(NULL, &img, e2, sizeof e2) == A);
    CHECK(is_sentence_with(e2, NULL));
    CHECK(gr_exr_read("", &img, e2, sizeof e2) == A);
    CHECK(is_sentinel(&img));
    CHECK(gr_exr_read(path, NULL, e2, sizeof e2) == A);
  }
}

/* A write that fails part-way (a file-size limit, as a full disk) leaves
 * the earlier file of that name whole and no temporary file behind; the
 * next write, with room, replaces it. The limited write runs in a child
 * process (RLIMIT_FSIZE, SIGXFSZ ignored, as `ulimit -f` in a shell). */
static void test_write_atomic(void) {
  enum { N = 256 };
  static float small[4 * 4], big[N * N];
  const char *names[1] = {"elevation"};
  const float *ds[1] = {small}, *db[1] = {big};
  char path[1024], err[512];
  for (int i = 0; i < 16; ++i)
    small[i] = (float)i;
  /* Noise does not compress: the big file needs about 256 KiB. */
  unsigned state = 12345u;
  for (int i = 0; i < N * N; ++i) {
    state = state * 1664525u + 1013904223u;
    big[i] = (float)(state >> 8);
  }
  scratch_path(path, sizeof path, "atomic.exr");
  remove(path);
  CHECK(gr_exr_write(path, 4, 4, 1, names, ds, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
  long before = file_size(path);
  CHECK(before > 0);

  fflush(NULL);
  pid_t child = fork();
  if (child == 0) {
    struct rlimit lim = {64 * 1024, 64 * 1024};
    signal(SIGXFSZ, SIG_IGN);
    setrlimit(RLIMIT_FSIZE, &lim);
    gr_status st = gr_exr_write(path, N, N, 1, names, db, GR_EXR_FLOAT, err, sizeof err);
    printf("  limited write: status %d: %s\n", (int)st, err);
    fflush(stdout);
    _exit(st == GR_ERR_IO && is_sentence_with(err, path) ? 0 : 1);
  }
  int status = 0;
  CHECK(child > 0 && waitpid(child, &status, 0) == child);
  CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0,
            "the write beyond the limit fails with one sentence naming the file (%d)", status);
  CHECK_MSG(file_size(path) == before, "the earlier file is whole (%ld bytes, was %ld)",
            file_size(path), before);
  gr_exr_image img;
  CHECK(gr_exr_read(path, &img, err, sizeof err) == GR_OK);
  if (img.width == 4 && img.height == 4 && img.nchannels == 1) {
    CHECK(memcmp(img.data[0], small, sizeof small) == 0);
  } else {
    CHECK_MSG(0, "read back %d x %d x %d", img.width, img.height, img.nchannels);
  }
  gr_exr_image_free(&img);
  /* No temporary file left beside it. */
  DIR *dir = opendir(g_dir);
  int strays = 0;
  for (struct dirent *e = dir ? readdir(dir) : NULL; e; e = readdir(dir))
    strays += strncmp(e->d_name, "atomic", 6) == 0 && strcmp(e->d_name, "atomic.exr") != 0;
  if (dir)
    closedir(dir);
  CHECK_MSG(strays == 0, "%d temporary files left", strays);
  /* With room again the same write succeeds. */
  CHECK(gr_exr_write(path, N, N, 1, names, db, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
  CHECK(file_size(path) > 64 * 1024);
  remove(path);
}

/* ------------------------------------------------------------------------ */
/* gr_exr_find_channel and gr_exr_image_free                                */
/* ------------------------------------------------------------------------ */

static void test_helpers(void) {
  gr_exr_image img;
  char n0[] = "elevation", n1[] = "snow_depth";
  char *names[2];
  names[0] = n0;
  names[1] = n1;
  memset(&img, 0, sizeof img);
  CHECK(gr_exr_find_channel(&img, "elevation") == -1);
  CHECK(gr_exr_find_channel(NULL, "elevation") == -1);
  gr_exr_image_free(&img);
  gr_exr_image_free(&img);
  gr_exr_image_free(NULL);
  CHECK(img.width == 0 && img.data == NULL);

  img.nchannels = 2;
  img.names = names;
  CHECK(gr_exr_find_channel(&img, "elevation") == 0);
  CHECK(gr_exr_find_channel(&img, "snow_depth") == 1);
  CHECK(gr_exr_find_channel(&img, "snow") == -1);
  CHECK(gr_exr_find_channel(&img, "") == -1);
  CHECK(gr_exr_find_channel(&img, NULL) == -1);

  /* A real image, freed twice. */
  {
    float v[2] = {1.5f, -2.5f};
    const float *data[1] = {v};
    const char *wn[1] = {"x"};
    char path[1024], err[256];
    gr_exr_image r;
    scratch_path(path, sizeof path, "helpers.exr");
    CHECK(gr_exr_write(path, 2, 1, 1, wn, data, GR_EXR_FLOAT, err, sizeof err) == GR_OK);
    memset(&r, 0, sizeof r);
    CHECK(gr_exr_read(path, &r, err, sizeof err) == GR_OK);
    CHECK(gr_exr_find_channel(&r, "x") == 0);
    CHECK(gr_exr_find_channel(&r, "y") == -1);
    gr_exr_image_free(&r);
    CHECK(r.width == 0 && r.height == 0 && r.nchannels == 0 && r.names == NULL && r.types == NULL &&
          r.data == NULL);
    gr_exr_image_free(&r);
  }
}

/* ------------------------------------------------------------------------ */
/* Geometry and field data in the header                                    */
/* ------------------------------------------------------------------------ */

static int same_double_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

static const gr_exr_meta_field *find_meta_field(const gr_exr_meta *m, const char *name) {
  int f;
  for (f = 0; f < m->nfields; ++f)
    if (strcmp(m->fields[f].name, name) == 0)
      return &m->fields[f];
  return NULL;
}

/* A DEM with spacing 74.5 x 92.1, origin (100, 200, 0) and a ledger comes
 * back with exactly that geometry and ledger, from a file and from memory;
 * a file written without meta has none. */
static void test_meta_roundtrip(void) {
  char path[1024], err[512] = "";
  const int w = 5, h = 4;
  float plane[20];
  const char *names[1] = {"elevation"};
  const float *data[1] = {plane};
  double rain = 1234.5678901234567, time = 1800.0, steps = 421.0;
  double vec[6] = {-0.0, 1e-300, 3.0, -4.5, 1e300, 2.0 / 3.0};
  double nan_value = NAN;
  char *dev[1] = {"pthread-skylake (Portable Computing Language)"};
  char *tags[3] = {"a", "", "r\xc3\xa9seau"};
  gr_exr_meta_field fields[7];
  gr_exr_meta meta;
  gr_exr_image img, mem;
  gr_status st;
  int k;
  memset(fields, 0, sizeof fields);
  memset(&meta, 0, sizeof meta);
  for (k = 0; k < w * h; ++k)
    plane[k] = (float)k * 0.5f;
  fields[0] = (gr_exr_meta_field){"rain_volume", 0, 1, 1, &rain, NULL};
  fields[1] = (gr_exr_meta_field){"time", 0, 1, 1, &time, NULL};
  fields[2] = (gr_exr_meta_field){"infiltrated_volume_long_name", 0, 1, 1, &steps, NULL};
  fields[3] = (gr_exr_meta_field){"pairs", 0, 2, 6, vec, NULL};
  fields[4] = (gr_exr_meta_field){"graupel_device", 1, 1, 1, NULL, dev};
  fields[5] = (gr_exr_meta_field){"tags", 1, 1, 3, NULL, tags};
  fields[6] = (gr_exr_meta_field){"balance_error", 0, 1, 1, &nan_value, NULL};
  meta.has_spacing = 1;
  meta.spacing[0] = 74.5;
  meta.spacing[1] = 92.1;
  meta.has_origin = 1;
  meta.origin[0] = 100.0;
  meta.origin[1] = 200.0;
  meta.origin[2] = 0.0;
  meta.nfields = 7;
  meta.fields = fields;
  scratch_path(path, sizeof path, "meta.exr");
  st = gr_exr_write_meta(path, w, h, 1, names, data, GR_EXR_FLOAT, &meta, err, sizeof err);
  CHECK_MSG(st == GR_OK, "%s", err);
  memset(&img, 0, sizeof img);
  st = gr_exr_read(path, &img, err, sizeof err);
  CHECK_MSG(st == GR_OK, "%s", err);
  if (st == GR_OK) {
    const gr_exr_meta *m = &img.meta;
    const gr_exr_meta_field *f;
    CHECK(img.width == w && img.height == h && img.nchannels == 1);
    CHECK(img.nchannels == 1 && img.data[0][7] == 3.5f);
    CHECK(m->has_spacing && m->spacing[0] == 74.5 && m->spacing[1] == 92.1);
    CHECK(m->has_origin && m->origin[0] == 100.0 && m->origin[1] == 200.0 && m->origin[2] == 0.0);
    CHECK_MSG(m->nfields == 7, "%d fields", m->nfields);
    f = find_meta_field(m, "rain_volume");
    CHECK(f && !f->is_string && f->count == 1 && same_double_bits(f->numbers[0], rain));
    f = find_meta_field(m, "time");
    CHECK(f && f->count == 1 && f->numbers[0] == 1800.0);
    f = find_meta_field(m, "infiltrated_volume_long_name");
    CHECK(f && f->count == 1 && f->numbers[0] == 421.0);
    f = find_meta_field(m, "pairs");
    CHECK(f && !f->is_string && f->ncomponents == 2 && f->count == 6);
    for (k = 0; f && f->count == 6 && k < 6; ++k)
      CHECK_MSG(same_double_bits(f->numbers[k], vec[k]), "pairs[%d] %.17g", k, f->numbers[k]);
    f = find_meta_field(m, "graupel_device");
    CHECK(f && f->is_string && f->count == 1 && strcmp(f->strings[0], dev[0]) == 0);
    f = find_meta_field(m, "tags");
    CHECK(f && f->is_string && f->count == 3 && strcmp(f->strings[0], "a") == 0 &&
          f->strings[1][0] == '\0' && strcmp(f->strings[2], tags[2]) == 0);
    f = find_meta_field(m, "balance_error");
    CHECK(f && f->count == 1 && isnan(f->numbers[0]));
  }
  /* The same from memory. */
  {
    FILE *fp = fopen(path, "rb");
    unsigned char *bytes = (unsigned char *)malloc(1 << 16);
    size_t n = fp && bytes ? fread(bytes, 1, 1 << 16, fp) : 0;
    if (fp)
      fclose(fp);
    memset(&mem, 0, sizeof mem);
    st = gr_exr_read_memory(bytes, n, "meta", &mem, err, sizeof err);
    CHECK_MSG(st == GR_OK, "%s", err);
    CHECK(mem.meta.has_spacing && mem.meta.spacing[1] == 92.1 && mem.meta.nfields == 7);
    gr_exr_image_free(&mem);
    free(bytes);
  }
  gr_exr_meta_free(&img.meta);
  CHECK(img.meta.nfields == 0 && img.meta.fields == NULL && !img.meta.has_spacing);
  gr_exr_image_free(&img);
  gr_exr_meta_free(NULL);

  /* Without meta: no graupel attributes, the old behaviour. */
  scratch_path(path, sizeof path, "meta_none.exr");
  st = gr_exr_write(path, w, h, 1, names, data, GR_EXR_FLOAT, err, sizeof err);
  CHECK_MSG(st == GR_OK, "%s", err);
  memset(&img, 0, sizeof img);
  st = gr_exr_read(path, &img, err, sizeof err);
  CHECK(st == GR_OK && !img.meta.has_spacing && !img.meta.has_origin && img.meta.nfields == 0);
  gr_exr_image_free(&img);
}

/* The writer refuses bad meta with a sentence and writes nothing. */
static void expect_meta_write_error(const gr_exr_meta *meta, const char *what) {
  char path[1024], err[512] = "";
  float plane[4] = {1, 2, 3, 4};
  const char *names[1] = {"elevation"};
  const float *data[1] = {plane};
  gr_status st;
  scratch_path(path, sizeof path, "meta_bad_write.exr");
  remove(path);
  st = gr_exr_write_meta(path, 2, 2, 1, names, data, GR_EXR_FLOAT, meta, err, sizeof err);
  CHECK_MSG(st == GR_ERR_INVALID_ARGUMENT, "%s: status %d", what, (int)st);
  CHECK_MSG(is_sentence_with(err, path), "%s: '%s'", what, err);
  CHECK_MSG(!file_exists(path), "%s: a file was written", what);
}

/* Hostile headers written with OpenEXR's C API, one per `which`. */
enum {
  BAD_SPACING_NAN,
  BAD_SPACING_ZERO,
  BAD_SPACING_NEGATIVE,
  BAD_SPACING_HUGE,
  BAD_SPACING_TYPE,
  BAD_ORIGIN_INF,
  BAD_ORIGIN_TYPE,
  BAD_FIELD_NO_NAME,
  BAD_FIELD_TYPE,
  BAD_DOUBLES_SIZE,
  BAD_DOUBLES_TUPLES,
  BAD_DOUBLES_COUNT,
  BAD_TOO_MANY_FIELDS,
  BAD_COUNT
};

static exr_result_t hostile_attrs(exr_context_t ctxt, int part, int which) {
  exr_attr_v2d_t sp = {74.5, 92.1};
  exr_attr_v3d_t org = {100.0, 200.0, 0.0};
  exr_attr_v2f_t spf = {1.0f, 1.0f};
  unsigned char blob[4 + 8 * 6];
  exr_result_t rv = EXR_ERR_SUCCESS;
  int k;
  memset(blob, 0, sizeof blob);
  blob[0] = 2;
  switch (which) {
  case BAD_SPACING_NAN:
    sp.x = NAN;
    return exr_attr_set_v2d(ctxt, part, "graupel.spacing", &sp);
  case BAD_SPACING_ZERO:
    sp.y = 0.0;
    return exr_attr_set_v2d(ctxt, part, "graupel.spacing", &sp);
  case BAD_SPACING_NEGATIVE:
    sp.x = -3.0;
    return exr_attr_set_v2d(ctxt, part, "graupel.spacing", &sp);
  case BAD_SPACING_HUGE:
    sp.x = 1e300;
    return exr_attr_set_v2d(ctxt, part, "graupel.spacing", &sp);
  case BAD_SPACING_TYPE:
    return exr_attr_set_v2f(ctxt, part, "graupel.spacing", &spf);
  case BAD_ORIGIN_INF:
    org.z = INFINITY;
    return exr_attr_set_v3d(ctxt, part, "graupel.origin", &org);
  case BAD_ORIGIN_TYPE:
    return exr_attr_set_double(ctxt, part, "graupel.origin", 5.0);
  case BAD_FIELD_NO_NAME:
    return exr_attr_set_double(ctxt, part, "graupel.field.", 5.0);
  case BAD_FIELD_TYPE:
    return exr_attr_set_int(ctxt, part, "graupel.field.steps", 5);
  case BAD_DOUBLES_SIZE:
    return exr_attr_set_user(ctxt, part, "graupel.field.v", GR_EXR_DOUBLES_TYPE, 4 + 8 * 2 + 3,
                             blob);
  case BAD_DOUBLES_TUPLES:
    blob[0] = 4; /* 6 values are not whole tuples of 4 */
    return exr_attr_set_user(ctxt, part, "graupel.field.v", GR_EXR_DOUBLES_TYPE,
                             (int32_t)sizeof blob, blob);
  case BAD_DOUBLES_COUNT: {
    /* One value more than allowed. */
    size_t size = 4 + 8 * ((size_t)GR_EXR_MAX_META_VALUES + 1);
    unsigned char *big = (unsigned char *)calloc(size, 1);
    if (big == NULL)
      return EXR_ERR_OUT_OF_MEMORY;
    big[0] = 1;
    rv = exr_attr_set_user(ctxt, part, "graupel.field.v", GR_EXR_DOUBLES_TYPE, (int32_t)size, big);
    free(big);
    return rv;
  }
  case BAD_TOO_MANY_FIELDS:
    for (k = 0; k <= GR_EXR_MAX_META_FIELDS && rv == EXR_ERR_SUCCESS; ++k) {
      char name[64];
      snprintf(name, sizeof name, "graupel.field.f%d", k);
      rv = exr_attr_set_double(ctxt, part, name, (double)k);
    }
    return rv;
  default:
    return EXR_ERR_INVALID_ARGUMENT;
  }
}

static void test_meta_bad_values(void) {
  static const char *const what[BAD_COUNT] = {
      "spacing NaN",    "spacing 0",     "spacing -3",           "spacing 1e300", "spacing v2f",
      "origin inf",     "origin double", "field without a name", "field int",     "doubles size",
      "doubles tuples", "doubles count", "1025 fields"};
  const double nan_value = NAN;
  double one = 1.0;
  gr_exr_meta_field f[2];
  gr_exr_meta m;
  int which;

  /* Writer. */
  memset(&m, 0, sizeof m);
  m.has_spacing = 1;
  m.spacing[0] = nan_value;
  m.spacing[1] = 1.0;
  expect_meta_write_error(&m, "write: spacing NaN");
  m.spacing[0] = 0.0;
  expect_meta_write_error(&m, "write: spacing 0");
  m.spacing[0] = -74.5;
  expect_meta_write_error(&m, "write: spacing negative");
  m.spacing[0] = INFINITY;
  expect_meta_write_error(&m, "write: spacing inf");
  memset(&m, 0, sizeof m);
  m.has_origin = 1;
  m.origin[1] = nan_value;
  expect_meta_write_error(&m, "write: origin NaN");
  memset(&m, 0, sizeof m);
  memset(f, 0, sizeof f);
  m.fields = f;
  m.nfields = 1;
  f[0] = (gr_exr_meta_field){"", 0, 1, 1, &one, NULL};
  expect_meta_write_error(&m, "write: empty name");
  f[0] = (gr_exr_meta_field){"x", 0, 1, 0, &one, NULL};
  expect_meta_write_error(&m, "write: no values");
  f[0] = (gr_exr_meta_field){"x", 0, 1, GR_EXR_MAX_META_VALUES + 1, &one, NULL};
  expect_meta_write_error(&m, "write: too many values");
  f[0] = (gr_exr_meta_field){"x", 0, 2, 3, &one, NULL};
  expect_meta_write_error(&m, "write: not whole tuples");
  f[0] = (gr_exr_meta_field){"x", 1, 1, 1, NULL, NULL};
  expect_meta_write_error(&m, "write: no strings");
  f[0] = (gr_exr_meta_field){"x", 0, 1, 1, &one, NULL};
  f[1] = (gr_exr_meta_field){"x", 0, 1, 1, &one, NULL};
  m.nfields = 2;
  expect_meta_write_error(&m, "write: a name twice");
  m.nfields = GR_EXR_MAX_META_FIELDS + 1;
  expect_meta_write_error(&m, "write: too many fields");

  /* Reader: every hostile header fails with a sentence naming the file and
   * leaves the output untouched. */
  for (which = 0; which < BAD_COUNT; ++which) {
    char path[1024], name[64], err[512] = "";
    capi_spec s = capi_default();
    gr_exr_image img;
    gr_status st;
    s.attrs = &hostile_attrs;
    s.which = which;
    snprintf(name, sizeof name, "meta_bad_%d.exr", which);
    scratch_path(path, sizeof path, name);
    CHECK_MSG(capi_write(path, &s), "%s: could not write", what[which]);
    sentinel(&img);
    st = gr_exr_read(path, &img, err, sizeof err);
    CHECK_MSG(st == GR_ERR_FORMAT, "%s: status %d", what[which], (int)st);
    CHECK_MSG(is_sentence_with(err, path), "%s: '%s'", what[which], err);
    CHECK_MSG(is_sentinel(&img), "%s: output touched", what[which]);
    printf("  %-20s %s\n", what[which], err);
    if (st == GR_OK)
      gr_exr_image_free(&img);
  }
}

static const gr_subtest tests[] = {
    {"roundtrips", test_roundtrips, 0},
    {"file_orientation", test_file_orientation, 0},
    {"half_rounding", test_half_rounding, 0},
    {"equal_size_chunk", test_equal_size_chunk, 0},
    {"names_roundtrip", test_names_roundtrip, 0},
    {"capi_inputs", test_capi_inputs, 0},
    {"bad_files", test_bad_files, 0},
    {"implausible_chunks", test_implausible_chunks, 0},
    {"undecodable_compression", test_undecodable_compression, 0},
    {"memory_reads", test_memory_reads, 0},
    {"write_errors", test_write_errors, 0},
    {"write_atomic", test_write_atomic, 0},
    {"helpers", test_helpers, 0},
    {"meta_roundtrip", test_meta_roundtrip, 0},
    {"meta_bad_values", test_meta_bad_values, 0},
};

/* test_exr [--scratch DIR | DIR] [--list | SUBTEST...]: the scratch
 * directory must exist and be writable (default: the current directory); a
 * bare first argument with a '/' is taken as the directory, as before. */
int main(int argc, char **argv) {
  char probe[1024];
  if (argc > 2 && strcmp(argv[1], "--scratch") == 0) {
    g_dir = argv[2];
    argv[2] = argv[0];
    argc -= 2;
    argv += 2;
  } else if (argc > 1 && strchr(argv[1], '/') != NULL) {
    g_dir = argv[1];
    argv[1] = argv[0];
    argc -= 1;
    argv += 1;
  }
  if (!(argc > 1 && strcmp(argv[1], "--list") == 0)) {
    scratch_path(probe, sizeof probe, "probe.tmp");
    if (!save_bytes(probe, "x", 1)) {
      fprintf(stderr, "cannot write into the scratch directory '%s'\n", g_dir);
      return 2;
    }
    remove(probe);
  }
  return gr_test_main(argc, argv, tests, (int)(sizeof tests / sizeof tests[0]), NULL, NULL);
}
