/* Private to exr_io.c (reading), exr_io_meta.c (the graupel.* header
 * attributes) and exr_io_write.c (writing): the error text they share and
 * the header attributes' read, check and write. */
#ifndef GRAUPEL_EXR_IO_INTERNAL_H
#define GRAUPEL_EXR_IO_INTERNAL_H

#include "graupel/exr_io.h"

#include <openexr.h>

#include <stddef.h>

/* The first message OpenEXR reported for a context (later ones are usually
 * consequences of the first). */
typedef struct gr_exr_msg {
  char text[512];
  int have;
} gr_exr_msg;

/* OpenEXR's error handler: keeps the first message in the context's user
 * data (a gr_exr_msg), without its trailing dots. */
void gr_exr_capture_error(exr_const_context_t ctxt, exr_result_t code, const char *msg);

/* A formatted sentence into err (when err and err_len). */
void gr_exr_set_err(char *err, size_t err_len, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* The library's own words for a failure: the captured message, or the
 * generic text of the code. */
const char *gr_exr_detail(const gr_exr_msg *m, exr_result_t rv);

/* Every graupel.* attribute of part 0 into meta (zeroed by the caller; the
 * caller frees it on failure). Other attributes are ignored. */
gr_status gr_exr_meta_read(exr_const_context_t ctxt, const char *label, gr_exr_meta *meta,
                           char *err, size_t err_len);

/* Checks meta for the writer and finds whether any attribute name needs
 * OpenEXR's long names. */
gr_status gr_exr_meta_check(const char *path, const gr_exr_meta *meta, int *longnames, char *err,
                            size_t err_len);

/* The graupel.* attributes of a checked meta, into part 0 before its header
 * is written. */
exr_result_t gr_exr_meta_write(exr_context_t ctxt, int part, const gr_exr_meta *meta);

#endif
