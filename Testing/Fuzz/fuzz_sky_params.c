/* libFuzzer harness: gr_lightning_params_validate and
 * gr_cloud_cover_params_validate (the sky core's two validators, one
 * table). No OpenCL is touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks how the fields are
 * made, byte 1 the length of a small message buffer, byte 2 which
 * parameters (even: lightning, odd: cloud cover), then:
 *   mode 0  every field from raw bytes (4 per int, 8 per double), so NaN,
 *           infinities, subnormals and huge values appear;
 *   mode 1  the defaults with the fields whose bit is set in the next 2
 *           bytes read raw, as in mode 0;
 *   mode 2  one byte per field picks an edge value: NaN, infinities,
 *           extremes, or a table row's min, max, default or one ulp beyond.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes
 * with a non-empty message ending in '.'; parameters are accepted exactly
 * when every table field lies in its row of gr_sky_param_bounds (and, for
 * the lightning, Start and End are finite and apart and the time finite);
 * an accepted bolt has
 * ControlPoints + Strands * max(2, ControlPoints / 2) points, a refused one
 * 0, and a small accepted bolt is generated with Start and End exact; a
 * short message buffer is never overrun and is always terminated; the
 * answer does not depend on the buffer. */
#include "fuzz_common.h"
#include "graupel/sky.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct field {
  size_t offset;
  char kind;       /* 'i' int, 'd' double */
  const char *row; /* the table row, NULL for Start and End */
} field;

static const field lightning_fields[] = {
    {offsetof(gr_lightning_params, control_points), 'i', "ControlPoints"},
    {offsetof(gr_lightning_params, strands), 'i', "Strands"},
    {offsetof(gr_lightning_params, jitter), 'd', "Jitter"},
    {offsetof(gr_lightning_params, seed), 'i', "Seed"},
    {offsetof(gr_lightning_params, variant), 'i', NULL},
    {offsetof(gr_lightning_params, flicker_rate), 'd', "FlickerRate"},
    {offsetof(gr_lightning_params, time), 'd', NULL},
    {offsetof(gr_lightning_params, start), 'd', NULL},
    {offsetof(gr_lightning_params, start) + sizeof(double), 'd', NULL},
    {offsetof(gr_lightning_params, start) + 2 * sizeof(double), 'd', NULL},
    {offsetof(gr_lightning_params, end), 'd', NULL},
    {offsetof(gr_lightning_params, end) + sizeof(double), 'd', NULL},
    {offsetof(gr_lightning_params, end) + 2 * sizeof(double), 'd', NULL},
};

static const field cloud_fields[] = {
    {offsetof(gr_cloud_cover_params, cover), 'd', "Cover"},
    {offsetof(gr_cloud_cover_params, scale), 'd', "Scale"},
    {offsetof(gr_cloud_cover_params, sharpness), 'd', "Sharpness"},
    {offsetof(gr_cloud_cover_params, wind_speed), 'd', "WindSpeed"},
    {offsetof(gr_cloud_cover_params, wind_direction), 'd', "WindDirection"},
    {offsetof(gr_cloud_cover_params, resolution), 'i', "Resolution"},
    {offsetof(gr_cloud_cover_params, size), 'd', "Size"},
    {offsetof(gr_cloud_cover_params, seed), 'i', "Seed"},
};

static double field_value(const void *base, const field *f) {
  const char *at = (const char *)base + f->offset;
  if (f->kind == 'd') {
    double v;
    memcpy(&v, at, sizeof v);
    return v;
  }
  int v;
  memcpy(&v, at, sizeof v);
  return v;
}

