/* Memory tests (memory.h): what the query reports, the check's sentences and
 * figures, that a device buffer in host memory is allocated at once and one
 * that does not fit is refused with a sentence (PoCL's lazy allocation
 * asserted and aborted the process instead), that every core's estimate
 * matches what it allocates, and that every core refuses a grid beyond what
 * the process can get before it allocates anything.
 *
 * The allocation figures are the process's mapped address space (VmSize)
 * before and after: the program sets malloc's mmap threshold to 64 kB, so
 * every buffer and plane is a mapping of its own that comes and goes with
 * it. The address-space limit is set in-process (setrlimit RLIMIT_AS, the
 * soft limit, restored after); under a sanitizer, whose shadow memory maps
 * terabytes, those subtests only say so. */
#define _GNU_SOURCE /* mallopt */
#include "graupel/cl_runtime.h"
#include "graupel/exr_io.h"
#include "graupel/memory.h"
#include "graupel/particles.h"
#include "graupel/procedural_terrain.h"
#include "graupel/rain_runoff.h"
#include "graupel/sky.h"
#include "graupel/snow_accumulation.h"
#include "graupel/snow_deformation.h"
#include "graupel/terrain_analysis.h"
#include "graupel/water_surface.h"
#include "gr_test.h"

#include <malloc.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#define MB 1e6

static gr_context *ctx;

static double vm_size(void) {
  unsigned long long pages = 0;
  FILE *f = fopen("/proc/self/statm", "r");
  if (!f)
    return 0.0;
  if (fscanf(f, "%llu", &pages) != 1)
    pages = 0;
  fclose(f);
  return (double)pages * (double)sysconf(_SC_PAGESIZE);
}

/* VmSize once the device is idle and PoCL's driver threads have freed what
 * was released (they do it after the commands that used a buffer are done,
 * a little after gr_finish): unchanged over 3 reads 20 ms apart, 2 s at most. */
static double settled_vm_size(void) {
  gr_finish(ctx);
  double last = vm_size();
  int same = 0;
  for (int i = 0; i < 100 && same < 3; ++i) {
    struct timespec pause = {0, 20 * 1000 * 1000};
    nanosleep(&pause, NULL);
    double now = vm_size();
    same = now == last ? same + 1 : 0;
    last = now;
  }
  return last;
}

/* Sanitizers map terabytes of shadow memory and keep freed blocks in
 * quarantine (their allocator, not malloc's mappings): no address-space
 * limit and no measurement then. */
static int limits_usable(void) {
  if (vm_size() > 64e9) {
    printf("address-space limits and mappings not tested: %.0f GB mapped (a sanitizer's "
           "shadow)\n",
           vm_size() / 1e9);
    return 0;
  }
  return 1;
}

static struct rlimit saved_limit;

/* The soft address-space limit at what is mapped now plus budget bytes. */
static void limit_to(double budget) {
  getrlimit(RLIMIT_AS, &saved_limit);
  struct rlimit l = saved_limit;
  l.rlim_cur = (rlim_t)(vm_size() + budget);
  CHECK(setrlimit(RLIMIT_AS, &l) == 0);
}

static void unlimit(void) {
  CHECK(setrlimit(RLIMIT_AS, &saved_limit) == 0);
}

static int uses_host_memory(void) {
  gr_memory_info m;
  CHECK(gr_memory_query(ctx, &m) == GR_OK);
  return m.device_uses_host_memory;
}

static void test_format(void) {
  char s[32];
  gr_memory_format(12.8e9, s, sizeof(s));
  CHECK(strcmp(s, "12.8 GB") == 0);
  gr_memory_format(640e6, s, sizeof(s));
  CHECK(strcmp(s, "640.0 MB") == 0);
  gr_memory_format(12345.0, s, sizeof(s));
  CHECK(strcmp(s, "12 kB") == 0);
  gr_memory_need a = {1.0, 5.0, 2.0, 10.0, 3.0}, b = {4.0, 3.0, 1.0, 5.0, 1.0};
  gr_memory_need_add(&a, &b);
  CHECK(a.device == 5.0 && a.largest == 5.0 && a.host == 3.0 && a.points == 15.0 && a.state == 4.0);
}

