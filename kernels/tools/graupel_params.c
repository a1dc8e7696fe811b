/* graupel-params: prints every core's parameter table as JSON on stdout, so
 * that a test can compare the XML domains, the VTK clamps and the README
 * with the one table the validators follow:
 *   {"procedural_terrain": [{"property": "Seed", "unit": "", "min": ...,
 *     "max": ..., "default": ..., "to_core": ..., "min_open": 0, "integer": 1},
 *     ...], "rain_runoff": [...]}
 * Numbers are printed with %.17g, so they read back as the same doubles.
 * The cores, in order, are those of the registry (graupel_cores.h, written
 * from kernels/cores.cmake): each core's gr_<core>_param_bounds. Needs no
 * OpenCL device. */
#include "graupel_cores.h"

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

/* Every core of the registry with its table, in the registry's order. */
typedef struct core_table {
  const char *name;
  const gr_param_bound *(*bounds)(int *count);
} core_table;

#define GR_CORE_TABLE(core) {#core, gr_##core##_param_bounds},
static const core_table cores[] = {GRAUPEL_CORE_LIST(GR_CORE_TABLE)};
#undef GR_CORE_TABLE
static const int ncores = (int)(sizeof(cores) / sizeof(cores[0]));

int main(int argc, char **argv) {
  if (argc > 1 && (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0)) {
    printf("usage: %s\nPrints every Graupel core's parameter table as JSON.\n", argv[0]);
    return 0;
  }
  int bad = 0;
  printf("{");
  for (int i = 0; i < ncores; ++i) {
    int n = 0;
    const gr_param_bound *rows = cores[i].bounds(&n);
    if (i)
      printf(",\n");
    bad |= print_table(cores[i].name, rows, n);
  }
  printf("}\n");
  return bad ? 1 : 0;
}
