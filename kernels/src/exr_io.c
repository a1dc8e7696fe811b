/*
 * exr_io.c - height fields and named fields in OpenEXR files, through
 * OpenEXR's C API (OpenEXRCore): reading, the error text the reader and the
 * writer share, and the image helpers. The graupel.* header attributes are
 * in exr_io_meta.c, writing in exr_io_write.c (around exr_io_internal.h).
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
#include "exr_io_internal.h"
#include "graupel/memory.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* Error text                                                               */
/* ------------------------------------------------------------------------ */

void gr_exr_capture_error(exr_const_context_t ctxt, exr_result_t code, const char *msg) {
  void *ud = NULL;
  gr_exr_msg *m;
  (void)code;
  if (ctxt == NULL || exr_get_user_data(ctxt, &ud) != EXR_ERR_SUCCESS || ud == NULL)
    return;
  m = (gr_exr_msg *)ud;
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

void gr_exr_set_err(char *err, size_t err_len, const char *fmt, ...) {
  va_list ap;
  if (err == NULL || err_len == 0)
    return;
  va_start(ap, fmt);
  vsnprintf(err, err_len, fmt, ap);
  va_end(ap);
}

/* The library's own words for a failure: the captured message, or the
 * generic text of the code. */
const char *gr_exr_detail(const gr_exr_msg *m, exr_result_t rv) {
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
 * comes first: gr_exr_capture_error takes the user data for an gr_exr_msg. */
typedef struct read_source {
  gr_exr_msg msg;
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

/* Opens the file or the buffer of src as *ctxt (label names it). */
static gr_status read_open(const char *label, read_source *src, exr_context_t *ctxt, char *err,
                           size_t err_len) {
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = &gr_exr_capture_error;
  init.user_data = src;
  init.max_image_width = GR_EXR_MAX_DIM;
  init.max_image_height = GR_EXR_MAX_DIM;
  init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
  if (src->bytes != NULL) {
    /* The label is only a name: OpenEXR opens nothing when read_fn is set. */
    init.read_fn = &memory_read;
    init.size_fn = &memory_size;
  }
  exr_result_t rv = exr_start_read(ctxt, label, &init);
  if (rv == EXR_ERR_SUCCESS)
    return GR_OK;
  if (rv == EXR_ERR_FILE_ACCESS)
    gr_exr_set_err(err, err_len, "Cannot read '%s': the file cannot be opened (OpenEXR: %s).",
                   label, gr_exr_detail(&src->msg, rv));
  else
    gr_exr_set_err(err, err_len, "Cannot read '%s': it is not a valid OpenEXR file (OpenEXR: %s).",
                   label, gr_exr_detail(&src->msg, rv));
  return read_status(rv);
}

/* Part 0's header: its storage, data window (into L) and channels; deep
 * data is refused. */
static gr_status read_header(const char *label, const gr_exr_msg *msg, chunk_layout *L,
                             exr_storage_t *storage, const exr_attr_chlist_t **chlist, char *err,
                             size_t err_len) {
  int nparts = 0;
  exr_result_t rv = exr_get_count(L->ctxt, &nparts);
  if (rv == EXR_ERR_SUCCESS && nparts < 1)
    rv = EXR_ERR_FILE_BAD_HEADER;
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_storage(L->ctxt, 0, storage);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_data_window(L->ctxt, 0, &L->dw);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_channels(L->ctxt, 0, chlist);
  if (rv == EXR_ERR_SUCCESS && *chlist == NULL)
    rv = EXR_ERR_MISSING_REQ_ATTR;
  if (rv != EXR_ERR_SUCCESS) {
    gr_exr_set_err(err, err_len, "Cannot read '%s': its header is incomplete (OpenEXR: %s).", label,
                   gr_exr_detail(msg, rv));
    return read_status(rv);
  }
  if (*storage != EXR_STORAGE_SCANLINE && *storage != EXR_STORAGE_TILED) {
    gr_exr_set_err(err, err_len, "Cannot read '%s': it holds deep data, which is not supported.",
                   label);
    return GR_ERR_FORMAT;
  }
  return GR_OK;
}

/* Size guards, before anything is allocated: the data window, the samples
 * (*npix pixels a channel) and the memory the planes take. */
static gr_status read_size_guards(const char *label, chunk_layout *L,
                                  const exr_attr_chlist_t *chlist, size_t *npix, char *err,
                                  size_t err_len) {
  L->width = (int64_t)L->dw.max.x - (int64_t)L->dw.min.x + 1;
  L->height = (int64_t)L->dw.max.y - (int64_t)L->dw.min.y + 1;
  if (L->width < 1 || L->height < 1 || L->width > GR_EXR_MAX_DIM || L->height > GR_EXR_MAX_DIM) {
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': its data window is %lld by %lld pixels, outside "
                   "1 to %d.",
                   label, (long long)L->width, (long long)L->height, GR_EXR_MAX_DIM);
    return GR_ERR_FORMAT;
  }
  if (chlist->num_channels < 1 || chlist->entries == NULL) {
    gr_exr_set_err(err, err_len, "Cannot read '%s': it has no channels.", label);
    return GR_ERR_FORMAT;
  }
  *npix = (size_t)L->width * (size_t)L->height;
  if (*npix > GR_EXR_MAX_SAMPLES / (size_t)chlist->num_channels ||
      *npix > SIZE_MAX / sizeof(float)) {
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': %lld by %lld pixels in %d channels is more than "
                   "the %llu samples allowed.",
                   label, (long long)L->width, (long long)L->height, chlist->num_channels,
                   (unsigned long long)GR_EXR_MAX_SAMPLES);
    return GR_ERR_FORMAT;
  }
  /* The planes, before anything is decoded: a file that does not fit is
   * refused at once, not after minutes of decoding or by a failed malloc
   * under the kernel's overcommit. */
  gr_memory_need need;
  char why[200];
  memset(&need, 0, sizeof(need));
  need.points = (double)*npix;
  need.host = (double)*npix * (double)chlist->num_channels * sizeof(float);
  if (gr_memory_check(NULL, &need, why, sizeof(why)) != GR_OK) {
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': the image of %lld by %lld pixels in %d channels %s.", label,
                   (long long)L->width, (long long)L->height, chlist->num_channels, why);
    return GR_ERR_TOO_LARGE;
  }
  return GR_OK;
}