static void test_query(void) {
  gr_memory_info m;
  CHECK(gr_memory_query(NULL, NULL) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_memory_query(NULL, &m) == GR_OK);
  CHECK(m.host_free != GR_MEMORY_UNLIMITED && m.host_free > 64e6);
  CHECK(m.host_available <= m.host_free && m.host_available <= m.address_space_left);
  CHECK(m.device_global == 0 && m.device_max_alloc == 0);
  struct rlimit l;
  getrlimit(RLIMIT_AS, &l);
  if (l.rlim_cur == RLIM_INFINITY)
    CHECK(m.address_space_left == GR_MEMORY_UNLIMITED && m.host_available == m.host_free);
  gr_device_info info;
  CHECK(gr_context_device_info(ctx, &info) == GR_OK);
  CHECK(gr_memory_query(ctx, &m) == GR_OK);
  CHECK(m.device_global == info.global_mem_bytes && m.device_max_alloc == info.max_alloc_bytes);
  CHECK(m.device_uses_host_memory == info.host_memory);
  if (info.is_cpu)
    CHECK(m.device_uses_host_memory == 1);
  printf("host: %.2f GB available (MemAvailable %.2f GB); device '%s': %.2f GB, largest buffer "
         "%.2f GB, host memory %d\n",
         m.host_available / 1e9, m.host_free / 1e9, info.name, m.device_global / 1e9,
         m.device_max_alloc / 1e9, m.device_uses_host_memory);

  /* Under a limit: what is left of it, the smaller figure. */
  if (!limits_usable())
    return;
  limit_to(300 * MB);
  CHECK(gr_memory_query(ctx, &m) == GR_OK);
  unlimit();
  CHECK_MSG(m.address_space_left > 280 * MB && m.address_space_left <= 300 * MB, "%.1f MB",
            m.address_space_left / MB);
  CHECK(m.host_available == m.address_space_left);
}

