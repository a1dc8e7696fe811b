/* The checkpoint manifest (graupel/checkpoint.h): read from JSON text with
 * the bounded reader of checkpoint_json.c, checked, and written back. Every
 * refusal is one sentence whose subject is the caller's label; the checks
 * come in a fixed order (format, version, then the keys as the header
 * lists them, then what ties them together), whatever the order of keys in
 * the text. */
#include "graupel/checkpoint.h"
#include "graupel/cl_runtime.h"
#include "checkpoint_json.h"

#include <limits.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GR_CP_LABEL "The checkpoint manifest"
#define GR_CP_GIVE "; give the .json a CheckpointFile wrote."

/* Who speaks a sentence: its subject, the advice that ends it and where it goes. */
typedef struct gr_cp_voice {
  const char *label; /* NULL: GR_CP_LABEL */
  const char *fix;   /* "; give the .json ..." */
  char *msg;
  size_t msg_len;
} gr_cp_voice;

/* Writes "<label> <fmt...><fix>" to msg and as the thread's latest error
 * (no fix where fmt ends in its own full stop); returns st. */
static gr_status gr_cp_say(gr_status st, const gr_cp_voice *v, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static gr_status gr_cp_say(gr_status st, const gr_cp_voice *v, const char *fmt, ...) {
  char text[1536];
  int n = snprintf(text, sizeof(text), "%s ", v->label ? v->label : GR_CP_LABEL);
  if (n < 0 || (size_t)n >= sizeof(text))
    n = 0;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(text + n, sizeof(text) - (size_t)n, fmt, ap);
  va_end(ap);
  size_t len = strlen(text);
  if (len > 0 && text[len - 1] != '.')
    snprintf(text + len, sizeof(text) - len, "%s", v->fix ? v->fix : GR_CP_GIVE);
  if (v->msg && v->msg_len)
    snprintf(v->msg, v->msg_len, "%s", text);
  return gr_set_error(NULL, st, "%s", text);
}

/* A string for a sentence: at most 64 bytes of it, other than printable
 * ASCII shown as '?'. */
static const char *gr_cp_show(const char *s, char out[72]) {
  size_t k = 0;
  for (; s[k] && k < 64; ++k)
    out[k] = (s[k] >= 0x20 && s[k] < 0x7f) ? s[k] : '?';
  if (s[k]) {
    memcpy(out + k, "...", 3);
    k += 3;
  }
  out[k] = '\0';
  return out;
}

/* ------------------------------------------------------------ validation */

/* The sentence for a whole-number value v of what that is not within lo .. hi. */
static gr_status gr_cp_whole_fault(const gr_cp_voice *v, const char *what, double x, long long lo,
                                   long long hi) {
  return gr_cp_say(GR_ERR_FORMAT, v,
                   "gives %s as %.17g, but it must be a whole number from %lld to %lld", what, x,
                   lo, hi);
}

static int gr_cp_whole_ok(double v, long long lo, long long hi) {
  return v == floor(v) && v >= (double)lo && v <= (double)hi;
}

/* A string the struct holds: '\0'-ended within its array, no control character. */
static int gr_cp_text_ok(const char *s, int empty_ok) {
  size_t n = 0;
  for (; n <= GR_CHECKPOINT_MAX_STRING && s[n]; ++n)
    if ((unsigned char)s[n] < 0x20 || s[n] == 0x7f)
      return 0;
  return n <= GR_CHECKPOINT_MAX_STRING && (empty_ok || n > 0);
}

/* A piece's file: one name beside the manifest, never a path out of its folder. */
static int gr_cp_file_ok(const char *f) {
  return gr_cp_text_ok(f, 0) && !strchr(f, '/') && !strchr(f, '\\') && strcmp(f, ".") != 0 &&
         strcmp(f, "..") != 0;
}

static gr_status gr_cp_check_piece(const gr_checkpoint *c, int r, const gr_cp_voice *v) {
  const gr_checkpoint_piece *p = &c->pieces[r];
  char what[64], show[72];
  if (p->rank != r)
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "lists the piece of rank %d in place %d, but the piece in place r must be "
                     "rank r's",
                     p->rank, r);
  if (!(p->rows[0] >= 0 && p->rows[0] <= p->rows[1] && p->rows[1] < c->grid[1]))
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "gives rank %d the rows %d to %d, but its grid has the rows 0 to %d and a "
                     "piece's first row may not come after its last",
                     r, p->rows[0], p->rows[1], c->grid[1] - 1);
  if (!gr_cp_file_ok(p->file))
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "names the piece of rank %d '%s', which is no file beside the manifest (a "
                     "name of 1 to %d bytes without '/', '\\', control characters, and not '.' "
                     "or '..')",
                     r, gr_cp_text_ok(p->file, 1) ? gr_cp_show(p->file, show) : "?",
                     GR_CHECKPOINT_MAX_STRING);
  snprintf(what, sizeof(what), "the bytes of rank %d's state", r);
  if (p->bytes < 0 || p->bytes > GR_CHECKPOINT_MAX_BYTES)
    return gr_cp_whole_fault(v, what, (double)p->bytes, 0, GR_CHECKPOINT_MAX_BYTES);
  return GR_OK;
}