/* Every channel HALF or FLOAT, not subsampled, with a name. */
static gr_status read_check_channels(const char *label, const exr_attr_chlist_t *chlist, char *err,
                                     size_t err_len) {
  for (size_t c = 0; c < (size_t)chlist->num_channels; ++c) {
    const exr_attr_chlist_entry_t *e = &chlist->entries[c];
    const char *nm = e->name.str != NULL ? e->name.str : "";
    if (e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT) {
      gr_exr_set_err(err, err_len,
                     "Cannot read '%s': channel '%s' is %s, and only HALF and FLOAT "
                     "channels are supported.",
                     label, nm, pixel_type_name(e->pixel_type));
      return GR_ERR_FORMAT;
    }
    if (e->x_sampling != 1 || e->y_sampling != 1) {
      gr_exr_set_err(err, err_len,
                     "Cannot read '%s': channel '%s' is subsampled (%d by %d), which "
                     "is not supported.",
                     label, nm, (int)e->x_sampling, (int)e->y_sampling);
      return GR_ERR_FORMAT;
    }
    if (nm[0] == '\0' || strlen(nm) > GR_EXR_MAX_NAME) {
      gr_exr_set_err(err, err_len, "Cannot read '%s': channel %d has an empty or over-long name.",
                     label, (int)c);
      return GR_ERR_FORMAT;
    }
  }
  return GR_OK;
}

/* The chunk layout into L: the compression (and the most a packed byte may
 * unpack to), then scanlines per chunk or the level-0 tiles. */