static gr_status validate(int cloud, const void *p, char *msg, size_t len) {
  return cloud ? gr_cloud_cover_params_validate(p, msg, len)
               : gr_lightning_params_validate(p, msg, len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const double fixed[] = {0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 50.0, 1000.0, 1e300, -1e300};
  gr_lightning_params lp;
  gr_cloud_cover_params cp;
  reader r;
  char msg[1024];
  int n = 0;
  const gr_param_bound *table = gr_sky_param_bounds(&n);
  REQUIRE(table != NULL && n == 12);

  r.p = data;
  r.n = size;
  int mode = take_byte(&r) % 3;
  size_t small_len = take_byte(&r) % 96;
  int cloud = take_byte(&r) & 1;
  const field *fields = cloud ? cloud_fields : lightning_fields;
  int nfields = cloud ? (int)(sizeof cloud_fields / sizeof cloud_fields[0])
                      : (int)(sizeof lightning_fields / sizeof lightning_fields[0]);
  void *p = cloud ? (void *)&cp : (void *)&lp;
  memset(&lp, 0, sizeof lp);
  memset(&cp, 0, sizeof cp);
  if (mode == 1) {
    uint8_t bits[2];
    gr_lightning_params_init(&lp);
    gr_cloud_cover_params_init(&cp);
    take(&r, bits, sizeof bits);
    for (int f = 0; f < nfields; ++f)
      if (bits[f / 8] & (1u << (f % 8)))
        take(&r, (char *)p + fields[f].offset,
             fields[f].kind == 'd' ? sizeof(double) : sizeof(int));
  } else {
    for (int f = 0; f < nfields; ++f) {
      char *at = (char *)p + fields[f].offset;
      if (mode == 0) {
        take(&r, at, fields[f].kind == 'd' ? sizeof(double) : sizeof(int));
      } else {
        double v = fuzz_table_edge(table, n, fixed, sizeof fixed / sizeof fixed[0], take_byte(&r));
        if (fields[f].kind == 'd') {
          memcpy(at, &v, sizeof v);
        } else {
          int iv = isfinite(v) && fabs(v) < 2e9 ? (int)v : -1;
          memcpy(at, &iv, sizeof iv);
        }
      }
    }
  }

  int documented = 1;
  for (int f = 0; f < nfields; ++f)
    if (fields[f].row)
      documented &= fuzz_in_row(fuzz_row(table, n, fields[f].row), field_value(p, &fields[f]));
  if (!cloud) {
    double d2 = 0.0;
    documented &= isfinite(lp.time);
    for (int c = 0; c < 3; ++c) {
      documented &= isfinite(lp.start[c]) && isfinite(lp.end[c]);
      d2 += (lp.end[c] - lp.start[c]) * (lp.end[c] - lp.start[c]);
    }
    documented &= d2 > 0.0;
  }

  msg[0] = '\0';
  gr_status sp = validate(cloud, p, msg, sizeof msg);
  check_message(sp, msg);
  REQUIRE((sp == GR_OK) == documented);

  if (!cloud) {
    long count = gr_lightning_point_count(&lp);
    if (sp == GR_OK) {
      int m = lp.control_points / 2 > 2 ? lp.control_points / 2 : 2;
      REQUIRE(count == lp.control_points + (long)lp.strands * m);
      if (count <= 4096) {
        double *xyz = malloc(sizeof(double) * 3 * (size_t)count);
        REQUIRE(xyz != NULL);
        REQUIRE(gr_lightning_generate(&lp, xyz, NULL, NULL, NULL, 0) == GR_OK);
        REQUIRE(memcmp(xyz, lp.start, sizeof lp.start) == 0);
        REQUIRE(memcmp(xyz + 3 * (lp.control_points - 1), lp.end, sizeof lp.end) == 0);
        free(xyz);
      }
    } else {
      REQUIRE(count == 0);
    }
  }

  REQUIRE(validate(cloud, p, NULL, 0) == sp);
  REQUIRE(validate(cloud, p, NULL, 64) == sp);
  char *small = (char *)malloc(small_len > 0 ? small_len : 1);
  REQUIRE(small != NULL);
  if (small_len > 0) {
    memset(small, 'x', small_len);
    REQUIRE(validate(cloud, p, small, small_len) == sp);
    if (sp != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
  }
  free(small);

  msg[0] = '\0';
  check_message(validate(cloud, NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  return 0;
}
