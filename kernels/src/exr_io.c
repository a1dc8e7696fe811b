/*
 * exr_io.c - height fields and named fields in OpenEXR files, through
 * OpenEXR's C API (OpenEXRCore).
 *
 * Reading: part 0 of a scanline or tiled file (level 0 only for multi-level
 * tiled files); every channel must be HALF or FLOAT with sampling 1. The
 * library decodes each chunk straight into the output planes as float (it
 * widens half to float itself), rows in file order; the planes are flipped at
 * the end so that row 0 is the southern edge. gr_exr_read opens a file;
 * gr_exr_read_memory gives OpenEXR read and size callbacks over a buffer
 * instead; everything after opening is the one function read_exr.
 *
 * Writing: one scanline part, ZIP compression, every channel HALF or FLOAT.
 * Each chunk's rows are copied, flipped, into a float staging buffer; the
 * library packs (and for HALF storage rounds to nearest even) from it.
 *
 * Header attributes: graupel.spacing, graupel.origin and graupel.field.*
 * (exr_io.h lists them) carry an image's geometry and field data; the
 * reader checks each before it allocates anything for the pixels.
 *
 * The library's error messages are caught by an error handler that finds its
 * buffer through the context's user data, so nothing is printed and there is
 * no global state.
 */
#include "graupel/exr_io.h"
#include "graupel/memory.h"

#include <openexr.h>

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* Error text                                                               */
/* ------------------------------------------------------------------------ */

/* The first message OpenEXR reported for a context (later ones are usually
 * consequences of the first). */
typedef struct exr_msg {
  char text[512];
  int have;
} exr_msg;

static void exr_capture_error(exr_const_context_t ctxt, exr_result_t code, const char *msg) {
  void *ud = NULL;
  exr_msg *m;
  (void)code;
  if (ctxt == NULL || exr_get_user_data(ctxt, &ud) != EXR_ERR_SUCCESS || ud == NULL)
    return;
  m = (exr_msg *)ud;
  if (m->have || msg == NULL)
    return;
  snprintf(m->text, sizeof m->text, "%s", msg);
  /* A sentence ends with our own period; drop trailing dots and newlines. */
  {
    size_t n = strlen(m->text);
    while (n > 0 && (m->text[n - 1] == '.' || m->text[n - 1] == '\n' || m->text[n - 1] == ' '))
      m->text[--n] = '\0';
  }
  m->have = 1;
}

static void set_err(char *err, size_t err_len, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static void set_err(char *err, size_t err_len, const char *fmt, ...) {
  va_list ap;
  if (err == NULL || err_len == 0)
    return;
  va_start(ap, fmt);
  vsnprintf(err, err_len, fmt, ap);
  va_end(ap);
}

/* The library's own words for a failure: the captured message, or the
 * generic text of the code. */
static const char *exr_detail(const exr_msg *m, exr_result_t rv) {
  if (m->have)
    return m->text;
  return exr_get_default_error_message(rv);
}

/* Status for a failed OpenEXR call while reading. */
static gr_status read_status(exr_result_t rv) {
  switch (rv) {
  case EXR_ERR_OUT_OF_MEMORY:
    return GR_ERR_OUT_OF_MEMORY;
  case EXR_ERR_FILE_ACCESS:
    return GR_ERR_IO;
  default:
    return GR_ERR_FORMAT;
  }
}

static const char *pixel_type_name(exr_pixel_type_t t) {
  switch (t) {
  case EXR_PIXEL_UINT:
    return "UINT";
  case EXR_PIXEL_HALF:
    return "HALF";
  case EXR_PIXEL_FLOAT:
    return "FLOAT";
  default:
    return "unknown";
  }
}

/* ------------------------------------------------------------------------ */
/* Image helpers                                                            */
/* ------------------------------------------------------------------------ */

void gr_exr_image_free(gr_exr_image *img) {
  int c;
  if (img == NULL)
    return;
  if (img->names != NULL) {
    for (c = 0; c < img->nchannels; ++c)
      free(img->names[c]);
  }
  if (img->data != NULL) {
    for (c = 0; c < img->nchannels; ++c)
      free(img->data[c]);
  }
  free(img->names);
  free(img->types);
  free(img->data);
  gr_exr_meta_free(&img->meta);
  memset(img, 0, sizeof *img);
}

void gr_exr_meta_free(gr_exr_meta *meta) {
  int f, k;
  if (meta == NULL)
    return;
  for (f = 0; meta->fields != NULL && f < meta->nfields; ++f) {
    gr_exr_meta_field *fd = &meta->fields[f];
    free(fd->name);
    free(fd->numbers);
    for (k = 0; fd->strings != NULL && k < fd->count; ++k)
      free(fd->strings[k]);
    free(fd->strings);
  }
  free(meta->fields);
  memset(meta, 0, sizeof *meta);
}

int gr_exr_find_channel(const gr_exr_image *img, const char *name) {
  int c;
  if (img == NULL || name == NULL || img->names == NULL)
    return -1;
  for (c = 0; c < img->nchannels; ++c) {
    if (img->names[c] != NULL && strcmp(img->names[c], name) == 0)
      return c;
  }
  return -1;
}

static void flip_rows(float *plane, size_t width, size_t height) {
  size_t top, bottom, i;
  if (height < 2)
    return;
  for (top = 0, bottom = height - 1; top < bottom; ++top, --bottom) {
    float *a = plane + top * width;
    float *b = plane + bottom * width;
    for (i = 0; i < width; ++i) {
      float t = a[i];
      a[i] = b[i];
      b[i] = t;
    }
  }
}

/* ------------------------------------------------------------------------ */
/* Geometry and field data in the header (graupel.* attributes)             */
/* ------------------------------------------------------------------------ */

#define META_SPACING "graupel.spacing"
#define META_ORIGIN "graupel.origin"
/* Largest spacing and origin coordinate kept: beyond them extents overflow
 * what any terrain needs, and a hostile header could make bounds infinite. */
#define META_MAX_SPACING 1.0e9
#define META_MAX_ORIGIN 1.0e15
/* Longest string value kept in a field-data array. */
#define META_MAX_STRING 65536

static char *dup_bytes(const char *s, size_t n) {
  char *d = (char *)malloc(n + 1);
  if (d != NULL) {
    if (n > 0)
      memcpy(d, s, n);
    d[n] = '\0';
  }
  return d;
}

static int spacing_ok(const double v[2]) {
  return isfinite(v[0]) && isfinite(v[1]) && v[0] > 0.0 && v[1] > 0.0 && v[0] <= META_MAX_SPACING &&
         v[1] <= META_MAX_SPACING;
}

static int origin_ok(const double v[3]) {
  return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]) && fabs(v[0]) <= META_MAX_ORIGIN &&
         fabs(v[1]) <= META_MAX_ORIGIN && fabs(v[2]) <= META_MAX_ORIGIN;
}

static void put_le64(unsigned char *p, double v) {
  uint64_t u;
  int k;
  memcpy(&u, &v, sizeof u);
  for (k = 0; k < 8; ++k)
    p[k] = (unsigned char)(u >> (8 * k));
}

static double get_le64(const unsigned char *p) {
  uint64_t u = 0;
  double v;
  int k;
  for (k = 0; k < 8; ++k)
    u |= (uint64_t)p[k] << (8 * k);
  memcpy(&v, &u, sizeof v);
  return v;
}