static void test_check(void) {
  char msg[512];
  gr_memory_info m;
  CHECK(gr_memory_query(ctx, &m) == GR_OK);
  gr_memory_need small = {4096.0, 4096.0, 4096.0, 1024.0, 0.0};
  CHECK(gr_memory_check(ctx, &small, msg, sizeof(msg)) == GR_OK && msg[0] == '\0');
  CHECK(gr_memory_check(NULL, &small, NULL, 0) == GR_OK);
  CHECK(gr_memory_check(ctx, NULL, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);

  /* Twice what the process can get, 8 bytes a point: both figures said. */
  double points = (double)m.host_available / 4.0;
  gr_memory_need host = {0.0, 0.0, 8.0 * points, points, 0.0};
  CHECK(gr_memory_check(NULL, &host, msg, sizeof(msg)) == GR_ERR_TOO_LARGE);
  char need[32], have[32];
  gr_memory_format(host.host, need, sizeof(need));
  gr_memory_format((double)m.host_available, have, sizeof(have));
  CHECK_MSG(strncmp(msg, "needs ", 6) == 0 && strstr(msg, need) &&
                strstr(msg, "(8 bytes a point)") && strstr(msg, "this process can use "),
            "'%s' (need %s, have %s)", msg, need, have);

  /* A device whose buffers are host memory counts them there too. */
  gr_memory_need half = {0.6 * (double)m.host_available, 1.0, 0.6 * (double)m.host_available, 0, 0};
  gr_status st = gr_memory_check(ctx, &half, msg, sizeof(msg));
  if (m.device_uses_host_memory)
    CHECK_MSG(st == GR_ERR_TOO_LARGE && strstr(msg, "this process can use"), "'%s'", msg);
  else if (half.device <= (double)m.device_global)
    CHECK_MSG(st == GR_OK, "'%s'", msg);

  /* One buffer beyond the device's largest, the total small enough. */
  gr_memory_need one = {(double)m.device_max_alloc + 4096.0, (double)m.device_max_alloc + 4096.0,
                        0.0, 0.0, 0.0};
  if (one.device < 0.5 * (double)m.host_available &&
      (m.device_uses_host_memory || one.device <= (double)m.device_global)) {
    CHECK(gr_memory_check(ctx, &one, msg, sizeof(msg)) == GR_ERR_TOO_LARGE);
    CHECK_MSG(strstr(msg, "needs one buffer of ") && strstr(msg, "allows at most") &&
                  strstr(msg, gr_context_device_name(ctx)),
              "'%s'", msg);
  }
  /* Absurd sizes are numbers, not overflows. */
  gr_memory_need absurd = {1e30, 1e30, 1e30, 1e12, 0.0};
  CHECK(gr_memory_check(ctx, &absurd, msg, sizeof(msg)) == GR_ERR_TOO_LARGE);
}

/* On a device whose buffers are host memory a buffer is mapped when it is
 * made, not at its first use (PoCL's lazy allocation aborted the process
 * when it failed there), and a buffer beyond what the process can get is
 * refused with a sentence. */
static void test_buffers(void) {
  if (!limits_usable())
    return;
  if (!uses_host_memory()) {
    printf("the device keeps its buffers apart from the host's memory: nothing to check\n");
    return;
  }
  const size_t bytes = (size_t)64 << 20;
  double before = vm_size();
  cl_mem buf = NULL;
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, bytes, NULL, &buf) == GR_OK);
  double grown = vm_size() - before;
  CHECK_MSG(grown >= (double)bytes, "the buffer of %zu bytes mapped %.0f", bytes, grown);
  gr_buffer_release(&buf);
  CHECK_MSG(vm_size() - before < 1 * MB, "%.0f bytes left mapped", vm_size() - before);

  gr_memory_info m;
  CHECK(gr_memory_query(ctx, &m) == GR_OK);
  size_t big = (size_t)512 << 20;
  if ((double)big > (double)m.device_max_alloc)
    big = (size_t)(m.device_max_alloc / 2);
  limit_to((double)big / 2.0);
  gr_status st = gr_buffer_create(ctx, CL_MEM_READ_WRITE, big, NULL, &buf);
  unlimit();
  CHECK_MSG(st == GR_ERR_OUT_OF_MEMORY && buf == NULL, "%s", gr_status_string(st));
  CHECK_MSG(strstr(gr_last_error(ctx), "does not fit") && strstr(gr_last_error(ctx), "can use"),
            "'%s'", gr_last_error(ctx));
  /* The same buffer without the limit. */
  CHECK(gr_buffer_create(ctx, CL_MEM_READ_WRITE, big, NULL, &buf) == GR_OK);
  gr_buffer_release(&buf);
}

/* ---------------------------------------------- estimates against use */

/* The mapped bytes a core's handle holds after create and a pass through
 * its steps and reads (run once before, to build the programs), against
 * its estimate: device (host memory here) plus host. The estimate may
 * count more than a plain run takes: a few planes it only makes for inputs
 * or paths it may take, never less. */
typedef void *(*make_fn)(const gr_grid *g);
typedef void (*free_fn)(void *h);

static void compare(const char *core, const gr_grid *g, const gr_memory_need *est, make_fn make,
                    free_fn drop, double extra) {
  drop(make(g)); /* programs built, work-group functions compiled */
  double before = settled_vm_size();
  void *h = make(g);
  double used = settled_vm_size() - before;
  CHECK_MSG(h != NULL, "%s: %s", core, gr_last_error(ctx));
  drop(h);
  double estimate = est->device + est->host;
  printf("%-20s %4d x %-4d  used %7.1f MB  estimated %7.1f MB (%.0f bytes a point)\n", core, g->nx,
         g->ny, used / MB, estimate / MB, estimate / est->points);
  /* Never less than taken (2 MB for the small tables, reductions and
   * rounding to pages), and at most `extra` planes' bytes more. */
  CHECK_MSG(estimate >= used - 2 * MB, "%s: estimated %.1f MB, used %.1f MB", core, estimate / MB,
            used / MB);
  CHECK_MSG(estimate <= used + extra * 4.0 * est->points + 2 * MB,
            "%s: estimated %.1f MB, used %.1f MB", core, estimate / MB, used / MB);
}