/* gr_checkpoint_validate, in v's voice. */
static gr_status gr_cp_validate(const gr_checkpoint *c, const gr_cp_voice *v) {
  if (!c)
    return gr_cp_say(GR_ERR_INVALID_ARGUMENT, v,
                     "is missing: gr_checkpoint_validate was given no checkpoint.");
  if (c->version != GR_CHECKPOINT_VERSION)
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "is of version %d of the checkpoint format, and this Graupel reads version "
                     "%d only; write the checkpoint again with this Graupel.",
                     c->version, GR_CHECKPOINT_VERSION);
  if (!gr_cp_text_ok(c->simulation, 1) || !gr_cp_text_ok(c->class_name, 1))
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "gives a 'simulation' or 'class' of more than %d bytes or with a control "
                     "character",
                     GR_CHECKPOINT_MAX_STRING);
  if (c->output_index < 0)
    return gr_cp_whole_fault(v, "'output_index'", c->output_index, 0, INT_MAX);
  if (!(isfinite(c->time) && c->time >= 0.0))
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "gives 'time' as %.17g, but it must be a finite number of seconds, 0 or "
                     "more",
                     c->time);
  if (!(isfinite(c->output_interval) && c->output_interval > 0.0))
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "gives 'output_interval' as %.17g, but it must be a finite number of "
                     "seconds above 0",
                     c->output_interval);
  if (c->has_steps && !(isfinite(c->steps) && c->steps >= 0.0))
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "gives 'steps' as %.17g, but it must be a finite number, 0 or more", c->steps);
  for (int a = 0; a < 2; ++a)
    if (c->grid[a] < 1)
      return gr_cp_whole_fault(v, a ? "the grid's points in y" : "the grid's points in x",
                               c->grid[a], 1, INT_MAX);
  if (c->split != 0 && c->split != 1)
    return gr_cp_say(GR_ERR_FORMAT, v, "gives 'split' as %d, but it must be true or false",
                     c->split);
  if (c->ranks < 1 || c->ranks > GR_CHECKPOINT_MAX_RANKS)
    return gr_cp_whole_fault(v, "'ranks'", c->ranks, 1, GR_CHECKPOINT_MAX_RANKS);
  if (!c->split && c->ranks != 1)
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "says it was written whole on one rank ('split' is false) but gives "
                     "'ranks' as %d",
                     c->ranks);
  if (!c->pieces)
    return gr_cp_say(GR_ERR_FORMAT, v, "lists no pieces");
  for (int r = 0; r < c->ranks; ++r) {
    gr_status st = gr_cp_check_piece(c, r, v);
    if (st != GR_OK)
      return st;
  }
  return GR_OK;
}

gr_status gr_checkpoint_validate(const gr_checkpoint *c, const char *label, char *msg,
                                 size_t msg_len) {
  const gr_cp_voice v = {label, GR_CP_GIVE, msg, msg_len};
  return gr_cp_validate(c, &v);
}

