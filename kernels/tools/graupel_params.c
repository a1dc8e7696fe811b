/* graupel-params: prints every core's parameter table as JSON on stdout, so
 * that a test can compare the XML domains, the VTK clamps and the README
 * with the one table the validators follow:
 *   {"procedural_terrain": [{"property": "Seed", "unit": "", "min": ...,
 *     "max": ..., "default": ..., "to_core": ..., "min_open": 0, "integer": 1},
 *     ...], "rain_runoff": [...]}
 * Numbers are printed with %.17g, so they read back as the same doubles.
 * Needs no OpenCL device. */
#include "graupel/procedural_terrain.h"
#include "graupel/rain_runoff.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void print_string(const char *s) {
  putchar('"');
  for (; s && *s; ++s) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\')
      printf("\\%c", c);
    else if (c < 0x20)
      printf("\\u%04x", c);
    else
      putchar(c);
  }
  putchar('"');
}

/* JSON has no NaN or infinity: a table holding one is a bug to report. */
static int print_number(double v) {
  if (!isfinite(v)) {
    printf("null");
    return 1;
  }
  printf("%.17g", v);
  return 0;
}

static int print_table(const char *core, const gr_param_bound *rows, int n) {
  int bad = 0;
  print_string(core);
  printf(": [");
  for (int i = 0; i < n; ++i) {
    const gr_param_bound *b = &rows[i];
    printf("%s\n  {\"property\": ", i ? "," : "");
    print_string(b->property);
    printf(", \"unit\": ");
    print_string(b->unit);
    printf(", \"min\": ");
    bad |= print_number(b->min);
    printf(", \"max\": ");
    bad |= print_number(b->max);
    printf(", \"default\": ");
    bad |= print_number(b->default_value);
    printf(", \"to_core\": ");
    bad |= print_number(b->to_core);
    printf(", \"min_open\": %d, \"integer\": %d}", b->min_open ? 1 : 0, b->integer ? 1 : 0);
  }
  printf("]");
  if (bad)
    fprintf(stderr, "graupel-params: the %s table holds a number that is not finite.\n", core);
  return bad;
}

int main(int argc, char **argv) {
  if (argc > 1 && (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0)) {
    printf("usage: %s\nPrints every Graupel core's parameter table as JSON.\n", argv[0]);
    return 0;
  }
  int n = 0, bad = 0;
  const gr_param_bound *rows = gr_procedural_terrain_param_bounds(&n);
  printf("{");
  bad |= print_table("procedural_terrain", rows, n);
  printf(",\n");
  rows = gr_rain_runoff_param_bounds(&n);
  bad |= print_table("rain_runoff", rows, n);
  printf("}\n");
  return bad ? 1 : 0;
}