static int32_t get_le32(const unsigned char *p) {
  uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
  return (int32_t)u;
}

/* One graupel.field.* attribute into fd (zeroed by the caller). Returns
 * GR_OK, or GR_ERR_FORMAT / GR_ERR_OUT_OF_MEMORY with a sentence. */
static gr_status read_meta_field(exr_const_context_t ctxt, const char *label,
                                 const exr_attribute_t *a, gr_exr_meta_field *fd, char *err,
                                 size_t err_len) {
  const char *fname = a->name + strlen(GR_EXR_FIELD_PREFIX);
  int k;
  if (fname[0] == '\0') {
    set_err(err, err_len,
            "Cannot read '%s': the header attribute '%s' names no field-data array; rename it "
            "%sNAME or remove it.",
            label, a->name, GR_EXR_FIELD_PREFIX);
    return GR_ERR_FORMAT;
  }
  fd->name = dup_bytes(fname, strlen(fname));
  if (fd->name == NULL)
    goto oom;
  if (a->type == EXR_ATTR_DOUBLE) {
    fd->ncomponents = 1;
    fd->count = 1;
    fd->numbers = (double *)malloc(sizeof(double));
    if (fd->numbers == NULL)
      goto oom;
    fd->numbers[0] = a->d;
    return GR_OK;
  }
  if (a->type == EXR_ATTR_OPAQUE && a->type_name != NULL &&
      strcmp(a->type_name, GR_EXR_DOUBLES_TYPE) == 0) {
    const char *tname = NULL;
    int32_t size = 0;
    const void *bytes = NULL;
    int32_t ncomp, n;
    if (exr_attr_get_user(ctxt, 0, a->name, &tname, &size, &bytes) != EXR_ERR_SUCCESS ||
        bytes == NULL || size < 12 || (size - 4) % 8 != 0) {
      set_err(err, err_len,
              "Cannot read '%s': the header attribute '%s' holds %d bytes, which is not a "
              "component count and whole doubles; the file is corrupt.",
              label, a->name, (int)size);
      return GR_ERR_FORMAT;
    }
    ncomp = get_le32((const unsigned char *)bytes);
    n = (size - 4) / 8;
    if (n > GR_EXR_MAX_META_VALUES || ncomp < 1 || n % ncomp != 0) {
      set_err(err, err_len,
              "Cannot read '%s': the header attribute '%s' holds %d values in tuples of %d, and "
              "1 to %d values in whole tuples are allowed; the file is corrupt.",
              label, a->name, (int)n, (int)ncomp, GR_EXR_MAX_META_VALUES);
      return GR_ERR_FORMAT;
    }
    fd->numbers = (double *)malloc((size_t)n * sizeof(double));
    if (fd->numbers == NULL)
      goto oom;
    for (k = 0; k < n; ++k)
      fd->numbers[k] = get_le64((const unsigned char *)bytes + 4 + 8 * (size_t)k);
    fd->ncomponents = ncomp;
    fd->count = n;
    return GR_OK;
  }
  if (a->type == EXR_ATTR_STRING || a->type == EXR_ATTR_STRING_VECTOR) {
    int n = a->type == EXR_ATTR_STRING ? 1 : (a->stringvector ? a->stringvector->n_strings : 0);
    if (n < 1 || n > GR_EXR_MAX_META_VALUES) {
      set_err(err, err_len,
              "Cannot read '%s': the header attribute '%s' holds %d strings, and 1 to %d are "
              "allowed.",
              label, a->name, n, GR_EXR_MAX_META_VALUES);
      return GR_ERR_FORMAT;
    }
    fd->strings = (char **)calloc((size_t)n, sizeof(char *));
    if (fd->strings == NULL)
      goto oom;
    fd->is_string = 1;
    fd->ncomponents = 1;
    fd->count = n;
    for (k = 0; k < n; ++k) {
      const exr_attr_string_t *str =
          a->type == EXR_ATTR_STRING ? a->string : &a->stringvector->strings[k];
      if (str == NULL || str->length < 0 || str->length > META_MAX_STRING ||
          (str->length > 0 && str->str == NULL)) {
        set_err(err, err_len,
                "Cannot read '%s': string %d of the header attribute '%s' is missing or longer "
                "than %d bytes.",
                label, k, a->name, META_MAX_STRING);
        return GR_ERR_FORMAT;
      }
      fd->strings[k] = dup_bytes(str->length > 0 ? str->str : "", (size_t)str->length);
      if (fd->strings[k] == NULL)
        goto oom;
    }
    return GR_OK;
  }
  set_err(err, err_len,
          "Cannot read '%s': the header attribute '%s' is of type '%s', and field-data arrays "
          "are double, %s, string or stringvector.",
          label, a->name, a->type_name ? a->type_name : "unknown", GR_EXR_DOUBLES_TYPE);
  return GR_ERR_FORMAT;
oom:
  set_err(err, err_len, "Cannot read '%s': out of memory for the header attribute '%s'.", label,
          a->name);
  return GR_ERR_OUT_OF_MEMORY;
}

/* Every graupel.* attribute of part 0 into meta (zeroed by the caller; the
 * caller frees it on failure). Other attributes are ignored. */
static gr_status read_meta(exr_const_context_t ctxt, const char *label, gr_exr_meta *meta,
                           char *err, size_t err_len) {
  int32_t nattr = 0, i, nfields = 0;
  const size_t plen = strlen(GR_EXR_FIELD_PREFIX);
  if (exr_get_attribute_count(ctxt, 0, &nattr) != EXR_ERR_SUCCESS || nattr < 0)
    return GR_OK;
  for (i = 0; i < nattr; ++i) {
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_index(ctxt, 0, EXR_ATTR_LIST_FILE_ORDER, i, &a) == EXR_ERR_SUCCESS &&
        a != NULL && a->name != NULL && strncmp(a->name, GR_EXR_FIELD_PREFIX, plen) == 0)
      ++nfields;
  }
  if (nfields > GR_EXR_MAX_META_FIELDS) {
    set_err(err, err_len,
            "Cannot read '%s': its header holds %d field-data arrays, and at most %d are "
            "allowed.",
            label, (int)nfields, GR_EXR_MAX_META_FIELDS);
    return GR_ERR_FORMAT;
  }
  if (nfields > 0) {
    meta->fields = (gr_exr_meta_field *)calloc((size_t)nfields, sizeof(gr_exr_meta_field));
    if (meta->fields == NULL) {
      set_err(err, err_len, "Cannot read '%s': out of memory for its field-data arrays.", label);
      return GR_ERR_OUT_OF_MEMORY;
    }
  }
  for (i = 0; i < nattr; ++i) {
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_index(ctxt, 0, EXR_ATTR_LIST_FILE_ORDER, i, &a) != EXR_ERR_SUCCESS ||
        a == NULL || a->name == NULL)
      continue;
    if (strcmp(a->name, META_SPACING) == 0) {
      double v[2] = {0.0, 0.0};
      if (a->type != EXR_ATTR_V2D || a->v2d == NULL) {
        set_err(err, err_len,
                "Cannot read '%s': its header attribute '%s' is of type '%s', not v2d.", label,
                a->name, a->type_name ? a->type_name : "unknown");
        return GR_ERR_FORMAT;
      }
      v[0] = a->v2d->x;
      v[1] = a->v2d->y;
      if (!spacing_ok(v)) {
        set_err(err, err_len,
                "Cannot read '%s': its spacing (%s) is %g by %g m, and must be finite, above 0 "
                "and at most %g m; fix or remove the attribute.",
                label, a->name, v[0], v[1], META_MAX_SPACING);
        return GR_ERR_FORMAT;
      }
      meta->has_spacing = 1;
      meta->spacing[0] = v[0];
      meta->spacing[1] = v[1];
    } else if (strcmp(a->name, META_ORIGIN) == 0) {
      double v[3] = {0.0, 0.0, 0.0};
      if (a->type != EXR_ATTR_V3D || a->v3d == NULL) {
        set_err(err, err_len,
                "Cannot read '%s': its header attribute '%s' is of type '%s', not v3d.", label,
                a->name, a->type_name ? a->type_name : "unknown");
        return GR_ERR_FORMAT;
      }
      v[0] = a->v3d->x;
      v[1] = a->v3d->y;
      v[2] = a->v3d->z;
      if (!origin_ok(v)) {
        set_err(err, err_len,
                "Cannot read '%s': its origin (%s) is (%g, %g, %g) m, and must be finite and "
                "within %g m of 0; fix or remove the attribute.",
                label, a->name, v[0], v[1], v[2], META_MAX_ORIGIN);
        return GR_ERR_FORMAT;
      }
      meta->has_origin = 1;
      memcpy(meta->origin, v, sizeof v);
    } else if (strncmp(a->name, GR_EXR_FIELD_PREFIX, plen) == 0 && meta->nfields < nfields) {
      gr_status st = read_meta_field(ctxt, label, a, &meta->fields[meta->nfields], err, err_len);
      /* Counted before the check, so the caller frees a half-filled field. */
      ++meta->nfields;
      if (st != GR_OK)
        return st;
    }
  }
  return GR_OK;
}

