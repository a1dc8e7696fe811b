/*
 * exr_io_meta.c - the graupel.* header attributes of an EXR file
 * (graupel.spacing, graupel.origin and graupel.field.*, listed in exr_io.h):
 * read from part 0 and checked before the reader allocates anything for the
 * pixels, checked and written by the writer; and gr_exr_meta_free.
 */
#include "exr_io_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define META_SPACING "graupel.spacing"
#define META_ORIGIN "graupel.origin"
/* Largest spacing and origin coordinate kept: beyond them extents overflow
 * what any terrain needs, and a hostile header could make bounds infinite. */
#define META_MAX_SPACING 1.0e9
#define META_MAX_ORIGIN 1.0e15
/* Longest string value kept in a field-data array. */
#define META_MAX_STRING 65536

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
    gr_exr_set_err(
        err, err_len,
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
      gr_exr_set_err(err, err_len,
                     "Cannot read '%s': the header attribute '%s' holds %d bytes, which is not a "
                     "component count and whole doubles; the file is corrupt.",
                     label, a->name, (int)size);
      return GR_ERR_FORMAT;
    }
    ncomp = get_le32((const unsigned char *)bytes);
    n = (size - 4) / 8;
    if (n > GR_EXR_MAX_META_VALUES || ncomp < 1 || n % ncomp != 0) {
      gr_exr_set_err(
          err, err_len,
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
      gr_exr_set_err(
          err, err_len,
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
        gr_exr_set_err(
            err, err_len,
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
  gr_exr_set_err(
      err, err_len,
      "Cannot read '%s': the header attribute '%s' is of type '%s', and field-data arrays "
      "are double, %s, string or stringvector.",
      label, a->name, a->type_name ? a->type_name : "unknown", GR_EXR_DOUBLES_TYPE);
  return GR_ERR_FORMAT;
oom:
  gr_exr_set_err(err, err_len, "Cannot read '%s': out of memory for the header attribute '%s'.",
                 label, a->name);
  return GR_ERR_OUT_OF_MEMORY;
}

/* Every graupel.* attribute of part 0 into meta (zeroed by the caller; the
 * caller frees it on failure). Other attributes are ignored. */
gr_status gr_exr_meta_read(exr_const_context_t ctxt, const char *label, gr_exr_meta *meta,
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
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': its header holds %d field-data arrays, and at most %d are "
                   "allowed.",
                   label, (int)nfields, GR_EXR_MAX_META_FIELDS);
    return GR_ERR_FORMAT;
  }
  if (nfields > 0) {
    meta->fields = (gr_exr_meta_field *)calloc((size_t)nfields, sizeof(gr_exr_meta_field));
    if (meta->fields == NULL) {
      gr_exr_set_err(err, err_len, "Cannot read '%s': out of memory for its field-data arrays.",
                     label);
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
        gr_exr_set_err(err, err_len,
                       "Cannot read '%s': its header attribute '%s' is of type '%s', not v2d.",
                       label, a->name, a->type_name ? a->type_name : "unknown");
        return GR_ERR_FORMAT;
      }
      v[0] = a->v2d->x;
      v[1] = a->v2d->y;
      if (!spacing_ok(v)) {
        gr_exr_set_err(
            err, err_len,
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
        gr_exr_set_err(err, err_len,
                       "Cannot read '%s': its header attribute '%s' is of type '%s', not v3d.",
                       label, a->name, a->type_name ? a->type_name : "unknown");
        return GR_ERR_FORMAT;
      }
      v[0] = a->v3d->x;
      v[1] = a->v3d->y;
      v[2] = a->v3d->z;
      if (!origin_ok(v)) {
        gr_exr_set_err(
            err, err_len,
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
gr_status gr_exr_meta_check(const char *path, const gr_exr_meta *meta, int *longnames, char *err,
                            size_t err_len) {
  const size_t plen = strlen(GR_EXR_FIELD_PREFIX);
  int f, k;
  if (meta->has_spacing && !spacing_ok(meta->spacing)) {
    gr_exr_set_err(
        err, err_len,
        "Cannot write '%s': the spacing is %g by %g m; give finite values above 0 and at "
        "most %g m.",
        path, meta->spacing[0], meta->spacing[1], META_MAX_SPACING);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (meta->has_origin && !origin_ok(meta->origin)) {
    gr_exr_set_err(
        err, err_len,
        "Cannot write '%s': the origin is (%g, %g, %g) m; give finite values within %g m "
        "of 0.",
        path, meta->origin[0], meta->origin[1], meta->origin[2], META_MAX_ORIGIN);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (meta->nfields < 0 || meta->nfields > GR_EXR_MAX_META_FIELDS ||
      (meta->nfields > 0 && meta->fields == NULL)) {
    gr_exr_set_err(err, err_len,
                   "Cannot write '%s': %d field-data arrays were given, and 0 to %d are allowed.",
                   path, meta->nfields, GR_EXR_MAX_META_FIELDS);
    return GR_ERR_INVALID_ARGUMENT;
  }
  for (f = 0; f < meta->nfields; ++f) {
    const gr_exr_meta_field *fd = &meta->fields[f];
    size_t len = fd->name ? strlen(fd->name) : 0;
    if (len == 0 || len > GR_EXR_MAX_NAME - plen) {
      gr_exr_set_err(
          err, err_len,
          "Cannot write '%s': field-data array %d has a name of %zu characters; give 1 to "
          "%zu.",
          path, f, len, (size_t)GR_EXR_MAX_NAME - plen);
      return GR_ERR_INVALID_ARGUMENT;
    }
    if (plen + len > 31)
      *longnames = 1;
    for (k = 0; k < f; ++k) {
      if (strcmp(meta->fields[k].name, fd->name) == 0) {
        gr_exr_set_err(err, err_len, "Cannot write '%s': the field-data array '%s' is given twice.",
                       path, fd->name);
        return GR_ERR_INVALID_ARGUMENT;
      }
    }
    if (fd->count < 1 || fd->count > GR_EXR_MAX_META_VALUES ||
        (fd->is_string
             ? fd->strings == NULL
             : (fd->numbers == NULL || fd->ncomponents < 1 || fd->count % fd->ncomponents != 0))) {
      gr_exr_set_err(
          err, err_len,
          "Cannot write '%s': the field-data array '%s' has %d values in tuples of %d; give "
          "1 to %d values in whole tuples.",
          path, fd->name, fd->count, fd->ncomponents, GR_EXR_MAX_META_VALUES);
      return GR_ERR_INVALID_ARGUMENT;
    }
    for (k = 0; fd->is_string && k < fd->count; ++k) {
      if (fd->strings[k] == NULL || strlen(fd->strings[k]) > META_MAX_STRING) {
        gr_exr_set_err(
            err, err_len,
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
exr_result_t gr_exr_meta_write(exr_context_t ctxt, int part, const gr_exr_meta *meta) {
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