gr_status gr_checkpoint_init(gr_checkpoint *c, int ranks, char *msg, size_t msg_len) {
  const gr_cp_voice voice = {"gr_checkpoint_init", "", msg, msg_len}, *v = &voice;
  if (!c)
    return gr_cp_say(GR_ERR_INVALID_ARGUMENT, v, "needs a checkpoint to set up.");
  memset(c, 0, sizeof(*c));
  if (ranks < 1 || ranks > GR_CHECKPOINT_MAX_RANKS)
    return gr_cp_say(GR_ERR_INVALID_ARGUMENT, v,
                     "was asked for %d ranks, but a checkpoint has 1 to %d.", ranks,
                     GR_CHECKPOINT_MAX_RANKS);
  c->pieces = calloc((size_t)ranks, sizeof(*c->pieces));
  if (!c->pieces)
    return gr_cp_say(GR_ERR_OUT_OF_MEMORY, v, "ran out of host memory.");
  c->version = GR_CHECKPOINT_VERSION;
  c->ranks = ranks;
  c->split = ranks > 1;
  for (int r = 0; r < ranks; ++r)
    c->pieces[r].rank = r;
  return GR_OK;
}

void gr_checkpoint_free(gr_checkpoint *c) {
  if (!c)
    return;
  free(c->pieces);
  memset(c, 0, sizeof(*c));
}

/* ---------------------------------------------------------------- reading */

typedef struct gr_cp_reader {
  const char *text;
  const gr_json *doc;
  gr_cp_voice voice;
} gr_cp_reader;

/* The value of key in object: its node in *out, or a sentence when it is
 * missing (unless optional: *out is 0), given twice or not of type (TRUE
 * stands for true or false). what names it in the sentence. */
static gr_status gr_cp_get(const gr_cp_reader *r, size_t object, const char *key, const char *what,
                           gr_json_type type, int optional, size_t *out) {
  static const char *const want[] = {"an object", "an array", "a string", "a number",
                                     "true or false"};
  int found = 0;
  size_t v = gr_json_member(r->text, r->doc, object, key, &found);
  *out = 0;
  if (found == 0)
    return optional ? GR_OK : gr_cp_say(GR_ERR_FORMAT, &r->voice, "has no %s", what);
  if (found > 1)
    return gr_cp_say(GR_ERR_FORMAT, &r->voice, "gives %s twice", what);
  gr_json_type t = (gr_json_type)r->doc->nodes[v].type;
  if (t != type && !(type == GR_JSON_TRUE && t == GR_JSON_FALSE))
    return gr_cp_say(GR_ERR_FORMAT, &r->voice, "gives %s as %s, where %s belongs", what,
                     gr_json_kind(&r->doc->nodes[v]), want[type]);
  *out = v;
  return GR_OK;
}

/* A number node that must be a whole number from lo to hi. */
static gr_status gr_cp_whole(const gr_cp_reader *r, size_t node, const char *what, long long lo,
                             long long hi, long long *out) {
  double v = gr_json_number(r->text, &r->doc->nodes[node]);
  if (!gr_cp_whole_ok(v, lo, hi))
    return gr_cp_whole_fault(&r->voice, what, v, lo, hi);
  *out = (long long)v;
  return GR_OK;
}

/* A key whose value is a whole number from lo to hi. */
static gr_status gr_cp_get_whole(const gr_cp_reader *r, size_t object, const char *key,
                                 const char *what, long long lo, long long hi, long long *out) {
  size_t v;
  gr_status st = gr_cp_get(r, object, key, what, GR_JSON_NUMBER, 0, &v);
  return st != GR_OK ? st : gr_cp_whole(r, v, what, lo, hi, out);
}

/* A key whose value is a string of at most GR_CHECKPOINT_MAX_STRING bytes. */
static gr_status gr_cp_get_text(const gr_cp_reader *r, size_t object, const char *key,
                                const char *what, char *out) {
  size_t v;
  int control;
  gr_status st = gr_cp_get(r, object, key, what, GR_JSON_STRING, 0, &v);
  if (st != GR_OK)
    return st;
  if (gr_json_string(r->text, &r->doc->nodes[v], out, GR_CHECKPOINT_MAX_STRING + 1, &control) < 0 ||
      control)
    return gr_cp_say(GR_ERR_FORMAT, &r->voice,
                     "gives %s as a string of more than %d bytes or with a control "
                     "character",
                     what, GR_CHECKPOINT_MAX_STRING);
  return GR_OK;
}

