/* Builds every embedded OpenCL program on the default device and prints the
 * build log of any that fails; used at build time so that a kernel syntax
 * error breaks the build. Without any OpenCL platform it says so and passes:
 * there is nothing to compile with. */
#include "graupel/cl_runtime.h"

#include <stdio.h>
#include <string.h>

int main(int argc, char **argv) {
  const char *stamp = NULL;
  for (int i = 1; i < argc; ++i)
    if (strcmp(argv[i], "--stamp") == 0 && i + 1 < argc)
      stamp = argv[++i];
  gr_context *ctx = NULL;
  gr_status st = gr_context_create(NULL, &ctx);
  if (st == GR_ERR_NO_PLATFORM || st == GR_ERR_NO_DEVICE) {
    printf("graupel-clc: kernels not compiled: %s\n", gr_last_error(NULL));
    return 0;
  }
  if (st != GR_OK) {
    fprintf(stderr, "graupel-clc: %s\n", gr_last_error(NULL));
    return 1;
  }
  int failed = 0;
  for (int i = 0; i < gr_kernel_source_count(); ++i) {
    const gr_kernel_source *src = gr_kernel_source_at(i);
    cl_program prog = NULL;
    if (gr_program_get(ctx, src->name, NULL, &prog) != GR_OK) {
      fprintf(stderr, "graupel-clc: %s\n", gr_last_error(ctx));
      failed = 1;
    } else {
      /* A clean build has an empty log: show whatever the compiler said, and
       * treat warnings as errors so they are fixed, not scrolled past. */
      char log[8192] = "";
      cl_device_id dev = gr_context_device(ctx);
      clGetProgramBuildInfo(prog, dev, CL_PROGRAM_BUILD_LOG, sizeof(log), log, NULL);
      log[sizeof(log) - 1] = '\0';
      if (strstr(log, "warning")) {
        fprintf(stderr, "graupel-clc: %s.cl has warnings:\n%s\n", src->name, log);
        failed = 1;
      } else {
        printf("graupel-clc: %s.cl compiles on %s\n", src->name, gr_context_device_name(ctx));
      }
    }
  }
  gr_context_release(ctx);
  if (!failed && stamp) {
    FILE *f = fopen(stamp, "w");
    if (f)
      fclose(f);
  }
  return failed;
}