/* Checks meta for the writer and finds whether any attribute name needs
 * OpenEXR's long names. */
static gr_status check_meta(const char *path, const gr_exr_meta *meta, int *longnames, char *err,
                            size_t err_len) {
  const size_t plen = strlen(GR_EXR_FIELD_PREFIX);
  int f, k;
  if (meta->has_spacing && !spacing_ok(meta->spacing)) {
    set_err(err, err_len,
            "Cannot write '%s': the spacing is %g by %g m; give finite values above 0 and at "
            "most %g m.",
            path, meta->spacing[0], meta->spacing[1], META_MAX_SPACING);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (meta->has_origin && !origin_ok(meta->origin)) {
    set_err(err, err_len,
            "Cannot write '%s': the origin is (%g, %g, %g) m; give finite values within %g m "
            "of 0.",
            path, meta->origin[0], meta->origin[1], meta->origin[2], META_MAX_ORIGIN);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (meta->nfields < 0 || meta->nfields > GR_EXR_MAX_META_FIELDS ||
      (meta->nfields > 0 && meta->fields == NULL)) {
    set_err(err, err_len,
            "Cannot write '%s': %d field-data arrays were given, and 0 to %d are allowed.", path,
            meta->nfields, GR_EXR_MAX_META_FIELDS);
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (f = 0; f < meta->nfields; ++f) {
    const gr_exr_meta_field *fd = &meta->fields[f];
    size_t len = fd->name ? strlen(fd->name) : 0;
    if (len == 0 || len > GR_EXR_MAX_NAME - plen) {
      set_err(err, err_len,
              "Cannot write '%s': field-data array %d has a name of %zu characters; give 1 to "
              "%zu.",
              path, f, len, (size_t)GR_EXR_MAX_NAME - plen);
      return GR_ERR_INVALID_ARGUMENT;
    }
    if (plen + len > 31)
      *longnames = 1;
    for (k = 0; k < f; ++k) {
      if (strcmp(meta->fields[k].name, fd->name) == 0) {
        set_err(err, err_len, "Cannot write '%s': the field-data array '%s' is given twice.", path,
                fd->name);
        return GR_ERR_INVALID_ARGUMENT;
      }
    }
    if (fd->count < 1 || fd->count > GR_EXR_MAX_META_VALUES ||
        (fd->is_string
             ? fd->strings == NULL
             : (fd->numbers == NULL || fd->ncomponents < 1 || fd->count % fd->ncomponents != 0))) {
      set_err(err, err_len,
              "Cannot write '%s': the field-data array '%s' has %d values in tuples of %d; give "
              "1 to %d values in whole tuples.",
              path, fd->name, fd->count, fd->ncomponents, GR_EXR_MAX_META_VALUES);
      return GR_ERR_INVALID_ARGUMENT;
    }
    for (k = 0; fd->is_string && k < fd->count; ++k) {
      if (fd->strings[k] == NULL || strlen(fd->strings[k]) > META_MAX_STRING) {
        set_err(err, err_len,
                "Cannot write '%s': string %d of the field-data array '%s' is missing or longer "
                "than %d bytes.",
                path, k, fd->name, META_MAX_STRING);
        return GR_ERR_INVALID_ARGUMENT;
      }
    }
  }
  return GR_OK;
}

/* The graupel.* attributes of a checked meta, into part 0 before its header
 * is written. */
static exr_result_t write_meta(exr_context_t ctxt, int part, const gr_exr_meta *meta) {
  exr_result_t rv = EXR_ERR_SUCCESS;
  int f;
  char aname[GR_EXR_MAX_NAME + 1];
  if (meta->has_spacing) {
    exr_attr_v2d_t v;
    v.x = meta->spacing[0];
    v.y = meta->spacing[1];
    rv = exr_attr_set_v2d(ctxt, part, META_SPACING, &v);
  }
  if (rv == EXR_ERR_SUCCESS && meta->has_origin) {
    exr_attr_v3d_t v;
    v.x = meta->origin[0];
    v.y = meta->origin[1];
    v.z = meta->origin[2];
    rv = exr_attr_set_v3d(ctxt, part, META_ORIGIN, &v);
  }
  for (f = 0; f < meta->nfields && rv == EXR_ERR_SUCCESS; ++f) {
    const gr_exr_meta_field *fd = &meta->fields[f];
    snprintf(aname, sizeof aname, "%s%s", GR_EXR_FIELD_PREFIX, fd->name);
    if (fd->is_string && fd->count == 1) {
      rv = exr_attr_set_string(ctxt, part, aname, fd->strings[0]);
    } else if (fd->is_string) {
      rv = exr_attr_set_string_vector(ctxt, part, aname, (int32_t)fd->count,
                                      (const char **)fd->strings);
    } else if (fd->count == 1) {
      rv = exr_attr_set_double(ctxt, part, aname, fd->numbers[0]);
    } else {
      size_t size = 4 + 8 * (size_t)fd->count;
      unsigned char *b = (unsigned char *)malloc(size);
      int k;
      if (b == NULL)
        return EXR_ERR_OUT_OF_MEMORY;
      b[0] = (unsigned char)fd->ncomponents;
      b[1] = (unsigned char)(fd->ncomponents >> 8);
      b[2] = (unsigned char)(fd->ncomponents >> 16);
      b[3] = (unsigned char)(fd->ncomponents >> 24);
      for (k = 0; k < fd->count; ++k)
        put_le64(b + 4 + 8 * (size_t)k, fd->numbers[k]);
      rv = exr_attr_set_user(ctxt, part, aname, GR_EXR_DOUBLES_TYPE, (int32_t)size, b);
      free(b);
    }
  }
  return rv;
}

/* ------------------------------------------------------------------------ */
/* Reading                                                                  */
/* ------------------------------------------------------------------------ */

/* Layout of part 0's level-0 chunks. */
typedef struct chunk_layout {
  exr_context_t ctxt;
  int tiled;
  exr_attr_box2i_t dw;
  int64_t width, height;
  int64_t lines;    /* scanlines per chunk (scanline parts) */
  int64_t tw, th;   /* tile size (tiled parts) */
  int64_t ntx, nty; /* tile counts at level 0 */
  exr_compression_t compression;
  int undecodable; /* compression the library cannot decompress */
  uint64_t expand; /* most bytes one packed byte may unpack to (0: no bound) */
} chunk_layout;

/* Where walk_chunks stopped: the chunk (tile indices, or its first scanline)
 * and, when its sizes were implausible, what it claimed. */
typedef struct chunk_fault {
  int64_t x, y;
  int implausible;
  uint64_t packed, unpacked;
} chunk_fault;

/* The most bytes one packed byte of a chunk can unpack to, by compression,
 * about twice each method's own limit: zlib's 1032:1 (ZIP, ZIPS; PXR24 packs
 * FLOAT into 3 bytes first), EXR's RLE 64:1, PIZ's Huffman run codes about
 * 410:1, B44's 32 bytes in 3, DWA's RLE or DCT before zlib about 66000:1,
 * twice that for FLOAT. OpenEXR allocates a chunk's unpacked size before it
 * decompresses, and so does this reader for the image, so a chunk that
 * claims more is rejected before anything is allocated: else a few hundred
 * bytes could ask for gigabytes. 0: no bound known. */
static const char *compression_name(exr_compression_t c) {
  static const char *const names[] = {"NONE",  "RLE", "ZIPS", "ZIP",  "PIZ",
                                      "PXR24", "B44", "B44A", "DWAA", "DWAB"};
  if ((int)c >= 0 && (size_t)c < sizeof names / sizeof names[0])
    return names[c];
  return "unknown";
}

static uint64_t max_expansion(exr_compression_t c) {
  switch (c) {
  case EXR_COMPRESSION_NONE:
    return 1;
  case EXR_COMPRESSION_RLE:
    return 128;
  case EXR_COMPRESSION_ZIPS:
  case EXR_COMPRESSION_ZIP:
  case EXR_COMPRESSION_PXR24:
    return 2048;
  case EXR_COMPRESSION_PIZ:
    return 1024;
  case EXR_COMPRESSION_B44:
  case EXR_COMPRESSION_B44A:
    return 32;
  case EXR_COMPRESSION_DWAA:
  case EXR_COMPRESSION_DWAB:
    return (uint64_t)1 << 18;
  default:
    return 0;
  }
}

/* OpenEXRCore before 3.2 cannot decompress DWAA/DWAB ("not yet implemented
 * in C"); only chunks stored raw in such files can be read. */
static int core_decodes_dwa(void) {
  int major = 0, minor = 0, patch = 0;
  const char *extra = NULL;
  exr_get_library_version(&major, &minor, &patch, &extra);
  return major > 3 || (major == 3 && minor >= 2);
}

/* A chunk's packed bytes can hold its unpacked size under L's compression. */
static int chunk_plausible(const chunk_layout *L, const exr_chunk_info_t *cinfo) {
  if (L->expand == 0)
    return 1;
  if (cinfo->packed_size == 0)
    return cinfo->unpacked_size == 0;
  return cinfo->unpacked_size / cinfo->packed_size < L->expand ||
         (cinfo->unpacked_size / cinfo->packed_size == L->expand &&
          cinfo->unpacked_size % cinfo->packed_size == 0);
}

static exr_result_t implausible_chunk(chunk_fault *f, const exr_chunk_info_t *cinfo) {
  f->implausible = 1;
  f->packed = cinfo->packed_size;
  f->unpacked = cinfo->unpacked_size;
  return EXR_ERR_CORRUPT_CHUNK;
}

/* Points each decoder channel at its plane; (x, y) is the chunk's first pixel
 * relative to the data window's corner. */
static int bind_decode_channels(exr_decode_pipeline_t *dec, const gr_exr_image *img, int64_t x,
                                int64_t y) {
  int c;
  for (c = 0; c < dec->channel_count; ++c) {
    exr_coding_channel_info_t *ch = &dec->channels[c];
    int k = gr_exr_find_channel(img, ch->channel_name);
    if (k < 0)
      return 0;
    ch->decode_to_ptr = (uint8_t *)(img->data[k] + (size_t)y * (size_t)img->width + (size_t)x);
    ch->user_pixel_stride = (int32_t)sizeof(float);
    ch->user_line_stride = (int32_t)((size_t)img->width * sizeof(float));
    ch->user_bytes_per_element = (int16_t)sizeof(float);
    ch->user_data_type = EXR_PIXEL_FLOAT;
  }
  return 1;
}

/* Decodes one chunk into img at pixel (x, y) of the data window. */
static exr_result_t decode_chunk(exr_context_t ctxt, const exr_chunk_info_t *cinfo,
                                 exr_decode_pipeline_t *dec, int *dec_live, const gr_exr_image *img,
                                 int64_t x, int64_t y) {
  exr_result_t rv;
  if (!*dec_live) {
    rv = exr_decoding_initialize(ctxt, 0, cinfo, dec);
    if (rv != EXR_ERR_SUCCESS)
      return rv;
    *dec_live = 1;
  } else {
    rv = exr_decoding_update(ctxt, 0, cinfo, dec);
    if (rv != EXR_ERR_SUCCESS)
      return rv;
  }
  if (!bind_decode_channels(dec, img, x, y))
    return EXR_ERR_INCORRECT_CHUNK;
  rv = exr_decoding_choose_default_routines(ctxt, 0, dec);
  if (rv != EXR_ERR_SUCCESS)
    return rv;
  return exr_decoding_run(ctxt, 0, dec);
}

/* Visits every level-0 chunk in order. With img NULL it only reads and checks
 * each chunk's description (offset, size and extent against the file, and
 * its unpacked size against its packed size), which catches truncated,
 * inconsistent and hostile files before any image is allocated; otherwise it
 * decodes the chunk into img, rows in file order. On failure *f names the
 * chunk. */
static exr_result_t walk_chunks(const chunk_layout *L, const gr_exr_image *img,
                                exr_decode_pipeline_t *dec, int *dec_live, chunk_fault *f) {
  exr_result_t rv = EXR_ERR_SUCCESS;
  exr_chunk_info_t cinfo;
  if (!L->tiled) {
    int64_t y;
    for (y = L->dw.min.y; y <= (int64_t)L->dw.max.y; y += L->lines) {
      int64_t expect_h = (int64_t)L->dw.max.y - y + 1;
      if (expect_h > L->lines)
        expect_h = L->lines;
      f->x = 0;
      f->y = y;
      memset(&cinfo, 0, sizeof cinfo);
      rv = exr_read_scanline_chunk_info(L->ctxt, 0, (int)y, &cinfo);
      if (rv == EXR_ERR_SUCCESS &&
          ((int64_t)cinfo.start_y != y || (int64_t)cinfo.height != expect_h ||
           (int64_t)cinfo.width != L->width))
        rv = EXR_ERR_INCORRECT_CHUNK;
      if (rv == EXR_ERR_SUCCESS && !chunk_plausible(L, &cinfo))
        rv = implausible_chunk(f, &cinfo);
      if (rv == EXR_ERR_SUCCESS && img != NULL)
        rv = decode_chunk(L->ctxt, &cinfo, dec, dec_live, img, 0, y - L->dw.min.y);
      if (rv != EXR_ERR_SUCCESS)
        return rv;
    }
  } else {
    int64_t tx, ty;
    for (ty = 0; ty < L->nty; ++ty) {
      for (tx = 0; tx < L->ntx; ++tx) {
        int64_t x0 = tx * L->tw, y0 = ty * L->th;
        int64_t ew = L->width - x0 < L->tw ? L->width - x0 : L->tw;
        int64_t eh = L->height - y0 < L->th ? L->height - y0 : L->th;
        f->x = tx;
        f->y = ty;
        memset(&cinfo, 0, sizeof cinfo);
        rv = exr_read_tile_chunk_info(L->ctxt, 0, (int)tx, (int)ty, 0, 0, &cinfo);
        if (rv == EXR_ERR_SUCCESS && ((int64_t)cinfo.width != ew || (int64_t)cinfo.height != eh))
          rv = EXR_ERR_INCORRECT_CHUNK;
        if (rv == EXR_ERR_SUCCESS && !chunk_plausible(L, &cinfo))
          rv = implausible_chunk(f, &cinfo);
        if (rv == EXR_ERR_SUCCESS && img != NULL)
          rv = decode_chunk(L->ctxt, &cinfo, dec, dec_live, img, x0, y0);
        if (rv != EXR_ERR_SUCCESS)
          return rv;
      }
    }
  }
  return rv;
}

/* Where the bytes come from: a file (bytes NULL: OpenEXR opens the named
 * file itself) or a caller's buffer. It is the context's user data, and msg
 * comes first: exr_capture_error takes the user data for an exr_msg. */
typedef struct read_source {
  exr_msg msg;
  const unsigned char *bytes;
  size_t size;
} read_source;

/* pread semantics over the buffer: a read at or past the end returns 0
 * bytes, one across it the bytes up to the end (OpenEXR turns a short read
 * into EXR_ERR_READ_IO where it needed them all). Thread safe: it only reads. */
static int64_t memory_read(exr_const_context_t ctxt, void *userdata, void *buffer, uint64_t sz,
                           uint64_t offset, exr_stream_error_func_ptr_t error_cb) {
  const read_source *src = (const read_source *)userdata;
  uint64_t n;
  (void)ctxt;
  (void)error_cb;
  if (src == NULL || src->bytes == NULL || (buffer == NULL && sz > 0))
    return -1;
  if (offset >= (uint64_t)src->size)
    return 0;
  n = (uint64_t)src->size - offset;
  if (n > sz)
    n = sz;
  if (n > (uint64_t)INT64_MAX)
    n = (uint64_t)INT64_MAX;
  memcpy(buffer, src->bytes + offset, (size_t)n);
  return (int64_t)n;
}

static int64_t memory_size(exr_const_context_t ctxt, void *userdata) {
  const read_source *src = (const read_source *)userdata;
  (void)ctxt;
  if (src == NULL || src->bytes == NULL)
    return -1;
  return (uint64_t)src->size > (uint64_t)INT64_MAX ? INT64_MAX : (int64_t)src->size;
}

/* gr_exr_read and gr_exr_read_memory: opens the file or the buffer of src
 * (label names it in every message: the path of a file), then parses, checks
 * and decodes part 0. The arguments are checked by the callers. */
static gr_status read_exr(const char *label, read_source *src, gr_exr_image *out, char *err,
                          size_t err_len) {
  gr_status st = GR_OK;
  exr_result_t rv;
  exr_context_t ctxt = NULL;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  exr_decode_pipeline_t dec;
  int dec_live = 0;
  exr_msg *msg = &src->msg;
  exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
  const exr_attr_chlist_t *chlist = NULL;
  chunk_layout L;
  chunk_fault fault;
  size_t npix, c;
  int nparts = 0, pass;
  gr_exr_image img;

  memset(&img, 0, sizeof img);
  memset(&dec, 0, sizeof dec);
  memset(msg, 0, sizeof *msg);
  memset(&L, 0, sizeof L);
  memset(&fault, 0, sizeof fault);

  init.error_handler_fn = &exr_capture_error;
  init.user_data = src;
  init.max_image_width = GR_EXR_MAX_DIM;
  init.max_image_height = GR_EXR_MAX_DIM;
  init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
  if (src->bytes != NULL) {
    /* The label is only a name: OpenEXR opens nothing when read_fn is set. */
    init.read_fn = &memory_read;
    init.size_fn = &memory_size;
  }

  rv = exr_start_read(&ctxt, label, &init);
  if (rv != EXR_ERR_SUCCESS) {
    st = read_status(rv);
    if (rv == EXR_ERR_FILE_ACCESS)
      set_err(err, err_len, "Cannot read '%s': the file cannot be opened (OpenEXR: %s).", label,
              exr_detail(msg, rv));
    else
      set_err(err, err_len, "Cannot read '%s': it is not a valid OpenEXR file (OpenEXR: %s).",
              label, exr_detail(msg, rv));
    goto cleanup;
  }
  L.ctxt = ctxt;

  rv = exr_get_count(ctxt, &nparts);
  if (rv == EXR_ERR_SUCCESS && nparts < 1)
    rv = EXR_ERR_FILE_BAD_HEADER;
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_storage(ctxt, 0, &storage);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_data_window(ctxt, 0, &L.dw);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_channels(ctxt, 0, &chlist);
  if (rv == EXR_ERR_SUCCESS && chlist == NULL)
    rv = EXR_ERR_MISSING_REQ_ATTR;
  if (rv != EXR_ERR_SUCCESS) {
    st = read_status(rv);
    set_err(err, err_len, "Cannot read '%s': its header is incomplete (OpenEXR: %s).", label,
            exr_detail(msg, rv));
    goto cleanup;
  }
  if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
    st = GR_ERR_FORMAT;
    set_err(err, err_len, "Cannot read '%s': it holds deep data, which is not supported.", label);
    goto cleanup;
  }

  /* Size guards, before anything is allocated. */
  L.width = (int64_t)L.dw.max.x - (int64_t)L.dw.min.x + 1;
  L.height = (int64_t)L.dw.max.y - (int64_t)L.dw.min.y + 1;
  if (L.width < 1 || L.height < 1 || L.width > GR_EXR_MAX_DIM || L.height > GR_EXR_MAX_DIM) {
    st = GR_ERR_FORMAT;
    set_err(err, err_len,
            "Cannot read '%s': its data window is %lld by %lld pixels, outside "
            "1 to %d.",
            label, (long long)L.width, (long long)L.height, GR_EXR_MAX_DIM);
    goto cleanup;
  }
  if (chlist->num_channels < 1 || chlist->entries == NULL) {
    st = GR_ERR_FORMAT;
    set_err(err, err_len, "Cannot read '%s': it has no channels.", label);
    goto cleanup;
  }
  npix = (size_t)L.width * (size_t)L.height;
  if (npix > GR_EXR_MAX_SAMPLES / (size_t)chlist->num_channels || npix > SIZE_MAX / sizeof(float)) {
    st = GR_ERR_FORMAT;
    set_err(err, err_len,
            "Cannot read '%s': %lld by %lld pixels in %d channels is more than "
            "the %llu samples allowed.",
            label, (long long)L.width, (long long)L.height, chlist->num_channels,
            (unsigned long long)GR_EXR_MAX_SAMPLES);
    goto cleanup;
  }
  {
    /* The planes, before anything is decoded: a file that does not fit is
     * refused at once, not after minutes of decoding or by a failed malloc
     * under the kernel's overcommit. */
    gr_memory_need need;
    char why[200];
    memset(&need, 0, sizeof(need));
    need.points = (double)npix;
    need.host = (double)npix * (double)chlist->num_channels * sizeof(float);
    if (gr_memory_check(NULL, &need, why, sizeof(why)) != GR_OK) {
      st = GR_ERR_TOO_LARGE;
      set_err(err, err_len, "Cannot read '%s': the image of %lld by %lld pixels in %d channels %s.",
              label, (long long)L.width, (long long)L.height, chlist->num_channels, why);
      goto cleanup;
    }
  }
  for (c = 0; c < (size_t)chlist->num_channels; ++c) {
    const exr_attr_chlist_entry_t *e = &chlist->entries[c];
    const char *nm = e->name.str != NULL ? e->name.str : "";
    if (e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT) {
      st = GR_ERR_FORMAT;
      set_err(err, err_len,
              "Cannot read '%s': channel '%s' is %s, and only HALF and FLOAT "
              "channels are supported.",
              label, nm, pixel_type_name(e->pixel_type));
      goto cleanup;
    }
    if (e->x_sampling != 1 || e->y_sampling != 1) {
      st = GR_ERR_FORMAT;
      set_err(err, err_len,
              "Cannot read '%s': channel '%s' is subsampled (%d by %d), which "
              "is not supported.",
              label, nm, (int)e->x_sampling, (int)e->y_sampling);
      goto cleanup;
    }
    if (nm[0] == '\0' || strlen(nm) > GR_EXR_MAX_NAME) {
      st = GR_ERR_FORMAT;
      set_err(err, err_len, "Cannot read '%s': channel %d has an empty or over-long name.", label,
              (int)c);
      goto cleanup;
    }
  }

  st = read_meta(ctxt, label, &img.meta, err, err_len);
  if (st != GR_OK)
    goto cleanup;

  /* Chunk layout: scanlines per chunk, or level-0 tiles. */
  {
    exr_compression_t comp = EXR_COMPRESSION_NONE;
    rv = exr_get_compression(ctxt, 0, &comp);
    if (rv != EXR_ERR_SUCCESS) {
      st = GR_ERR_FORMAT;
      set_err(err, err_len, "Cannot read '%s': its compression is not understood (OpenEXR: %s).",
              label, exr_detail(msg, rv));
      goto cleanup;
    }
    L.compression = comp;
    L.expand = max_expansion(comp);
    /* DWA the library cannot decode: allow only raw-stored chunks, so that a
     * small hostile file cannot claim gigabytes (DWA packs about 66000:1)
     * and be refused only after the image was allocated. */
    L.undecodable =
        (comp == EXR_COMPRESSION_DWAA || comp == EXR_COMPRESSION_DWAB) && !core_decodes_dwa();
    if (L.undecodable)
      L.expand = 1;
  }
  if (storage == EXR_STORAGE_SCANLINE) {
    int32_t lines = 0;
    rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines);
    if (rv != EXR_ERR_SUCCESS || lines < 1) {
      st = GR_ERR_FORMAT;
      set_err(err, err_len, "Cannot read '%s': its compression is not understood (OpenEXR: %s).",
              label, exr_detail(msg, rv));
      goto cleanup;
    }
    L.lines = lines;
  } else {
    uint32_t tw = 0, th = 0;
    exr_tile_level_mode_t lmode;
    exr_tile_round_mode_t rmode;
    rv = exr_get_tile_descriptor(ctxt, 0, &tw, &th, &lmode, &rmode);
    if (rv != EXR_ERR_SUCCESS || tw < 1 || th < 1 || tw > INT32_MAX || th > INT32_MAX) {
      st = GR_ERR_FORMAT;
      set_err(err, err_len, "Cannot read '%s': its tile description is not valid (OpenEXR: %s).",
              label, exr_detail(msg, rv));
      goto cleanup;
    }
    L.tiled = 1;
    L.tw = (int64_t)tw;
    L.th = (int64_t)th;
    L.ntx = (L.width + L.tw - 1) / L.tw;
    L.nty = (L.height + L.th - 1) / L.th;
  }

  /* Pass 0 checks every chunk's description against the file; pass 1
   * allocates the image and decodes. */
  for (pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      img.width = (int)L.width;
      img.height = (int)L.height;
      img.names = (char **)calloc((size_t)chlist->num_channels, sizeof(char *));
      img.types =
          (gr_exr_pixel_type *)calloc((size_t)chlist->num_channels, sizeof(gr_exr_pixel_type));
      img.data = (float **)calloc((size_t)chlist->num_channels, sizeof(float *));
      if (img.names == NULL || img.types == NULL || img.data == NULL) {
        st = GR_ERR_OUT_OF_MEMORY;
        set_err(err, err_len, "Cannot read '%s': out of memory.", label);
        goto cleanup;
      }
      img.nchannels = chlist->num_channels;
      for (c = 0; c < (size_t)img.nchannels; ++c) {
        const exr_attr_chlist_entry_t *e = &chlist->entries[c];
        size_t len = strlen(e->name.str);
        img.names[c] = (char *)malloc(len + 1);
        img.data[c] = (float *)malloc(npix * sizeof(float));
        if (img.names[c] == NULL || img.data[c] == NULL) {
          st = GR_ERR_OUT_OF_MEMORY;
          set_err(err, err_len,
                  "Cannot read '%s': out of memory for %lld by %lld pixels in "
                  "%d channels.",
                  label, (long long)L.width, (long long)L.height, img.nchannels);
          goto cleanup;
        }
        memcpy(img.names[c], e->name.str, len + 1);
        img.types[c] = e->pixel_type == EXR_PIXEL_HALF ? GR_EXR_HALF : GR_EXR_FLOAT;
      }
      for (c = 0; c < (size_t)img.nchannels; ++c) {
        if (gr_exr_find_channel(&img, img.names[c]) != (int)c) {
          st = GR_ERR_FORMAT;
          set_err(err, err_len, "Cannot read '%s': channel '%s' appears twice.", label,
                  img.names[c]);
          goto cleanup;
        }
      }
    }
    rv = walk_chunks(&L, pass == 1 ? &img : NULL, &dec, &dec_live, &fault);
    if (rv != EXR_ERR_SUCCESS) {
      char where[64];
      st = read_status(rv);
      if (L.tiled)
        snprintf(where, sizeof where, "tile (%lld, %lld)", (long long)fault.x, (long long)fault.y);
      else
        snprintf(where, sizeof where, "scanline %lld", (long long)fault.y);
      if (fault.implausible && L.undecodable)
        set_err(err, err_len,
                "Cannot read '%s': the OpenEXR library in use cannot decode its %s compression "
                "(at %s).",
                label, compression_name(L.compression), where);
      else if (fault.implausible)
        set_err(err, err_len,
                "Cannot read '%s': the chunk at %s claims %llu bytes of pixels from %llu "
                "compressed bytes, more than its compression can hold; the file is corrupt.",
                label, where, (unsigned long long)fault.unpacked, (unsigned long long)fault.packed);
      else if (rv == EXR_ERR_FEATURE_NOT_IMPLEMENTED)
        set_err(err, err_len,
                "Cannot read '%s': the OpenEXR library in use cannot decode its %s compression "
                "(at %s; OpenEXR: %s).",
                label, compression_name(L.compression), where, exr_detail(msg, rv));
      else
        set_err(err, err_len,
                "Cannot read '%s': the file is truncated or corrupt at %s (OpenEXR: %s).", label,
                where, exr_detail(msg, rv));
      goto cleanup;
    }
  }

  /* File rows run north to south; memory row 0 is south. */
  for (c = 0; c < (size_t)img.nchannels; ++c)
    flip_rows(img.data[c], (size_t)img.width, (size_t)img.height);

cleanup:
  if (dec_live)
    exr_decoding_destroy(ctxt, &dec);
  if (ctxt != NULL)
    exr_finish(&ctxt);
  if (st == GR_OK)
    *out = img;
  else
    gr_exr_image_free(&img);
  return st;
}

