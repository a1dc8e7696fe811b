/*
 * exr_io_write.c - writing EXR files (gr_exr_write, gr_exr_write_meta): one
 * scanline part, ZIP compression, every channel HALF or FLOAT. Each chunk's
 * rows are copied, flipped, into a float staging buffer; the library packs
 * (and for HALF storage rounds to nearest even) from it.
 */
#include "exr_io_internal.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* OpenEXRCore 3.1.5's compressors keep the compressed bytes of a chunk when
 * they are exactly as many as the raw bytes (they fall back to raw only when
 * compression makes the chunk larger). Every reader, OpenEXR's own included,
 * takes packed size == unpacked size to mean "stored raw", so such a chunk
 * reads back as garbage (a 1x40 FLOAT image of 0..39 does it: its last chunk
 * is 32 bytes raw and 32 bytes deflated). This wraps the library's compressor
 * and stores the raw bytes whenever compression does not make the chunk
 * strictly smaller. */
typedef struct compress_hook {
  exr_result_t (*compress)(exr_encode_pipeline_t *enc);
} compress_hook;

static exr_result_t compress_or_store(exr_encode_pipeline_t *enc) {
  const compress_hook *hook = (const compress_hook *)enc->encoding_user_data;
  exr_result_t rv;
  if (hook == NULL || hook->compress == NULL)
    return EXR_ERR_INVALID_ARGUMENT;
  rv = hook->compress(enc);
  if (rv != EXR_ERR_SUCCESS)
    return rv;
  if (enc->compressed_bytes >= enc->packed_bytes && enc->compressed_buffer != enc->packed_buffer) {
    if (enc->compressed_buffer == NULL || enc->packed_buffer == NULL ||
        enc->compressed_alloc_size < enc->packed_bytes)
      return EXR_ERR_INVALID_ARGUMENT;
    memcpy(enc->compressed_buffer, enc->packed_buffer, (size_t)enc->packed_bytes);
    enc->compressed_bytes = (size_t)enc->packed_bytes;
  }
  return EXR_ERR_SUCCESS;
}

gr_status gr_exr_write(const char *path, int width, int height, int nchannels,
                       const char *const *names, const float *const *data, gr_exr_pixel_type type,
                       char *err, size_t err_len) {
  return gr_exr_write_meta(path, width, height, nchannels, names, data, type, NULL, err, err_len);
}

/* One image on its way to a file: the caller's arguments, the context and
 * part, and the chunk encoder with its float staging (nchannels planes of
 * stage_plane floats: width by at most lines rows). */
typedef struct write_job {
  const char *path;
  int width, height, nchannels;
  const char *const *names;
  const float *const *data;
  exr_context_t ctxt;
  int part;
  int32_t lines;
  exr_encode_pipeline_t enc;
  int enc_live;
  compress_hook hook;
  float *stage;
  size_t stage_plane;
} write_job;

/* The channels' names (present, not too long, each once) and data; sets
 * *longnames when a name needs OpenEXR's long names. */
static gr_status write_check_channels(const char *path, int nchannels, const char *const *names,
                                      const float *const *data, int *longnames, char *err,
                                      size_t err_len) {
  for (int c = 0; c < nchannels; ++c) {
    if (names[c] == NULL || names[c][0] == '\0') {
      gr_exr_set_err(err, err_len, "Cannot write '%s': channel %d has no name.", path, c);
      return GR_ERR_INVALID_ARGUMENT;
    }
    size_t len = strlen(names[c]);
    if (len > GR_EXR_MAX_NAME) {
      gr_exr_set_err(err, err_len,
                     "Cannot write '%s': the name of channel %d is %zu characters "
                     "long, and at most %d are allowed.",
                     path, c, len, GR_EXR_MAX_NAME);
      return GR_ERR_INVALID_ARGUMENT;
    }
    if (len > 31)
      *longnames = 1;
    if (data[c] == NULL) {
      gr_exr_set_err(err, err_len, "Cannot write '%s': channel '%s' has no data.", path, names[c]);
      return GR_ERR_INVALID_ARGUMENT;
    }
    for (int k = 0; k < c; ++k) {
      if (strcmp(names[k], names[c]) == 0) {
        gr_exr_set_err(err, err_len, "Cannot write '%s': the channel name '%s' is given twice.",
                       path, names[c]);
        return GR_ERR_INVALID_ARGUMENT;
      }
    }
  }
  return GR_OK;
}

