/**
 * @file exr_io.h
 * @brief Height fields and named fields in OpenEXR files (OpenEXR's C API).
 *
 * Reads single- or multi-channel scanline or tiled EXR images whose channels
 * are HALF or FLOAT, and writes any set of named float fields as one
 * multi-channel FLOAT EXR. A hostile or broken file gives GR_ERR_FORMAT or
 * GR_ERR_IO with a sentence, never a crash. Before anything is allocated,
 * every chunk's size is checked against the file and against what its
 * compressed bytes can hold (at most 2048 times as much; 2^18 for DWA), so a
 * small file cannot make the reader allocate gigabytes.
 *
 * Orientation: EXR stores rows top (y min of the data window) to bottom; a
 * height map's first row is its northern edge. gr_exr_image fields are
 * row-major with row 0 the SOUTHERN edge (the gr_grid convention), so the
 * reader flips rows and the writer flips them back: a round trip through
 * other EXR tools keeps north up.
 */
#ifndef GRAUPEL_EXR_IO_H
#define GRAUPEL_EXR_IO_H

#include "graupel/graupel.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest width or height accepted by the reader (a hostile header guard). */
#define GR_EXR_MAX_DIM 65536
/** Largest number of samples (width*height*channels) the reader allocates. */
#define GR_EXR_MAX_SAMPLES ((size_t)1 << 31)
/** Longest channel name kept (longer names are an error). */
#define GR_EXR_MAX_NAME 255

typedef enum gr_exr_pixel_type { GR_EXR_HALF = 1, GR_EXR_FLOAT = 2 } gr_exr_pixel_type;

/*
 * Geometry and field data in the header (Graupel's own attributes, which
 * other EXR tools keep and ignore):
 *   graupel.spacing        v2d     point spacing in x and y, metres, finite and > 0
 *   graupel.origin         v3d     the south-west point, metres, finite
 *   graupel.field.NAME     double  a one-value numeric field-data array NAME
 *   graupel.field.NAME     graupelDoubles (opaque: int32 components, then the
 *                                  values as float64, little-endian) for more values
 *   graupel.field.NAME     string or stringvector: a string array NAME
 * Other attributes are ignored. Attribute names longer than 31 characters
 * make the writer set OpenEXR's long-name flag.
 */
/** Prefix of the attributes that hold field-data arrays. */
#define GR_EXR_FIELD_PREFIX "graupel.field."
/** Largest number of field-data arrays kept in or read from a header. */
#define GR_EXR_MAX_META_FIELDS 1024
/** Largest number of values (numbers or strings) in one field-data array. */
#define GR_EXR_MAX_META_VALUES 65536
/** Type name of the opaque attribute that holds several doubles. */
#define GR_EXR_DOUBLES_TYPE "graupelDoubles"

/** One field-data array kept in an EXR header: numbers or strings. */
typedef struct gr_exr_meta_field {
  char *name;      /**< the array's name (the attribute's name without the prefix) */
  int is_string;   /**< 1: strings; 0: numbers */
  int ncomponents; /**< numbers: values per tuple (>= 1, divides count); strings: 1 */
  int count;       /**< number of values, 1 to GR_EXR_MAX_META_VALUES */
  double *numbers; /**< count numbers (is_string 0), else NULL */
  char **strings;  /**< count strings (is_string 1), else NULL */
} gr_exr_meta_field;

/** Geometry and field data of an EXR header. */
typedef struct gr_exr_meta {
  int has_spacing;   /**< 1: spacing holds the file's graupel.spacing */
  double spacing[2]; /**< x, y in metres */
  int has_origin;    /**< 1: origin holds the file's graupel.origin */
  double origin[3];  /**< x, y, z of the south-west point in metres */
  int nfields;
  gr_exr_meta_field *fields;
} gr_exr_meta;

/** An image read from an EXR file: nchannels planes of width*height floats. */
typedef struct gr_exr_image {
  int width, height;
  int nchannels;
  char **names;             /**< channel names, as in the file (sorted by EXR) */
  gr_exr_pixel_type *types; /**< the stored type of each channel */
  float **data;             /**< data[c][j*width + i], row 0 = south */
  gr_exr_meta meta;         /**< the header's graupel.* attributes (all zero without them) */
} gr_exr_image;

/**
 * Reads every HALF or FLOAT channel of an EXR file. UINT channels are an error.
 * Channels with x/y sampling other than 1 are an error. The graupel.*
 * attributes fill out->meta; one of the wrong type or with a bad value (a
 * spacing not finite and above 0, an origin not finite, an empty field name,
 * a value count or size out of range) fails the read with GR_ERR_FORMAT. On
 * failure *out is untouched and err (if given) holds a sentence naming the
 * file and the fault.
 */
GR_API gr_status gr_exr_read(const char *path, gr_exr_image *out, char *err, size_t err_len);

/**
 * As gr_exr_read, from an in-memory copy of a file; label names it in errors.
 * NULL or "" labels are "<memory>". NULL data or size 0 give GR_ERR_FORMAT
 * (no bytes are no EXR file); data is only read, and not kept.
 */
GR_API gr_status gr_exr_read_memory(const void *data, size_t size, const char *label,
                                    gr_exr_image *out, char *err, size_t err_len);

/** Frees what gr_exr_read or gr_exr_read_memory allocated; zeroes the struct. NULL is fine. */
GR_API void gr_exr_image_free(gr_exr_image *img);

/** Index of a channel by name, or -1. */
GR_API int gr_exr_find_channel(const gr_exr_image *img, const char *name);

/**
 * Writes nchannels fields of width*height floats (row 0 = south) as one
 * scanline EXR with ZIP compression. type selects HALF or FLOAT storage for
 * every channel. Names must be distinct and non-empty.
 */
GR_API gr_status gr_exr_write(const char *path, int width, int height, int nchannels,
                              const char *const *names, const float *const *data,
                              gr_exr_pixel_type type, char *err, size_t err_len);

/**
 * As gr_exr_write, and keeps meta (NULL: none) in the header as the
 * graupel.* attributes described above. has_spacing and has_origin choose
 * whether spacing and origin are written. A spacing not finite and above 0,
 * an origin not finite, a field without a name, with a name longer than
 * GR_EXR_MAX_NAME - 14 characters or given twice, or with a value count out
 * of range gives GR_ERR_INVALID_ARGUMENT and writes nothing.
 */
GR_API gr_status gr_exr_write_meta(const char *path, int width, int height, int nchannels,
                                   const char *const *names, const float *const *data,
                                   gr_exr_pixel_type type, const gr_exr_meta *meta, char *err,
                                   size_t err_len);

/** Frees what a reader put in meta (names, numbers, strings); zeroes it. NULL is fine. */
GR_API void gr_exr_meta_free(gr_exr_meta *meta);

#ifdef __cplusplus
}
#endif

#endif