/* A key whose value is an array of two whole numbers from lo to hi. */
static gr_status gr_cp_get_pair(const gr_cp_reader *r, size_t object, const char *key,
                                const char *what, long long lo, long long hi, int out[2]) {
  size_t v;
  gr_status st = gr_cp_get(r, object, key, what, GR_JSON_ARRAY, 0, &v);
  if (st != GR_OK)
    return st;
  const gr_json_node *a = &r->doc->nodes[v];
  size_t e[2] = {v + 1, 0};
  e[1] = a->count == 2 ? r->doc->nodes[e[0]].next : 0;
  if (a->count != 2 || r->doc->nodes[e[0]].type != GR_JSON_NUMBER ||
      r->doc->nodes[e[1]].type != GR_JSON_NUMBER)
    return gr_cp_say(GR_ERR_FORMAT, &r->voice,
                     "gives %s as an array of %u values, where two whole numbers belong", what,
                     (unsigned)a->count);
  for (int k = 0; k < 2; ++k) {
    long long x = 0;
    st = gr_cp_whole(r, e[k], what, lo, hi, &x);
    if (st != GR_OK)
      return st;
    out[k] = (int)x;
  }
  return GR_OK;
}

static gr_status gr_cp_read_piece(const gr_cp_reader *r, size_t node, int k,
                                  gr_checkpoint_piece *p) {
  char what[4][64];
  long long x = 0;
  snprintf(what[0], sizeof(what[0]), "piece %d's 'rank'", k);
  snprintf(what[1], sizeof(what[1]), "piece %d's 'rows'", k);
  snprintf(what[2], sizeof(what[2]), "piece %d's 'file'", k);
  snprintf(what[3], sizeof(what[3]), "piece %d's 'bytes'", k);
  if (r->doc->nodes[node].type != GR_JSON_OBJECT)
    return gr_cp_say(GR_ERR_FORMAT, &r->voice, "gives piece %d as %s, where an object belongs", k,
                     gr_json_kind(&r->doc->nodes[node]));
  gr_status st = gr_cp_get_whole(r, node, "rank", what[0], 0, GR_CHECKPOINT_MAX_RANKS - 1, &x);
  p->rank = (int)x;
  if (st == GR_OK)
    st = gr_cp_get_pair(r, node, "rows", what[1], 0, INT_MAX, p->rows);
  if (st == GR_OK)
    st = gr_cp_get_text(r, node, "file", what[2], p->file);
  if (st == GR_OK)
    st = gr_cp_get_whole(r, node, "bytes", what[3], 0, GR_CHECKPOINT_MAX_BYTES, &p->bytes);
  return st;
}

/* The format and the version, before anything else is judged. */
static gr_status gr_cp_read_head(const gr_cp_reader *r, gr_checkpoint *c) {
  char format[64], show[72], is[96];
  int found, control = 0;
  size_t v = gr_json_member(r->text, r->doc, 0, "format", &found);
  const gr_json_node *n = found ? &r->doc->nodes[v] : NULL;
  long got = n && n->type == GR_JSON_STRING
                 ? gr_json_string(r->text, n, format, sizeof(format), &control)
                 : -1;
  if (found != 1 || got < 0 || control || strcmp(format, GR_CHECKPOINT_FORMAT) != 0) {
    if (!n)
      snprintf(is, sizeof(is), "it has no 'format'");
    else if (found > 1)
      snprintf(is, sizeof(is), "it gives 'format' twice");
    else if (got < 0 || control)
      snprintf(is, sizeof(is), "its 'format' is %s", gr_json_kind(n));
    else
      snprintf(is, sizeof(is), "its 'format' is \"%s\"", gr_cp_show(format, show));
    return gr_cp_say(GR_ERR_FORMAT, &r->voice,
                     "is not a Graupel checkpoint manifest (%s, not \"" GR_CHECKPOINT_FORMAT "\")",
                     is);
  }
  gr_status st = gr_cp_get(r, 0, "version", "'version'", GR_JSON_NUMBER, 0, &v);
  if (st != GR_OK)
    return st;
  double x = gr_json_number(r->text, &r->doc->nodes[v]);
  if (x != GR_CHECKPOINT_VERSION)
    return gr_cp_say(GR_ERR_FORMAT, &r->voice,
                     "is of version %.17g of the checkpoint format, and this Graupel reads "
                     "version %d only; write the checkpoint again with this Graupel.",
                     x, GR_CHECKPOINT_VERSION);
  c->version = GR_CHECKPOINT_VERSION;
  return GR_OK;
}