static float *plane(const gr_grid *g, float value) {
  size_t n = (size_t)g->nx * (size_t)g->ny;
  float *f = malloc(n * 3 * sizeof(float));
  for (size_t i = 0; f && i < 3 * n; ++i)
    f[i] = value;
  return f;
}

static void *make_terrain(const gr_grid *g) {
  gr_procedural_terrain_params p;
  gr_procedural_terrain_params_init(&p);
  gr_procedural_terrain *t = NULL;
  if (gr_procedural_terrain_create(ctx, g, &p, &t) == GR_OK) {
    float *out = plane(g, 0.0f);
    gr_procedural_terrain_compute(t);
    gr_procedural_terrain_get_field(t, GR_FIELD_ELEVATION, out);
    free(out);
  }
  return t;
}

static void drop_terrain(void *h) {
  gr_procedural_terrain_destroy(h);
}

static void *make_analysis(const gr_grid *g) {
  gr_terrain_analysis_params p;
  gr_terrain_analysis_params_init(&p);
  p.model_shadows = 1;
  gr_terrain_analysis *t = NULL;
  if (gr_terrain_analysis_create(ctx, g, &p, &t) == GR_OK) {
    float *f = plane(g, 1.0f);
    gr_terrain_analysis_set_heights(t, f);
    gr_terrain_analysis_compute_shadow(t);
    gr_terrain_analysis_compute(t);
    gr_terrain_analysis_get_output(t, GR_TERRAIN_NORMAL, f);
    free(f);
  }
  return t;
}

static void drop_analysis(void *h) {
  gr_terrain_analysis_destroy(h);
}

static gr_rain_runoff_params rain_params;

static void *make_rain(const gr_grid *g) {
  gr_rain_runoff *s = NULL;
  if (gr_rain_runoff_create(ctx, g, &rain_params, &s) == GR_OK) {
    float *f = plane(g, 0.01f);
    gr_status st = gr_rain_runoff_set_field(s, GR_FIELD_WATER_DEPTH, f);
    if (st == GR_OK)
      st = gr_rain_runoff_step(s, 0.01, 2);
    if (st == GR_OK)
      st = gr_rain_runoff_get_field(s, GR_FIELD_VELOCITY, f);
    CHECK_MSG(st == GR_OK, "%s", gr_rain_runoff_last_error(s));
    free(f);
  }
  return s;
}

static void drop_rain(void *h) {
  gr_rain_runoff_destroy(h);
}

static void *make_deformation(const gr_grid *g) {
  gr_snow_deformation_params p;
  gr_snow_deformation_params_init(&p);
  gr_snow_deformation *s = NULL;
  if (gr_snow_deformation_create(ctx, g, &p, &s) == GR_OK) {
    float *f = plane(g, 0.0f);
    gr_snow_deformation_step(s, 0.01);
    gr_snow_deformation_get_field(s, GR_FIELD_SNOW_SURFACE, f);
    free(f);
  }
  return s;
}

static void drop_deformation(void *h) {
  gr_snow_deformation_destroy(h);
}

static gr_snow_accumulation_params snow_params;

static void *make_accumulation(const gr_grid *g) {
  gr_snow_accumulation *s = NULL;
  if (gr_snow_accumulation_create(ctx, g, &snow_params, &s) == GR_OK) {
    float *f = plane(g, 0.0f);
    gr_snow_accumulation_step(s, 60.0);
    gr_snow_accumulation_get_field(s, GR_FIELD_EXPOSURE, f);
    free(f);
  }
  return s;
}

static void drop_accumulation(void *h) {
  gr_snow_accumulation_destroy(h);
}

