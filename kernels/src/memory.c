/* What memory there is (host and device), and whether a grid fits in it. */
#include "graupel/memory.h"
#include "graupel/cl_runtime.h"

#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

/* A "Key:  N kB" line of a /proc file, in bytes; GR_MEMORY_UNLIMITED when
 * the file or the key is not there (not Linux). */
static unsigned long long gr_proc_kb(const char *path, const char *key) {
  unsigned long long bytes = GR_MEMORY_UNLIMITED;
  FILE *f = fopen(path, "r");
  if (!f)
    return bytes;
  char line[256];
  size_t n = strlen(key);
  while (fgets(line, sizeof(line), f)) {
    unsigned long long kb = 0;
    if (strncmp(line, key, n) == 0 && line[n] == ':' && sscanf(line + n + 1, "%llu", &kb) == 1) {
      bytes = kb * 1024ULL;
      break;
    }
  }
  fclose(f);
  return bytes;
}

/* The process's mapped address space (VmSize), in bytes; 0 when unknown.
 * /proc/self/statm's first figure is the same in pages, one read. */
static unsigned long long gr_mapped_bytes(void) {
  unsigned long long pages = 0;
  FILE *f = fopen("/proc/self/statm", "r");
  if (!f)
    return 0;
  if (fscanf(f, "%llu", &pages) != 1)
    pages = 0;
  fclose(f);
  long page = sysconf(_SC_PAGESIZE);
  return pages * (unsigned long long)(page > 0 ? page : 4096);
}

gr_status gr_memory_query(const gr_context *ctx, gr_memory_info *out) {
  if (!out)
    return gr_set_error(ctx, GR_ERR_INVALID_ARGUMENT,
                        "gr_memory_query needs a place for the answer.");
  memset(out, 0, sizeof(*out));
  out->host_free = gr_proc_kb("/proc/meminfo", "MemAvailable");
  out->address_space_left = GR_MEMORY_UNLIMITED;
  struct rlimit as;
  if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    unsigned long long limit = (unsigned long long)as.rlim_cur, mapped = gr_mapped_bytes();
    out->address_space_left = limit > mapped ? limit - mapped : 0;
  }
  out->host_available =
      out->host_free < out->address_space_left ? out->host_free : out->address_space_left;
  if (ctx) {
    gr_device_info info;
    gr_status st = gr_context_device_info(ctx, &info);
    if (st != GR_OK)
      return st;
    out->device_global = info.global_mem_bytes;
    out->device_max_alloc = info.max_alloc_bytes;
    out->device_uses_host_memory = info.host_memory;
  }
  return GR_OK;
}

void gr_memory_need_add(gr_memory_need *a, const gr_memory_need *b) {
  if (!a || !b)
    return;
  a->device += b->device;
  a->host += b->host;
  a->points += b->points;
  a->state += b->state;
  if (b->largest > a->largest)
    a->largest = b->largest;
}

void gr_memory_format(double bytes, char *buf, size_t len) {
  if (!buf || !len)
    return;
  if (bytes >= 1e9)
    snprintf(buf, len, "%.1f GB", bytes / 1e9);
  else if (bytes >= 1e6)
    snprintf(buf, len, "%.1f MB", bytes / 1e6);
  else
    snprintf(buf, len, "%.0f kB", bytes / 1e3);
}

/* Two figures that must read differently: with three decimals where one
 * would show them equal ("needs 4.3 GB but ... allows at most 4.3 GB"). */
static void gr_format_pair(double need, double have, char *a, char *b, size_t len) {
  gr_memory_format(need, a, len);
  gr_memory_format(have, b, len);
  if (strcmp(a, b) == 0 && need >= 1e6) {
    double unit = need >= 1e9 ? 1e9 : 1e6;
    const char *name = need >= 1e9 ? "GB" : "MB";
    snprintf(a, len, "%.3f %s", need / unit, name);
    snprintf(b, len, "%.3f %s", have / unit, name);
  }
}

/* " (N bytes a point)", or "" without points. */
static void gr_per_point(double bytes, double points, char *buf, size_t len) {
  if (points >= 1.0)
    snprintf(buf, len, " (%.0f bytes a point)", bytes / points);
  else
    buf[0] = '\0';
}

gr_status gr_memory_check(const gr_context *ctx, const gr_memory_need *need, char *msg,
                          size_t msg_len) {
  char scratch[8];
  if (!msg || !msg_len) {
    msg = scratch;
    msg_len = sizeof(scratch);
  }
  msg[0] = '\0';
  if (!need)
    return GR_ERR_INVALID_ARGUMENT;
  gr_memory_info mem;
  gr_status st = gr_memory_query(ctx, &mem);
  if (st != GR_OK)
    return st;
  char a[32], b[32], per[48];
  const char *device = ctx ? gr_context_device_name(ctx) : "";
  double host = need->host;
  if (ctx && !mem.device_uses_host_memory) {
    if (need->device > (double)mem.device_global) {
      gr_format_pair(need->device, (double)mem.device_global, a, b, sizeof(a));
      gr_per_point(need->device, need->points, per, sizeof(per));
      snprintf(msg, msg_len, "needs %s of device memory%s but the device '%s' has %s", a, per,
               device, b);
      return GR_ERR_TOO_LARGE;
    }
  } else {
    host += need->device;
  }
  if (host > (double)mem.host_available) {
    gr_format_pair(host, (double)mem.host_available, a, b, sizeof(a));
    gr_per_point(host, need->points, per, sizeof(per));
    snprintf(msg, msg_len, "needs %s%s%s but this process can use %s%s", a,
             ctx && !mem.device_uses_host_memory ? " of host memory" : "", per, b,
             mem.address_space_left < mem.host_free ? " (its address-space limit)" : "");
    return GR_ERR_TOO_LARGE;
  }
  if (ctx && need->largest > (double)mem.device_max_alloc) {
    gr_format_pair(need->largest, (double)mem.device_max_alloc, a, b, sizeof(a));
    snprintf(msg, msg_len,
             "needs one buffer of %s but the device '%s' allows at most %s in one buffer", a,
             device, b);
    return GR_ERR_TOO_LARGE;
  }
  return GR_OK;
}