static gr_status read_chunk_layout(const char *label, const gr_exr_msg *msg, exr_storage_t storage,
                                   chunk_layout *L, char *err, size_t err_len) {
  exr_compression_t comp = EXR_COMPRESSION_NONE;
  exr_result_t rv = exr_get_compression(L->ctxt, 0, &comp);
  if (rv != EXR_ERR_SUCCESS) {
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': its compression is not understood (OpenEXR: %s).", label,
                   gr_exr_detail(msg, rv));
    return GR_ERR_FORMAT;
  }
  L->compression = comp;
  L->expand = max_expansion(comp);
  /* DWA the library cannot decode: allow only raw-stored chunks, so that a
   * small hostile file cannot claim gigabytes (DWA packs about 66000:1)
   * and be refused only after the image was allocated. */
  L->undecodable =
      (comp == EXR_COMPRESSION_DWAA || comp == EXR_COMPRESSION_DWAB) && !core_decodes_dwa();
  if (L->undecodable)
    L->expand = 1;
  if (storage == EXR_STORAGE_SCANLINE) {
    int32_t lines = 0;
    rv = exr_get_scanlines_per_chunk(L->ctxt, 0, &lines);
    if (rv != EXR_ERR_SUCCESS || lines < 1) {
      gr_exr_set_err(err, err_len,
                     "Cannot read '%s': its compression is not understood (OpenEXR: %s).", label,
                     gr_exr_detail(msg, rv));
      return GR_ERR_FORMAT;
    }
    L->lines = lines;
    return GR_OK;
  }
  uint32_t tw = 0, th = 0;
  exr_tile_level_mode_t lmode;
  exr_tile_round_mode_t rmode;
  rv = exr_get_tile_descriptor(L->ctxt, 0, &tw, &th, &lmode, &rmode);
  if (rv != EXR_ERR_SUCCESS || tw < 1 || th < 1 || tw > INT32_MAX || th > INT32_MAX) {
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': its tile description is not valid (OpenEXR: %s).", label,
                   gr_exr_detail(msg, rv));
    return GR_ERR_FORMAT;
  }
  L->tiled = 1;
  L->tw = (int64_t)tw;
  L->th = (int64_t)th;
  L->ntx = (L->width + L->tw - 1) / L->tw;
  L->nty = (L->height + L->th - 1) / L->th;
  return GR_OK;
}

/* The image's names, types and planes (npix floats each), once every
 * chunk's description passed; a name twice is refused. */
static gr_status read_alloc_image(const char *label, const chunk_layout *L,
                                  const exr_attr_chlist_t *chlist, size_t npix, gr_exr_image *img,
                                  char *err, size_t err_len) {
  img->width = (int)L->width;
  img->height = (int)L->height;
  img->names = (char **)calloc((size_t)chlist->num_channels, sizeof(char *));
  img->types = (gr_exr_pixel_type *)calloc((size_t)chlist->num_channels, sizeof(gr_exr_pixel_type));
  img->data = (float **)calloc((size_t)chlist->num_channels, sizeof(float *));
  if (img->names == NULL || img->types == NULL || img->data == NULL) {
    gr_exr_set_err(err, err_len, "Cannot read '%s': out of memory.", label);
    return GR_ERR_OUT_OF_MEMORY;
  }
  img->nchannels = chlist->num_channels;
  for (size_t c = 0; c < (size_t)img->nchannels; ++c) {
    const exr_attr_chlist_entry_t *e = &chlist->entries[c];
    size_t len = strlen(e->name.str);
    img->names[c] = (char *)malloc(len + 1);
    img->data[c] = (float *)malloc(npix * sizeof(float));
    if (img->names[c] == NULL || img->data[c] == NULL) {
      gr_exr_set_err(err, err_len,
                     "Cannot read '%s': out of memory for %lld by %lld pixels in "
                     "%d channels.",
                     label, (long long)L->width, (long long)L->height, img->nchannels);
      return GR_ERR_OUT_OF_MEMORY;
    }
    memcpy(img->names[c], e->name.str, len + 1);
    img->types[c] = e->pixel_type == EXR_PIXEL_HALF ? GR_EXR_HALF : GR_EXR_FLOAT;
  }
  for (size_t c = 0; c < (size_t)img->nchannels; ++c) {
    if (gr_exr_find_channel(img, img->names[c]) != (int)c) {
      gr_exr_set_err(err, err_len, "Cannot read '%s': channel '%s' appears twice.", label,
                     img->names[c]);
      return GR_ERR_FORMAT;
    }
  }
  return GR_OK;
}