static void *make_water(const gr_grid *g) {
  gr_water_surface_params p;
  gr_water_surface_params_init(&p);
  p.drop_rate = 1.0; /* the drops' plane too */
  gr_water_surface *s = NULL;
  if (gr_water_surface_create(ctx, g, &p, &s) == GR_OK) {
    float *f = plane(g, 0.0f), *d = plane(g, 1.0f);
    gr_water_surface_set_field(s, GR_FIELD_ELEVATION, f);
    gr_water_surface_set_field(s, GR_FIELD_WATER_DEPTH, d);
    double dt = 0.0;
    gr_water_surface_stable_dt(s, &dt);
    gr_water_surface_step(s, dt, 2);
    gr_water_surface_get(s, GR_WATER_NORMAL, f);
    free(f);
    free(d);
  }
  return s;
}

static void drop_water(void *h) {
  gr_water_surface_destroy(h);
}

static gr_cloud_cover_params cloud_params;

static void *make_clouds(const gr_grid *g) {
  (void)g;
  gr_cloud_cover *c = NULL;
  if (gr_cloud_cover_create(ctx, &cloud_params, &c) == GR_OK)
    gr_cloud_cover_compute(c, 0.0);
  return c;
}

static void drop_clouds(void *h) {
  gr_cloud_cover_destroy(h);
}

static gr_particles_params particle_params;

static void *make_particles(const gr_grid *g) {
  (void)g;
  gr_particles *s = NULL;
  if (gr_particles_create(ctx, &particle_params, &s) == GR_OK)
    gr_particles_compute(s, 0.0);
  return s;
}

static void drop_particles(void *h) {
  gr_particles_destroy(h);
}

static void test_estimates(void) {
  if (!limits_usable())
    return;
  if (!uses_host_memory()) {
    printf("the device keeps its buffers apart from the host's memory: estimates not measured\n");
    return;
  }
  gr_grid g = {512, 384, 2.0, 2.0, 0.0, 0.0, 0, 0};
  gr_memory_need est;
  CHECK(gr_procedural_terrain_memory(&g, &est) == GR_OK);
  CHECK(est.points == 512.0 * 384 && est.device >= 4.0 * est.points &&
        est.largest == 4.0 * est.points);
  compare("procedural_terrain", &g, &est, make_terrain, drop_terrain, 0.0);
  CHECK(gr_terrain_analysis_memory(&g, &est) == GR_OK);
  compare("terrain_analysis", &g, &est, make_analysis, drop_analysis, 0.0);
  /* Rain runoff: a plain run of each model on this device; the estimate
   * for no optional inputs counts the initial water's plane. */
  for (int model = 0; model < 2; ++model) {
    gr_rain_runoff_params_init(&rain_params);
    rain_params.flow_model = model ? GR_FLOW_LOCAL_INERTIAL : GR_FLOW_SHALLOW_WATER;
    CHECK(gr_rain_runoff_memory(ctx, &g, &rain_params, 0, &est) == GR_OK);
    compare(model ? "rain_runoff (LI)" : "rain_runoff (SW)", &g, &est, make_rain, drop_rain, 0.0);
    gr_memory_need all;
    CHECK(gr_rain_runoff_memory(ctx, &g, &rain_params, GR_RAIN_RUNOFF_INPUT_ALL, &all) == GR_OK);
    CHECK_NEAR(all.device - est.device, 6.0 * 4.0 * est.points, 1.0);
    CHECK(all.state == est.state && est.state >= 17.0 * 4.0 * est.points);
  }
  CHECK(gr_snow_deformation_memory(&g, &est) == GR_OK);
  compare("snow_deformation", &g, &est, make_deformation, drop_deformation, 0.0);
  gr_snow_accumulation_params_init(&snow_params);
  snow_params.exposure_resolution = 256;
  CHECK(gr_snow_accumulation_memory(&g, &snow_params, &est) == GR_OK);
  compare("snow_accumulation", &g, &est, make_accumulation, drop_accumulation, 0.0);
  CHECK(gr_water_surface_memory(&g, &est) == GR_OK);
  /* The drops' mask of the still surface and wet points are made and freed
   * within a call: counted, not held (2 planes' worth). */
  compare("water_surface", &g, &est, make_water, drop_water, 2.0);
  gr_cloud_cover_params_init(&cloud_params);
  cloud_params.resolution = 1024;
  CHECK(gr_cloud_cover_memory(&cloud_params, &est) == GR_OK);
  CHECK(est.points == 1024.0 * 1024.0);
  gr_grid image;
  gr_cloud_cover_grid(&cloud_params, &image);
  compare("cloud_cover", &image, &est, make_clouds, drop_clouds, 0.0);
  gr_particles_params_init(&particle_params);
  particle_params.count = 1 << 20;
  CHECK(gr_particles_memory(&particle_params, &est) == GR_OK);
  CHECK(est.device == (3.0 + 3.0 + 1.0 + 3.0) * 4.0 * (1 << 20) || est.device > 0.0);
  compare("particles", &g, &est, make_particles, drop_particles, 0.0);
}