/* gr_exr_write_meta's arguments, before any file is touched. */
static gr_status write_check_args(const char *path, int width, int height, int nchannels,
                                  const char *const *names, const float *const *data,
                                  gr_exr_pixel_type type, const gr_exr_meta *meta, int *longnames,
                                  char *err, size_t err_len) {
  if (path == NULL || path[0] == '\0') {
    gr_exr_set_err(err, err_len, "The path given to gr_exr_write must not be NULL or empty.");
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (width < 1 || height < 1 || width > GR_EXR_MAX_DIM || height > GR_EXR_MAX_DIM) {
    gr_exr_set_err(err, err_len,
                   "Cannot write '%s': the image is %d by %d pixels, outside 1 to %d.", path, width,
                   height, GR_EXR_MAX_DIM);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (nchannels < 1 || nchannels > INT16_MAX) {
    gr_exr_set_err(err, err_len,
                   "Cannot write '%s': %d channels were given, and 1 to %d are allowed.", path,
                   nchannels, INT16_MAX);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (type != GR_EXR_HALF && type != GR_EXR_FLOAT) {
    gr_exr_set_err(err, err_len, "Cannot write '%s': the pixel type %d is neither HALF nor FLOAT.",
                   path, (int)type);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (names == NULL || data == NULL) {
    gr_exr_set_err(err, err_len, "Cannot write '%s': the channel names or data are missing.", path);
    return GR_ERR_INVALID_ARGUMENT;
  }
  gr_status st = write_check_channels(path, nchannels, names, data, longnames, err, err_len);
  if (st != GR_OK)
    return st;
  if ((size_t)width * (size_t)height > GR_EXR_MAX_SAMPLES / (size_t)nchannels) {
    gr_exr_set_err(err, err_len,
                   "Cannot write '%s': %d by %d pixels in %d channels is more than "
                   "the %llu samples allowed.",
                   path, width, height, nchannels, (unsigned long long)GR_EXR_MAX_SAMPLES);
    return GR_ERR_INVALID_ARGUMENT;
  }
  if (meta != NULL)
    return gr_exr_meta_check(path, meta, longnames, err, err_len);
  return GR_OK;
}

/* The part, its channels and attributes, and the header written; then
 * the scanlines per chunk into job->lines. */
static exr_result_t write_header(write_job *job, exr_pixel_type_t ptype, const gr_exr_meta *meta,
                                 int longnames) {
  exr_context_t ctxt = job->ctxt;
  exr_result_t rv = EXR_ERR_SUCCESS;
  if (longnames)
    rv = exr_set_longname_support(ctxt, 1);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &job->part);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_initialize_required_attr_simple(ctxt, job->part, job->width, job->height,
                                             EXR_COMPRESSION_ZIP);
  for (int c = 0; c < job->nchannels && rv == EXR_ERR_SUCCESS; ++c)
    rv = exr_add_channel(ctxt, job->part, job->names[c], ptype, EXR_PERCEPTUALLY_LINEAR, 1, 1);
  if (rv == EXR_ERR_SUCCESS && meta != NULL)
    rv = gr_exr_meta_write(ctxt, job->part, meta);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_write_header(ctxt);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_get_scanlines_per_chunk(ctxt, job->part, &job->lines);
  if (rv == EXR_ERR_SUCCESS && job->lines < 1)
    rv = EXR_ERR_INVALID_ARGUMENT;
  return rv;
}

/* The rows of the chunk at file row y (nrows of them) into the staging,
 * one plane per encoder channel, found by name; file row y + r is memory
 * row height - 1 - (y + r). */
static exr_result_t write_stage_rows(write_job *job, int y, int nrows) {
  int width = job->width;
  for (int c = 0; c < job->enc.channel_count; ++c) {
    exr_coding_channel_info_t *ch = &job->enc.channels[c];
    float *dst = job->stage + (size_t)c * job->stage_plane;
    int k;
    for (k = 0; k < job->nchannels; ++k) {
      if (strcmp(job->names[k], ch->channel_name) == 0)
        break;
    }
    if (k == job->nchannels)
      return EXR_ERR_INCORRECT_CHUNK;
    for (int r = 0; r < nrows; ++r) {
      size_t j = (size_t)(job->height - 1 - (y + r));
      memcpy(dst + (size_t)r * (size_t)width, job->data[k] + j * (size_t)width,
             (size_t)width * sizeof(float));
    }
    ch->encode_from_ptr = (const uint8_t *)dst;
    ch->user_pixel_stride = (int32_t)sizeof(float);
    ch->user_line_stride = (int32_t)((size_t)width * sizeof(float));
    ch->user_bytes_per_element = (int16_t)sizeof(float);
    ch->user_data_type = EXR_PIXEL_FLOAT;
  }
  return EXR_ERR_SUCCESS;
}

/* The chunk at file row y (nrows rows): its description, the encoder set
 * up or updated, the rows staged and the chunk compressed and written. */
static exr_result_t write_chunk(write_job *job, int y, int nrows) {
  exr_chunk_info_t cinfo;
  memset(&cinfo, 0, sizeof cinfo);
  exr_result_t rv = exr_write_scanline_chunk_info(job->ctxt, job->part, y, &cinfo);
  if (rv == EXR_ERR_SUCCESS && (cinfo.height != nrows || cinfo.width != job->width))
    rv = EXR_ERR_INCORRECT_CHUNK;
  if (rv == EXR_ERR_SUCCESS) {
    if (!job->enc_live) {
      rv = exr_encoding_initialize(job->ctxt, job->part, &cinfo, &job->enc);
      if (rv == EXR_ERR_SUCCESS)
        job->enc_live = 1;
    } else {
      rv = exr_encoding_update(job->ctxt, job->part, &cinfo, &job->enc);
    }
  }
  if (rv == EXR_ERR_SUCCESS && job->enc.channel_count != job->nchannels)
    rv = EXR_ERR_INCORRECT_CHUNK;
  if (rv == EXR_ERR_SUCCESS)
    rv = write_stage_rows(job, y, nrows);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_encoding_choose_default_routines(job->ctxt, job->part, &job->enc);
  if (rv == EXR_ERR_SUCCESS && job->enc.compress_fn != NULL &&
      job->enc.compress_fn != &compress_or_store) {
    job->hook.compress = job->enc.compress_fn;
    job->enc.encoding_user_data = &job->hook;
    job->enc.compress_fn = &compress_or_store;
  }
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_encoding_run(job->ctxt, job->part, &job->enc);
  return rv;
}

gr_status gr_exr_write_meta(const char *path, int width, int height, int nchannels,
                            const char *const *names, const float *const *data,
                            gr_exr_pixel_type type, const gr_exr_meta *meta, char *err,
                            size_t err_len) {
  gr_status st = GR_OK;
  exr_result_t rv = EXR_ERR_SUCCESS;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  int longnames = 0;
  gr_exr_msg msg;
  write_job job;

  memset(&job, 0, sizeof job);
  memset(&msg, 0, sizeof msg);
  job.hook.compress = NULL;

  st = write_check_args(path, width, height, nchannels, names, data, type, meta, &longnames, err,
                        err_len);
  if (st != GR_OK)
    return st;
  job.path = path;
  job.width = width, job.height = height, job.nchannels = nchannels;
  job.names = names, job.data = data;

  init.error_handler_fn = &gr_exr_capture_error;
  init.user_data = &msg;

  /* A temporary file in the same folder, renamed over path once complete:
   * a failed write (a full disk) or a kill leaves an earlier file whole. */
  rv = exr_start_write(&job.ctxt, path, EXR_INTERMEDIATE_TEMP_FILE, &init);
  if (rv != EXR_ERR_SUCCESS) {
    st = rv == EXR_ERR_OUT_OF_MEMORY ? GR_ERR_OUT_OF_MEMORY : GR_ERR_IO;
    gr_exr_set_err(err, err_len, "Cannot write '%s': the file cannot be created (OpenEXR: %s).",
                   path, gr_exr_detail(&msg, rv));
    goto cleanup;
  }

  rv = write_header(&job, type == GR_EXR_HALF ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT, meta, longnames);
  if (rv != EXR_ERR_SUCCESS) {
    st = rv == EXR_ERR_OUT_OF_MEMORY ? GR_ERR_OUT_OF_MEMORY : GR_ERR_IO;
    gr_exr_set_err(err, err_len,
                   "Cannot write '%s': the header could not be written (OpenEXR: %s).", path,
                   gr_exr_detail(&msg, rv));
    goto cleanup;
  }

  /* Float staging for one chunk: nchannels planes of width by at most
   * lines rows. */
  job.stage_plane = (size_t)width * (size_t)(job.lines < height ? job.lines : height);
  if (job.stage_plane > SIZE_MAX / sizeof(float) / (size_t)nchannels) {
    st = GR_ERR_OUT_OF_MEMORY;
    gr_exr_set_err(err, err_len, "Cannot write '%s': out of memory.", path);
    goto cleanup;
  }
  job.stage = (float *)malloc(job.stage_plane * (size_t)nchannels * sizeof(float));
  if (job.stage == NULL) {
    st = GR_ERR_OUT_OF_MEMORY;
    gr_exr_set_err(err, err_len, "Cannot write '%s': out of memory.", path);
    goto cleanup;
  }

  for (int y = 0; y < height; y += job.lines) {
    int nrows = height - y < job.lines ? height - y : job.lines;
    rv = write_chunk(&job, y, nrows);
    if (rv != EXR_ERR_SUCCESS) {
      st = rv == EXR_ERR_OUT_OF_MEMORY ? GR_ERR_OUT_OF_MEMORY : GR_ERR_IO;
      gr_exr_set_err(err, err_len,
                     "Cannot write '%s': scanlines %d to %d could not be written "
                     "(OpenEXR: %s).",
                     path, y, y + nrows - 1, gr_exr_detail(&msg, rv));
      goto cleanup;
    }
  }

  if (job.enc_live) {
    exr_encoding_destroy(job.ctxt, &job.enc);
    job.enc_live = 0;
  }
  /* exr_finish writes the chunk offset table. */
  rv = exr_finish(&job.ctxt);
  if (rv != EXR_ERR_SUCCESS) {
    st = GR_ERR_IO;
    gr_exr_set_err(err, err_len,
                   "Cannot write '%s': the file could not be completed (OpenEXR: %s).", path,
                   gr_exr_detail(&msg, rv));
    goto cleanup;
  }

cleanup:
  if (job.enc_live)
    exr_encoding_destroy(job.ctxt, &job.enc);
  if (job.ctxt != NULL)
    exr_finish(&job.ctxt);
  free(job.stage);
  return st;
}