gr_status gr_exr_read(const char *path, gr_exr_image *out, char *err, size_t err_len) {
  read_source src;
  if (path == NULL || path[0] == '\0' || out == NULL) {
    set_err(err, err_len,
            "The path and output image given to gr_exr_read must not be NULL "
            "or empty.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  memset(&src, 0, sizeof src);
  return read_exr(path, &src, out, err, err_len);
}

gr_status gr_exr_read_memory(const void *data, size_t size, const char *label, gr_exr_image *out,
                             char *err, size_t err_len) {
  read_source src;
  if (label == NULL || label[0] == '\0')
    label = "<memory>";
  if (out == NULL) {
    set_err(err, err_len, "The output image given to gr_exr_read_memory must not be NULL.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (data == NULL || size == 0) {
    set_err(err, err_len, "Cannot read '%s': the buffer is empty, so it is not an OpenEXR file.",
            label);
    return GR_ERR_FORMAT;
  }
  memset(&src, 0, sizeof src);
  src.bytes = (const unsigned char *)data;
  src.size = size;
  return read_exr(label, &src, out, err, err_len);
}

/* ------------------------------------------------------------------------ */
/* Writing                                                                  */
/* ------------------------------------------------------------------------ */

/* OpenEXRCore 3.1.5's compressors keep the compressed bytes of a chunk when
 * they are exactly as many as the raw bytes (they fall back to raw only when
 * compression makes the chunk larger). Every reader, OpenEXR's own included,
 * takes packed size == unpacked size to mean "stored raw", so such a chunk
 * reads back as garbage (a 1x40 FLOAT image of 0..39 does it: its last chunk
 * is 32 bytes raw and 32 bytes deflated). This wraps the library's compressor
 * and stores the raw bytes whenever compression does not make the chunk
 * strictly smaller. */
typedef struct compress_hook {
  exr_result_t (*compress)(exr_encode_pipeline_t *enc);
} compress_hook;

static exr_result_t compress_or_store(exr_encode_pipeline_t *enc) {
  const compress_hook *hook = (const compress_hook *)enc->encoding_user_data;
  exr_result_t rv;
  if (hook == NULL || hook->compress == NULL)
    return EXR_ERR_INVALID_ARGUMENT;
  rv = hook->compress(enc);
  if (rv != EXR_ERR_SUCCESS)
    return rv;
  if (enc->compressed_bytes >= enc->packed_bytes && enc->compressed_buffer != enc->packed_buffer) {
    if (enc->compressed_buffer == NULL || enc->packed_buffer == NULL ||
        enc->compressed_alloc_size < enc->packed_bytes)
      return EXR_ERR_INVALID_ARGUMENT;
    memcpy(enc->compressed_buffer, enc->packed_buffer, (size_t)enc->packed_bytes);
    enc->compressed_bytes = (size_t)enc->packed_bytes;
  }
  return EXR_ERR_SUCCESS;
}

gr_status gr_exr_write(const char *path, int width, int height, int nchannels,
                       const char *const *names, const float *const *data, gr_exr_pixel_type type,
                       char *err, size_t err_len) {
  return gr_exr_write_meta(path, width, height, nchannels, names, data, type, NULL, err, err_len);
}

gr_status gr_exr_write_meta(const char *path, int width, int height, int nchannels,
                            const char *const *names, const float *const *data,
                            gr_exr_pixel_type type, const gr_exr_meta *meta, char *err,
                            size_t err_len) {
  gr_status st = GR_OK;
  exr_result_t rv = EXR_ERR_SUCCESS;
  exr_context_t ctxt = NULL;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  exr_encode_pipeline_t enc;
  compress_hook hook;
  int enc_live = 0;
  int file_created = 0;
  exr_msg msg;
  int part = 0, c, longnames = 0;
  int32_t lines = 0;
  float *stage = NULL;
  size_t stage_plane;
  exr_pixel_type_t ptype;
  int y;

  memset(&enc, 0, sizeof enc);
  memset(&msg, 0, sizeof msg);
  hook.compress = NULL;

  if (path == NULL || path[0] == '\0') {
    set_err(err, err_len, "The path given to gr_exr_write must not be NULL or empty.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (width < 1 || height < 1 || width > GR_EXR_MAX_DIM || height > GR_EXR_MAX_DIM) {
    set_err(err, err_len, "Cannot write '%s': the image is %d by %d pixels, outside 1 to %d.", path,
            width, height, GR_EXR_MAX_DIM);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (nchannels < 1 || nchannels > INT16_MAX) {
    set_err(err, err_len, "Cannot write '%s': %d channels were given, and 1 to %d are allowed.",
            path, nchannels, INT16_MAX);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (type != GR_EXR_HALF && type != GR_EXR_FLOAT) {
    set_err(err, err_len, "Cannot write '%s': the pixel type %d is neither HALF nor FLOAT.", path,
            (int)type);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (names == NULL || data == NULL) {
    set_err(err, err_len, "Cannot write '%s': the channel names or data are missing.", path);
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (c = 0; c < nchannels; ++c) {
    int k;
    size_t len;
    if (names[c] == NULL || names[c][0] == '\0') {
      set_err(err, err_len, "Cannot write '%s': channel %d has no name.", path, c);
      return GR_ERR_INVALID_ARGUMENT;
    }
    len = strlen(names[c]);
    if (len > GR_EXR_MAX_NAME) {
      set_err(err, err_len,
              "Cannot write '%s': the name of channel %d is %zu characters "
              "long, and at most %d are allowed.",
              path, c, len, GR_EXR_MAX_NAME);
      return GR_ERR_INVALID_ARGUMENT;
    }
    if (len > 31)
      longnames = 1;
    if (data[c] == NULL) {
      set_err(err, err_len, "Cannot write '%s': channel '%s' has no data.", path, names[c]);
      return GR_ERR_INVALID_ARGUMENT;
    }
    for (k = 0; k < c; ++k) {
      if (strcmp(names[k], names[c]) == 0) {
        set_err(err, err_len, "Cannot write '%s': the channel name '%s' is given twice.", path,
                names[c]);
        return GR_ERR_INVALID_ARGUMENT;
      }
    }
  }
  if ((size_t)width * (size_t)height > GR_EXR_MAX_SAMPLES / (size_t)nchannels) {
    set_err(err, err_len,
            "Cannot write '%s': %d by %d pixels in %d channels is more than "
            "the %llu samples allowed.",
            path, width, height, nchannels, (unsigned long long)GR_EXR_MAX_SAMPLES);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (meta != NULL) {
    st = check_meta(path, meta, &longnames, err, err_len);
    if (st != GR_OK)
      return st;
  }
  ptype = type == GR_EXR_HALF ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;

  init.error_handler_fn = &exr_capture_error;
  init.user_data = &msg;

  rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init);
  if (rv != EXR_ERR_SUCCESS) {
    st = rv == EXR_ERR_OUT_OF_MEMORY ? GR_ERR_OUT_OF_MEMORY : GR_ERR_IO;
    set_err(err, err_len, "Cannot write '%s': the file cannot be created (OpenEXR: %s).", path,
            exr_detail(&msg, rv));
    goto cleanup;
  }
  file_created = 1;

  if (longnames)
    rv = exr_set_longname_support(ctxt, 1);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_initialize_required_attr_simple(ctxt, part, width, height, EXR_COMPRESSION_ZIP);
  for (c = 0; c < nchannels && rv == EXR_ERR_SUCCESS; ++c)
    rv = exr_add_channel(ctxt, part, names[c], ptype, EXR_PERCEPTUALLY_LINEAR, 1, 1);
  if (rv == EXR_ERR_SUCCESS && meta != NULL)
    rv = write_meta(ctxt, part, meta);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_write_header(ctxt);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_scanlines_per_chunk(ctxt, part, &lines);
  if (rv == EXR_ERR_SUCCESS && lines < 1)
    rv = EXR_ERR_INVALID_ARGUMENT;
  if (rv != EXR_ERR_SUCCESS) {
    st = rv == EXR_ERR_OUT_OF_MEMORY ? GR_ERR_OUT_OF_MEMORY : GR_ERR_IO;
    set_err(err, err_len, "Cannot write '%s': the header could not be written (OpenEXR: %s).", path,
            exr_detail(&msg, rv));
    goto cleanup;
  }

  /* Float staging for one chunk: nchannels planes of width by at most
   * lines rows. */
  stage_plane = (size_t)width * (size_t)(lines < height ? lines : height);
  if (stage_plane > SIZE_MAX / sizeof(float) / (size_t)nchannels) {
    st = GR_ERR_OUT_OF_MEMORY;
    set_err(err, err_len, "Cannot write '%s': out of memory.", path);
    goto cleanup;
  }
  stage = (float *)malloc(stage_plane * (size_t)nchannels * sizeof(float));
  if (stage == NULL) {
    st = GR_ERR_OUT_OF_MEMORY;
    set_err(err, err_len, "Cannot write '%s': out of memory.", path);
    goto cleanup;
  }

  for (y = 0; y < height; y += lines) {
    exr_chunk_info_t cinfo;
    int nrows = height - y < lines ? height - y : lines;
    int r;
    memset(&cinfo, 0, sizeof cinfo);
    rv = exr_write_scanline_chunk_info(ctxt, part, y, &cinfo);
    if (rv == EXR_ERR_SUCCESS && (cinfo.height != nrows || cinfo.width != width))
      rv = EXR_ERR_INCORRECT_CHUNK;
    if (rv == EXR_ERR_SUCCESS) {
      if (!enc_live) {
        rv = exr_encoding_initialize(ctxt, part, &cinfo, &enc);
        if (rv == EXR_ERR_SUCCESS)
          enc_live = 1;
      } else {
        rv = exr_encoding_update(ctxt, part, &cinfo, &enc);
      }
    }
    if (rv == EXR_ERR_SUCCESS && enc.channel_count != nchannels)
      rv = EXR_ERR_INCORRECT_CHUNK;
    /* File row y + r is memory row height - 1 - (y + r). */
    for (c = 0; c < enc.channel_count && rv == EXR_ERR_SUCCESS; ++c) {
      exr_coding_channel_info_t *ch = &enc.channels[c];
      float *dst = stage + (size_t)c * stage_plane;
      int k;
      for (k = 0; k < nchannels; ++k) {
        if (strcmp(names[k], ch->channel_name) == 0)
          break;
      }
      if (k == nchannels) {
        rv = EXR_ERR_INCORRECT_CHUNK;
        break;
      }
      for (r = 0; r < nrows; ++r) {
        size_t j = (size_t)(height - 1 - (y + r));
        memcpy(dst + (size_t)r * (size_t)width, data[k] + j * (size_t)width,
               (size_t)width * sizeof(float));
      }
      ch->encode_from_ptr = (const uint8_t *)dst;
      ch->user_pixel_stride = (int32_t)sizeof(float);
      ch->user_line_stride = (int32_t)((size_t)width * sizeof(float));
      ch->user_bytes_per_element = (int16_t)sizeof(float);
      ch->user_data_type = EXR_PIXEL_FLOAT;
    }
    if (rv == EXR_ERR_SUCCESS)
      rv = exr_encoding_choose_default_routines(ctxt, part, &enc);
    if (rv == EXR_ERR_SUCCESS && enc.compress_fn != NULL && enc.compress_fn != &compress_or_store) {
      hook.compress = enc.compress_fn;
      enc.encoding_user_data = &hook;
      enc.compress_fn = &compress_or_store;
    }
    if (rv == EXR_ERR_SUCCESS)
      rv = exr_encoding_run(ctxt, part, &enc);
    if (rv != EXR_ERR_SUCCESS) {
      st = rv == EXR_ERR_OUT_OF_MEMORY ? GR_ERR_OUT_OF_MEMORY : GR_ERR_IO;
      set_err(err, err_len,
              "Cannot write '%s': scanlines %d to %d could not be written "
              "(OpenEXR: %s).",
              path, y, y + nrows - 1, exr_detail(&msg, rv));
      goto cleanup;
    }
  }

  if (enc_live) {
    exr_encoding_destroy(ctxt, &enc);
    enc_live = 0;
  }
  /* exr_finish writes the chunk offset table. */
  rv = exr_finish(&ctxt);
  if (rv != EXR_ERR_SUCCESS) {
    st = GR_ERR_IO;
    set_err(err, err_len, "Cannot write '%s': the file could not be completed (OpenEXR: %s).", path,
            exr_detail(&msg, rv));
    goto cleanup;
  }

cleanup:
  if (enc_live)
    exr_encoding_destroy(ctxt, &enc);
  if (ctxt != NULL)
    exr_finish(&ctxt);
  free(stage);
  if (st != GR_OK && file_created)
    remove(path);
  return st;
}