/* Every key of the top-level object into c (pieces allocated). */
static gr_status gr_cp_read(const gr_cp_reader *r, gr_checkpoint *c) {
  long long x = 0;
  size_t v;
  gr_status st = gr_cp_read_head(r, c);
  if (st == GR_OK)
    st = gr_cp_get_text(r, 0, "simulation", "'simulation'", c->simulation);
  if (st == GR_OK)
    st = gr_cp_get_text(r, 0, "class", "'class'", c->class_name);
  if (st == GR_OK)
    st = gr_cp_get_whole(r, 0, "output_index", "'output_index'", 0, INT_MAX, &x);
  c->output_index = (int)x;
  const char *doubles[] = {"time", "output_interval", "steps"};
  double *into[] = {&c->time, &c->output_interval, &c->steps};
  for (int k = 0; st == GR_OK && k < 3; ++k) {
    char what[32];
    snprintf(what, sizeof(what), "'%s'", doubles[k]);
    st = gr_cp_get(r, 0, doubles[k], what, GR_JSON_NUMBER, k == 2, &v);
    if (st == GR_OK && v)
      *into[k] = gr_json_number(r->text, &r->doc->nodes[v]);
    if (k == 2)
      c->has_steps = v != 0;
  }
  if (st == GR_OK)
    st = gr_cp_get_pair(r, 0, "grid", "'grid'", 1, INT_MAX, c->grid);
  if (st == GR_OK)
    st = gr_cp_get(r, 0, "split", "'split'", GR_JSON_TRUE, 0, &v);
  c->split = st == GR_OK && r->doc->nodes[v].type == GR_JSON_TRUE;
  if (st == GR_OK)
    st = gr_cp_get_whole(r, 0, "ranks", "'ranks'", 1, GR_CHECKPOINT_MAX_RANKS, &x);
  c->ranks = (int)x;
  if (st == GR_OK)
    st = gr_cp_get(r, 0, "pieces", "'pieces'", GR_JSON_ARRAY, 0, &v);
  if (st != GR_OK)
    return st;
  const gr_json_node *list = &r->doc->nodes[v];
  if (list->count != (uint32_t)c->ranks)
    return gr_cp_say(GR_ERR_FORMAT, &r->voice,
                     "lists %u piece%s for %d rank%s, but a checkpoint lists one piece per "
                     "rank",
                     (unsigned)list->count, list->count == 1 ? "" : "s", c->ranks,
                     c->ranks == 1 ? "" : "s");
  c->pieces = calloc((size_t)c->ranks, sizeof(*c->pieces));
  if (!c->pieces)
    return gr_cp_say(GR_ERR_OUT_OF_MEMORY, &r->voice, "could not be read: out of host memory.");
  size_t e = v + 1;
  for (int k = 0; st == GR_OK && k < c->ranks; ++k, e = r->doc->nodes[e].next)
    st = gr_cp_read_piece(r, e, k, &c->pieces[k]);
  return st;
}

/* A JSON fault at byte where of text as "line L, column C". */
static void gr_cp_position(const char *text, size_t where, size_t *line, size_t *column) {
  *line = 1;
  *column = 1;
  for (size_t k = 0; k < where; ++k) {
    if (text[k] == '\n') {
      ++*line;
      *column = 1;
    } else {
      ++*column;
    }
  }
}