/* Every core refuses, before allocating, a grid beyond what the process can
 * get: GR_ERR_TOO_LARGE, a sentence that names the grid and both figures,
 * no handle and nothing mapped. 40 MB are left; a 4096 x 4096 grid's float
 * plane alone takes 67 MB. */
#define REFUSED(name, what, call, handle, destroy)                                                 \
  do {                                                                                             \
    limit_to(40 * MB);                                                                             \
    double before_ = vm_size();                                                                    \
    gr_status st_ = (call);                                                                        \
    double mapped_ = vm_size() - before_;                                                          \
    unlimit();                                                                                     \
    const char *e_ = gr_last_error(ctx);                                                           \
    CHECK_MSG(st_ == GR_ERR_TOO_LARGE && (handle) == NULL, "%s: %s", name, gr_status_string(st_)); \
    CHECK_MSG(strstr(e_, what) && strstr(e_, " needs ") && strstr(e_, "this process can use ") &&  \
                  strstr(e_, "(its address-space limit)"),                                         \
              "%s: '%s'", name, e_);                                                               \
    CHECK_MSG(mapped_ < 1 * MB, "%s: %.1f MB mapped", name, mapped_ / MB);                         \
    printf("%s\n", e_);                                                                            \
    destroy(handle);                                                                               \
  } while (0)

