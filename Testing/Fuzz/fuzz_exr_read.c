/* libFuzzer harness: gr_exr_read_memory on arbitrary bytes.
 *
 * On success the image must keep the reader's promises (dimensions and
 * sample count within the limits, at least one channel, names non-empty,
 * distinct and findable, HALF or FLOAT types, a plane per channel whose first
 * and last samples can be read); on failure the status must be GR_ERR_FORMAT
 * (or GR_ERR_OUT_OF_MEMORY), the output untouched and the error a sentence
 * naming the label. A broken promise is __builtin_trap(). */
#include "fuzz_common.h"
#include "graupel/exr_io.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define LABEL "fuzz input"

static void check_image(const gr_exr_image *img) {
  size_t npix;
  int c, k;
  REQUIRE(img->width >= 1 && img->width <= GR_EXR_MAX_DIM);
  REQUIRE(img->height >= 1 && img->height <= GR_EXR_MAX_DIM);
  REQUIRE(img->nchannels > 0);
  npix = (size_t)img->width * (size_t)img->height;
  REQUIRE(npix <= GR_EXR_MAX_SAMPLES / (size_t)img->nchannels);
  REQUIRE(img->names != NULL && img->types != NULL && img->data != NULL);
  for (c = 0; c < img->nchannels; ++c) {
    volatile float first, last;
    size_t len;
    REQUIRE(img->names[c] != NULL);
    len = strlen(img->names[c]);
    REQUIRE(len > 0 && len <= GR_EXR_MAX_NAME);
    for (k = 0; k < c; ++k)
      REQUIRE(strcmp(img->names[k], img->names[c]) != 0);
    REQUIRE(gr_exr_find_channel(img, img->names[c]) == c);
    REQUIRE(img->types[c] == GR_EXR_HALF || img->types[c] == GR_EXR_FLOAT);
    REQUIRE(img->data[c] != NULL);
    /* Under AddressSanitizer, a plane shorter than width*height traps. */
    first = img->data[c][0];
    last = img->data[c][npix - 1];
    (void)first;
    (void)last;
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  gr_exr_image img;
  char err[1024];
  gr_status st;
  size_t n;

  memset(&img, 0, sizeof img);
  img.width = -7;
  img.height = -9;
  img.nchannels = 12345;
  err[0] = '\0';
  st = gr_exr_read_memory(data, size, LABEL, &img, err, sizeof err);
  if (st == GR_OK) {
    check_image(&img);
    gr_exr_image_free(&img);
    REQUIRE(img.width == 0 && img.height == 0 && img.nchannels == 0 && img.names == NULL &&
            img.types == NULL && img.data == NULL);
    return 0;
  }
  REQUIRE(st == GR_ERR_FORMAT || st == GR_ERR_OUT_OF_MEMORY);
  REQUIRE(img.width == -7 && img.height == -9 && img.nchannels == 12345 && img.names == NULL &&
          img.types == NULL && img.data == NULL);
  n = strlen(err);
  REQUIRE(n > 0 && err[n - 1] == '.');
  REQUIRE(strstr(err, "'" LABEL "'") != NULL);
  return 0;
}