gr_status gr_checkpoint_parse(const char *text, size_t len, const char *label, gr_checkpoint *out,
                              char *msg, size_t msg_len) {
  const gr_cp_voice voice = {label, GR_CP_GIVE, msg, msg_len}, *v = &voice;
  if (!out || (!text && len > 0))
    return gr_cp_say(GR_ERR_INVALID_ARGUMENT, v,
                     "could not be read: gr_checkpoint_parse needs the text and a checkpoint to "
                     "fill.");
  if (len > GR_CHECKPOINT_MAX_TEXT)
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "is not a Graupel checkpoint manifest (it has more than %zu bytes, the most "
                     "a manifest has)",
                     GR_CHECKPOINT_MAX_TEXT);
  gr_json doc;
  size_t where = 0, line, column;
  char why[160];
  int r =
      gr_json_parse(text ? text : "", len, GR_CHECKPOINT_MAX_DEPTH, &doc, &where, why, sizeof(why));
  if (r != 0) {
    gr_json_free(&doc);
    if (r == -2)
      return gr_cp_say(GR_ERR_OUT_OF_MEMORY, v, "could not be read: out of host memory.");
    gr_cp_position(text, where, &line, &column);
    return gr_cp_say(GR_ERR_FORMAT, v,
                     "is not a Graupel checkpoint manifest (not JSON: at line %zu, column %zu: "
                     "%s)",
                     line, column, why);
  }
  gr_status st = GR_OK;
  gr_checkpoint c;
  memset(&c, 0, sizeof(c));
  if (doc.nodes[0].type != GR_JSON_OBJECT) {
    st = gr_cp_say(GR_ERR_FORMAT, v,
                   "is not a Graupel checkpoint manifest (its text is %s, not an object)",
                   gr_json_kind(&doc.nodes[0]));
  } else {
    gr_cp_reader rd = {text, &doc, voice};
    st = gr_cp_read(&rd, &c);
    if (st == GR_OK)
      st = gr_cp_validate(&c, &voice);
  }
  gr_json_free(&doc);
  if (st != GR_OK) {
    gr_checkpoint_free(&c);
    return st;
  }
  *out = c;
  return GR_OK;
}

/* ---------------------------------------------------------------- writing */

typedef struct gr_cp_buf {
  char *s;
  size_t len, cap;
  int oom;
} gr_cp_buf;

static void gr_cp_append(gr_cp_buf *b, const char *s, size_t n) {
  if (b->oom)
    return;
  if (b->len + n + 1 > b->cap) {
    size_t cap = b->cap ? b->cap : 1024;
    while (cap < b->len + n + 1)
      cap *= 2;
    char *t = realloc(b->s, cap);
    if (!t) {
      b->oom = 1;
      return;
    }
    b->s = t;
    b->cap = cap;
  }
  memcpy(b->s + b->len, s, n);
  b->len += n;
  b->s[b->len] = '\0';
}

static void gr_cp_printf(gr_cp_buf *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void gr_cp_printf(gr_cp_buf *b, const char *fmt, ...) {
  char text[128];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(text, sizeof(text), fmt, ap);
  va_end(ap);
  gr_cp_append(b, text, n > 0 ? (size_t)n : 0);
}

/* A JSON string: quotes, backslashes and control characters escaped. */
static void gr_cp_quote(gr_cp_buf *b, const char *s) {
  gr_cp_append(b, "\"", 1);
  for (; *s; ++s) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\')
      gr_cp_printf(b, "\\%c", c);
    else if (c < 0x20 || c == 0x7f)
      gr_cp_printf(b, "\\u%04x", c);
    else
      gr_cp_append(b, s, 1);
  }
  gr_cp_append(b, "\"", 1);
}

/* Reads back what gr_cp_double printed in the C library's locale. */
static int gr_cp_same(const char *text, double v) {
  double back = strtod(text, NULL);
  return back == v && signbit(back) == signbit(v);
}

/* A finite double with the fewest significant digits that read back to
 * its bits, without an exponent from 1e-5 to 1e17, '.' as the decimal
 * point whatever the locale, and ".0" when it would look whole. */