static void test_refusals(void) {
  if (!limits_usable())
    return;
  /* On a GPU the cores' buffers are the device's memory: an address-space
   * limit bounds only the host's copies (and the driver's own mappings,
   * which then fail cleanly but without the estimate's sentence). */
  if (!uses_host_memory()) {
    printf("refusals: skipped, the device's buffers are not host memory\n");
    return;
  }
  /* The programs first: building them takes memory of its own. */
  gr_grid small = {64, 64, 1.0, 1.0, 0.0, 0.0, 0, 0};
  drop_terrain(make_terrain(&small));
  drop_analysis(make_analysis(&small));
  gr_rain_runoff_params_init(&rain_params);
  drop_rain(make_rain(&small));
  drop_deformation(make_deformation(&small));
  gr_snow_accumulation_params_init(&snow_params);
  drop_accumulation(make_accumulation(&small));
  drop_water(make_water(&small));
  gr_cloud_cover_params_init(&cloud_params);
  gr_particles_params_init(&particle_params);

  gr_grid g = {4096, 4096, 1.0, 1.0, 0.0, 0.0, 0, 0};
  const char *grid = "4096 x 4096 grid";
  gr_procedural_terrain_params pt;
  gr_procedural_terrain_params_init(&pt);
  gr_procedural_terrain *terrain = NULL;
  REFUSED("procedural terrain", grid, gr_procedural_terrain_create(ctx, &g, &pt, &terrain), terrain,
          gr_procedural_terrain_destroy);
  gr_terrain_analysis_params ta;
  gr_terrain_analysis_params_init(&ta);
  gr_terrain_analysis *analysis = NULL;
  REFUSED("terrain analysis", grid, gr_terrain_analysis_create(ctx, &g, &ta, &analysis), analysis,
          gr_terrain_analysis_destroy);
  gr_rain_runoff *rain = NULL;
  REFUSED("rain runoff", grid, gr_rain_runoff_create(ctx, &g, &rain_params, &rain), rain,
          gr_rain_runoff_destroy);
  gr_snow_deformation_params sd;
  gr_snow_deformation_params_init(&sd);
  gr_snow_deformation *deformation = NULL;
  REFUSED("snow deformation", grid, gr_snow_deformation_create(ctx, &g, &sd, &deformation),
          deformation, gr_snow_deformation_destroy);
  gr_snow_accumulation *accumulation = NULL;
  REFUSED("snow accumulation", grid,
          gr_snow_accumulation_create(ctx, &g, &snow_params, &accumulation), accumulation,
          gr_snow_accumulation_destroy);
  gr_water_surface_params ws;
  gr_water_surface_params_init(&ws);
  gr_water_surface *water = NULL;
  REFUSED("water surface", grid, gr_water_surface_create(ctx, &g, &ws, &water), water,
          gr_water_surface_destroy);
  cloud_params.resolution = 8192;
  gr_cloud_cover *clouds = NULL;
  REFUSED("cloud cover", "8192 x 8192 pixels", gr_cloud_cover_create(ctx, &cloud_params, &clouds),
          clouds, gr_cloud_cover_destroy);
  particle_params.count = 1 << 24;
  gr_particles *particles = NULL;
  REFUSED("particles", "16777216 particles", gr_particles_create(ctx, &particle_params, &particles),
          particles, gr_particles_destroy);

  /* The EXR reader, before it decodes: 2048 x 2048 pixels in 2 channels
   * (33.6 MB of planes) with 20 MB left. */
  const char *dir = getenv("GR_TEST_SCRATCH");
  char path[4096];
  snprintf(path, sizeof(path), "%s/memory_2048.exr", dir && *dir ? dir : "/tmp");
  size_t n = (size_t)2048 * 2048;
  float *plane0 = calloc(n, sizeof(float)), *plane1 = calloc(n, sizeof(float));
  const char *names[2] = {"elevation", "snow_depth"};
  const float *data[2] = {plane0, plane1};
  char err[512];
  CHECK(plane0 && plane1 &&
        gr_exr_write(path, 2048, 2048, 2, names, data, GR_EXR_FLOAT, err, sizeof(err)) == GR_OK);
  free(plane0);
  free(plane1);
  gr_exr_image img;
  memset(&img, 0, sizeof(img));
  limit_to(20 * MB);
  double before = vm_size();
  gr_status st = gr_exr_read(path, &img, err, sizeof(err));
  double mapped = vm_size() - before;
  unlimit();
  CHECK_MSG(st == GR_ERR_TOO_LARGE && img.data == NULL, "exr: %s", gr_status_string(st));
  CHECK_MSG(strstr(err, "2048 by 2048 pixels in 2 channels needs 33.6 MB (8 bytes a point) but "
                        "this process can use ") != NULL,
            "exr: '%s'", err);
  CHECK_MSG(mapped < 1 * MB, "exr: %.1f MB mapped", mapped / MB);
  printf("%s\n", err);
  CHECK(gr_exr_read(path, &img, err, sizeof(err)) == GR_OK && img.width == 2048);
  gr_exr_image_free(&img);
  remove(path);
}

static int setup(void) {
  /* Every allocation from 64 kB on its own mapping (see the file comment). */
  mallopt(M_MMAP_THRESHOLD, 64 * 1024);
  return gr_context_create(NULL, &ctx) == GR_OK;
}

static void teardown(void) {
  gr_context_release(ctx);
}

static const gr_subtest tests[] = {
    {"format", test_format, 0},   {"query", test_query, 0},         {"check", test_check, 0},
    {"buffers", test_buffers, 0}, {"estimates", test_estimates, 0}, {"refusals", test_refusals, 0},
};

int main(int argc, char **argv) {
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), setup, teardown);
}