/* The sentence for walk_chunks' failure rv at the chunk fault names. */
static gr_status read_chunk_error(const char *label, const gr_exr_msg *msg, const chunk_layout *L,
                                  const chunk_fault *fault, exr_result_t rv, char *err,
                                  size_t err_len) {
  char where[64];
  if (L->tiled)
    snprintf(where, sizeof where, "tile (%lld, %lld)", (long long)fault->x, (long long)fault->y);
  else
    snprintf(where, sizeof where, "scanline %lld", (long long)fault->y);
  if (fault->implausible && L->undecodable)
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': the OpenEXR library in use cannot decode its %s compression "
                   "(at %s).",
                   label, compression_name(L->compression), where);
  else if (fault->implausible)
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': the chunk at %s claims %llu bytes of pixels from %llu "
                   "compressed bytes, more than its compression can hold; the file is corrupt.",
                   label, where, (unsigned long long)fault->unpacked,
                   (unsigned long long)fault->packed);
  else if (rv == EXR_ERR_FEATURE_NOT_IMPLEMENTED)
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': the OpenEXR library in use cannot decode its %s compression "
                   "(at %s; OpenEXR: %s).",
                   label, compression_name(L->compression), where, gr_exr_detail(msg, rv));
  else
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': the file is truncated or corrupt at %s (OpenEXR: %s).", label,
                   where, gr_exr_detail(msg, rv));
  return read_status(rv);
}

/* gr_exr_read and gr_exr_read_memory: opens the file or the buffer of src
 * (label names it in every message: the path of a file), then parses, checks
 * and decodes part 0. The arguments are checked by the callers. */
static gr_status read_exr(const char *label, read_source *src, gr_exr_image *out, char *err,
                          size_t err_len) {
  gr_status st = GR_OK;
  exr_context_t ctxt = NULL;
  exr_decode_pipeline_t dec;
  int dec_live = 0;
  gr_exr_msg *msg = &src->msg;
  exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
  const exr_attr_chlist_t *chlist = NULL;
  chunk_layout L;
  chunk_fault fault;
  size_t npix = 0;
  gr_exr_image img;

  memset(&img, 0, sizeof img);
  memset(&dec, 0, sizeof dec);
  memset(msg, 0, sizeof *msg);
  memset(&L, 0, sizeof L);
  memset(&fault, 0, sizeof fault);

  st = read_open(label, src, &ctxt, err, err_len);
  if (st != GR_OK)
    goto cleanup;
  L.ctxt = ctxt;
  st = read_header(label, msg, &L, &storage, &chlist, err, err_len);
  if (st == GR_OK)
    st = read_size_guards(label, &L, chlist, &npix, err, err_len);
  if (st == GR_OK)
    st = read_check_channels(label, chlist, err, err_len);
  if (st == GR_OK)
    st = gr_exr_meta_read(ctxt, label, &img.meta, err, err_len);
  if (st == GR_OK)
    st = read_chunk_layout(label, msg, storage, &L, err, err_len);
  /* Pass 0 checks every chunk's description against the file; pass 1
   * allocates the image and decodes. */
  for (int pass = 0; st == GR_OK && pass < 2; ++pass) {
    if (pass == 1)
      st = read_alloc_image(label, &L, chlist, npix, &img, err, err_len);
    if (st != GR_OK)
      break;
    exr_result_t rv = walk_chunks(&L, pass == 1 ? &img : NULL, &dec, &dec_live, &fault);
    if (rv != EXR_ERR_SUCCESS)
      st = read_chunk_error(label, msg, &L, &fault, rv, err, err_len);
  }
  /* File rows run north to south; memory row 0 is south. */
  for (size_t c = 0; st == GR_OK && c < (size_t)img.nchannels; ++c)
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
    gr_exr_set_err(err, err_len,
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
    gr_exr_set_err(err, err_len, "The output image given to gr_exr_read_memory must not be NULL.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (data == NULL || size == 0) {
    gr_exr_set_err(err, err_len,
                   "Cannot read '%s': the buffer is empty, so it is not an OpenEXR file.", label);
    return GR_ERR_FORMAT;
  }
  memset(&src, 0, sizeof src);
  src.bytes = (const unsigned char *)data;
  src.size = size;
  return read_exr(label, &src, out, err, err_len);
}