static void gr_cp_double(gr_cp_buf *b, double v) {
  char text[400], out[400];
  int digits = 1;
  while (digits < 17) {
    snprintf(text, sizeof(text), "%.*g", digits, v);
    if (gr_cp_same(text, v))
      break;
    ++digits;
  }
  snprintf(text, sizeof(text), "%.*e", digits - 1, v);
  const char *e = strchr(text, 'e');
  int exponent = e ? atoi(e + 1) : 0;
  if (exponent >= -5 && exponent < 17)
    snprintf(text, sizeof(text), "%.*f", digits - 1 - exponent > 0 ? digits - 1 - exponent : 0, v);
  else
    snprintf(text, sizeof(text), "%.*g", digits, v);
  if (!gr_cp_same(text, v))
    snprintf(text, sizeof(text), "%.17g", v);
  const char *point = localeconv()->decimal_point;
  size_t plen = point && point[0] ? strlen(point) : 0, k = 0;
  int plain = 1;
  for (const char *s = text; *s && k + 3 < sizeof(out);) {
    if (plen > 0 && strncmp(s, point, plen) == 0) {
      out[k++] = '.';
      s += plen;
      plain = 0;
      continue;
    }
    if (*s == 'e' || *s == 'E')
      plain = 0;
    out[k++] = *s++;
  }
  if (plain) {
    out[k++] = '.';
    out[k++] = '0';
  }
  gr_cp_append(b, out, k);
}

gr_status gr_checkpoint_format(const gr_checkpoint *c, char **text, size_t *len, char *msg,
                               size_t msg_len) {
  const gr_cp_voice voice = {"The checkpoint to write", "; no manifest was written.", msg, msg_len},
                    *v = &voice;
  if (!text || !len)
    return gr_cp_say(GR_ERR_INVALID_ARGUMENT, v,
                     "has nowhere to go: gr_checkpoint_format needs a place for the text and its "
                     "length.");
  *text = NULL;
  *len = 0;
  gr_status st = gr_cp_validate(c, v);
  if (st != GR_OK)
    return st;
  gr_cp_buf b = {NULL, 0, 0, 0};
  gr_cp_printf(&b, "{\n  \"format\": \"%s\",\n  \"version\": %d,\n  \"simulation\": ",
               GR_CHECKPOINT_FORMAT, c->version);
  gr_cp_quote(&b, c->simulation);
  gr_cp_append(&b, ",\n  \"class\": ", 13);
  gr_cp_quote(&b, c->class_name);
  gr_cp_printf(&b, ",\n  \"output_index\": %d,\n  \"time\": ", c->output_index);
  gr_cp_double(&b, c->time);
  gr_cp_append(&b, ",\n  \"output_interval\": ", 23);
  gr_cp_double(&b, c->output_interval);
  if (c->has_steps) {
    gr_cp_append(&b, ",\n  \"steps\": ", 13);
    gr_cp_double(&b, c->steps);
  }
  gr_cp_printf(&b, ",\n  \"grid\": [%d, %d],\n  \"split\": %s,\n  \"ranks\": %d,\n  \"pieces\": [",
               c->grid[0], c->grid[1], c->split ? "true" : "false", c->ranks);
  for (int r = 0; r < c->ranks; ++r) {
    const gr_checkpoint_piece *p = &c->pieces[r];
    gr_cp_printf(&b, "%s\n    {\"rank\": %d, \"rows\": [%d, %d], \"file\": ", r ? "," : "", p->rank,
                 p->rows[0], p->rows[1]);
    gr_cp_quote(&b, p->file);
    gr_cp_printf(&b, ", \"bytes\": %lld}", p->bytes);
  }
  gr_cp_append(&b, "\n  ]\n}\n", 7);
  if (b.oom) {
    free(b.s);
    return gr_cp_say(GR_ERR_OUT_OF_MEMORY, v, "could not be written: out of host memory.");
  }
  *text = b.s;
  *len = b.len;
  return GR_OK;
}

void gr_checkpoint_text_free(char *text) {
  free(text);
}
