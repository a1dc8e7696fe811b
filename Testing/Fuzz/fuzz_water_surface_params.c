/* libFuzzer harness: gr_water_surface_params_validate. No OpenCL is
 * touched.
 *
 * Input layout (missing bytes read as 0): byte 0 picks how the 10 fields of
 * gr_water_surface_params (in declaration order) are made, byte 1 the
 * length of a small message buffer, then:
 *   mode 0  every field from raw bytes (4 per int, 8 per double), so NaN,
 *           infinities, subnormals and huge values appear;
 *   mode 1  the defaults (gr_water_surface_params_init) with the fields
 *           whose bit is set in the next 2 bytes read raw, as in mode 0;
 *   mode 2  one byte per field picks an edge value: NaN, infinities,
 *           extremes, or a table row's min, max, default or one ulp beyond.
 *
 * Checks: the status is GR_OK or GR_ERR_INVALID_ARGUMENT; a failure comes
 * with a non-empty message ending in '.'; parameters are accepted exactly
 * when every one lies in its row of the parameter table
 * (gr_water_surface_param_bounds, which the XML, the VTK clamps and the
 * README follow); a short message buffer is never overrun and is always
 * terminated; the answer does not depend on the buffer. */
#include "fuzz_common.h"
#include "graupel/water_surface.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define NFIELDS 10

/* Field kinds in order: 'i' int, 'd' double. */
static const char kinds[] = "dddiddddid";
/* The table row of each field. */
static const char *const rows[NFIELDS] = {
    "WaveSpeed", "Damping",       "WetDepth",   "UseLakeLevel", "LakeLevel",
    "DropRate",  "DropAmplitude", "DropRadius", "Seed",         "CourantNumber"};

static void *field_ptr(gr_water_surface_params *p, int f) {
  switch (f) {
  case 0:
    return &p->wave_speed;
  case 1:
    return &p->damping;
  case 2:
    return &p->wet_depth;
  case 3:
    return &p->use_lake_level;
  case 4:
    return &p->lake_level;
  case 5:
    return &p->drop_rate;
  case 6:
    return &p->drop_amplitude;
  case 7:
    return &p->drop_radius;
  case 8:
    return &p->seed;
  default:
    return &p->cfl;
  }
}

static double field_value(gr_water_surface_params *p, int f) {
  if (kinds[f] == 'd') {
    double v;
    memcpy(&v, field_ptr(p, f), sizeof v);
    return v;
  }
  int v;
  memcpy(&v, field_ptr(p, f), sizeof v);
  return v;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const double fixed[] = {0.0, -0.0, 1.0, -1.0, 0.5, 0.01, 300.0, 1e300, -1e300, 2.0};
  gr_water_surface_params p;
  reader r;
  char msg[1024];
  int n = 0;
  const gr_param_bound *table = gr_water_surface_param_bounds(&n);
  REQUIRE(table != NULL && n == NFIELDS);

  r.p = data;
  r.n = size;
  int mode = take_byte(&r) % 3;
  size_t small_len = take_byte(&r) % 96;
  memset(&p, 0, sizeof p);
  if (mode == 1) {
    uint8_t bits[2];
    gr_water_surface_params_init(&p);
    take(&r, bits, sizeof bits);
    for (int f = 0; f < NFIELDS; ++f)
      if (bits[f / 8] & (1u << (f % 8)))
        take(&r, field_ptr(&p, f), kinds[f] == 'd' ? sizeof(double) : sizeof(int));
  } else {
    for (int f = 0; f < NFIELDS; ++f) {
      if (mode == 0) {
        take(&r, field_ptr(&p, f), kinds[f] == 'd' ? sizeof(double) : sizeof(int));
      } else {
        double v = fuzz_table_edge(table, n, fixed, sizeof fixed / sizeof fixed[0], take_byte(&r));
        if (kinds[f] == 'd') {
          memcpy(field_ptr(&p, f), &v, sizeof v);
        } else {
          int iv = isfinite(v) && fabs(v) < 2e9 ? (int)v : -1;
          memcpy(field_ptr(&p, f), &iv, sizeof iv);
        }
      }
    }
  }

  int documented = 1;
  for (int f = 0; f < NFIELDS; ++f)
    documented &= fuzz_in_row(fuzz_row(table, n, rows[f]), field_value(&p, f));

  msg[0] = '\0';
  gr_status sp = gr_water_surface_params_validate(&p, msg, sizeof msg);
  check_message(sp, msg);
  REQUIRE((sp == GR_OK) == documented);

  REQUIRE(gr_water_surface_params_validate(&p, NULL, 0) == sp);
  REQUIRE(gr_water_surface_params_validate(&p, NULL, 64) == sp);
  char *small = (char *)malloc(small_len > 0 ? small_len : 1);
  REQUIRE(small != NULL);
  if (small_len > 0) {
    memset(small, 'x', small_len);
    REQUIRE(gr_water_surface_params_validate(&p, small, small_len) == sp);
    if (sp != GR_OK)
      REQUIRE(memchr(small, '\0', small_len) != NULL);
  }
  free(small);

  msg[0] = '\0';
  check_message(gr_water_surface_params_validate(NULL, msg, sizeof msg), msg);
  REQUIRE(msg[0] != '\0');
  return 0;
}
