/* The bounded JSON reader under the checkpoint manifest (checkpoint_json.h):
 * RFC 8259 with NaN, Infinity and -Infinity as numbers, strings checked to
 * be UTF-8 with valid escapes, numbers of at most GR_JSON_MAX_NUMBER
 * characters. The recursion is as deep as the nesting, which the caller
 * bounds; nodes grow by doubling up to GR_JSON_MAX_NODES. */
#include "checkpoint_json.h"

#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct gr_json_parser {
  const unsigned char *s;
  size_t len, pos;
  int max_depth;
  gr_json *doc;
  size_t cap;
  size_t where;
  char *why;
  size_t why_len;
  int oom;
} gr_json_parser;

static int gr_json_fault(gr_json_parser *p, size_t at, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static int gr_json_fault(gr_json_parser *p, size_t at, const char *fmt, ...) {
  p->where = at;
  if (p->why && p->why_len) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->why, p->why_len, fmt, ap);
    va_end(ap);
  }
  return -1;
}

/* A byte for a sentence: 'x' when printable, else its code. */
static const char *gr_json_byte(unsigned char c, char out[16]) {
  if (c >= 0x20 && c < 0x7f)
    snprintf(out, 16, "'%c'", c);
  else
    snprintf(out, 16, "byte 0x%02x", c);
  return out;
}

/* The byte at the parser's position for a sentence, or "the end". */
static const char *gr_json_here(const gr_json_parser *p, char out[16]) {
  if (p->pos >= p->len)
    return "the end of the text";
  return gr_json_byte(p->s[p->pos], out);
}

static void gr_json_skip_ws(gr_json_parser *p) {
  while (p->pos < p->len) {
    unsigned char c = p->s[p->pos];
    if (c != ' ' && c != '\t' && c != '\n' && c != '\r')
      return;
    ++p->pos;
  }
}

/* A new node of type at the text's byte at: its index, or -1. */
static long gr_json_add(gr_json_parser *p, gr_json_type type, size_t at) {
  gr_json *d = p->doc;
  if (d->count >= GR_JSON_MAX_NODES)
    return gr_json_fault(p, at, "more than %zu values", (size_t)GR_JSON_MAX_NODES);
  if (d->count == p->cap) {
    size_t cap = p->cap ? 2 * p->cap : 64;
    gr_json_node *n = realloc(d->nodes, cap * sizeof(*n));
    if (!n) {
      p->oom = 1;
      return -1;
    }
    d->nodes = n;
    p->cap = cap;
  }
  gr_json_node *n = &d->nodes[d->count];
  memset(n, 0, sizeof(*n));
  n->type = (unsigned char)type;
  n->at = (uint32_t)at;
  return (long)d->count++;
}

/* Closes node k: its length up to the position and its subtree's end. */
static void gr_json_close(gr_json_parser *p, long k, size_t at) {
  gr_json_node *n = &p->doc->nodes[k];
  n->len = (uint32_t)(p->pos - at);
  n->next = (uint32_t)p->doc->count;
}

/* The length of the UTF-8 sequence at u (n bytes left), 0 when it is not
 * one (overlong, a surrogate, beyond U+10FFFF, cut short). */
static int gr_json_utf8(const unsigned char *u, size_t n) {
  unsigned c = u[0], cp, min;
  int len;
  if (c < 0x80)
    return 1;
  if (c >= 0xc2 && c <= 0xdf)
    len = 2, cp = c & 0x1f, min = 0x80;
  else if (c >= 0xe0 && c <= 0xef)
    len = 3, cp = c & 0x0f, min = 0x800;
  else if (c >= 0xf0 && c <= 0xf4)
    len = 4, cp = c & 0x07, min = 0x10000;
  else
    return 0;
  if (n < (size_t)len)
    return 0;
  for (int k = 1; k < len; ++k) {
    if ((u[k] & 0xc0) != 0x80)
      return 0;
    cp = cp << 6 | (u[k] & 0x3f);
  }
  if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
    return 0;
  return len;
}

/* Four hex digits at s (n bytes left) as a code unit, or -1. */
static long gr_json_hex4(const unsigned char *s, size_t n) {
  long v = 0;
  if (n < 4)
    return -1;
  for (int k = 0; k < 4; ++k) {
    unsigned char c = s[k];
    int d = c >= '0' && c <= '9'   ? c - '0'
            : c >= 'a' && c <= 'f' ? c - 'a' + 10
            : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                   : -1;
    if (d < 0)
      return -1;
    v = v * 16 + d;
  }
  return v;
}

/* The length of the escape at s (a backslash, n bytes left), 0 when it is not one. */
static size_t gr_json_escape(const unsigned char *s, size_t n) {
  if (n < 2)
    return 0;
  if (strchr("\"\\/bfnrt", s[1]) && s[1] != '\0')
    return 2;
  if (s[1] != 'u')
    return 0;
  long hi = gr_json_hex4(s + 2, n - 2);
  if (hi < 0 || (hi >= 0xdc00 && hi <= 0xdfff))
    return 0;
  if (hi < 0xd800 || hi > 0xdbff)
    return 6;
  /* A high surrogate needs its low one. */
  if (n < 12 || s[6] != '\\' || s[7] != 'u')
    return 0;
  long lo = gr_json_hex4(s + 8, n - 8);
  return lo >= 0xdc00 && lo <= 0xdfff ? 12 : 0;
}

static int gr_json_string_node(gr_json_parser *p) {
  const size_t open = p->pos++;
  char b[16];
  for (;;) {
    if (p->pos >= p->len)
      return gr_json_fault(p, open, "a string that never ends, cut short");
    unsigned char c = p->s[p->pos];
    if (c == '"')
      break;
    if (c < 0x20)
      return gr_json_fault(p, p->pos, "a control character (%s) inside a string",
                           gr_json_byte(c, b));
    size_t step = c == '\\'  ? gr_json_escape(p->s + p->pos, p->len - p->pos)
                  : c < 0x80 ? 1
                             : (size_t)gr_json_utf8(p->s + p->pos, p->len - p->pos);
    if (step == 0)
      return gr_json_fault(p, p->pos,
                           c == '\\' ? "an escape that JSON does not know inside a string"
                                     : "bytes that are not UTF-8 inside a string");
    p->pos += step;
  }
  long k = gr_json_add(p, GR_JSON_STRING, open + 1);
  if (k < 0)
    return -1;
  gr_json_close(p, k, open + 1);
  ++p->pos;
  return 0;
}

/* A literal word (true, false, null, NaN, Infinity, -Infinity) as a node. */
static int gr_json_literal(gr_json_parser *p, const char *word, gr_json_type type) {
  size_t n = strlen(word), left = p->len - p->pos;
  char b[16];
  if (left < n && memcmp(p->s + p->pos, word, left) == 0)
    return gr_json_fault(p, p->pos, "the text ends inside '%s', cut short", word);
  if (left < n || memcmp(p->s + p->pos, word, n) != 0)
    return gr_json_fault(p, p->pos, "%s where a value belongs", gr_json_here(p, b));
  long k = gr_json_add(p, type, p->pos);
  if (k < 0)
    return -1;
  const size_t at = p->pos;
  p->pos += n;
  gr_json_close(p, k, at);
  return 0;
}

static int gr_json_digits(gr_json_parser *p) {
  size_t start = p->pos;
  while (p->pos < p->len && p->s[p->pos] >= '0' && p->s[p->pos] <= '9')
    ++p->pos;
  return p->pos > start;
}

static int gr_json_number_node(gr_json_parser *p) {
  const size_t start = p->pos;
  if (p->s[p->pos] == '-') {
    ++p->pos;
    if (p->pos < p->len && p->s[p->pos] == 'I') {
      p->pos = start;
      return gr_json_literal(p, "-Infinity", GR_JSON_NUMBER);
    }
  }
  if (p->pos < p->len && p->s[p->pos] == '0')
    ++p->pos;
  else if (!gr_json_digits(p))
    return gr_json_fault(p, start, "a '-' without digits after it");
  if (p->pos < p->len && p->s[p->pos] == '.') {
    ++p->pos;
    if (!gr_json_digits(p))
      return gr_json_fault(p, start, "a number with no digits after its '.'");
  }
  if (p->pos < p->len && (p->s[p->pos] == 'e' || p->s[p->pos] == 'E')) {
    ++p->pos;
    if (p->pos < p->len && (p->s[p->pos] == '+' || p->s[p->pos] == '-'))
      ++p->pos;
    if (!gr_json_digits(p))
      return gr_json_fault(p, start, "a number with no digits in its exponent");
  }
  if (p->pos - start > GR_JSON_MAX_NUMBER)
    return gr_json_fault(p, start, "a number of more than %d characters", GR_JSON_MAX_NUMBER);
  long k = gr_json_add(p, GR_JSON_NUMBER, start);
  if (k < 0)
    return -1;
  gr_json_close(p, k, start);
  return 0;
}

static int gr_json_value(gr_json_parser *p, int depth);

/* An object or an array, its members' values depth + 1 deep. */
static int gr_json_container(gr_json_parser *p, int depth, int object) {
  const size_t open = p->pos;
  const unsigned char close = object ? '}' : ']';
  const char *inside = object ? "an object" : "an array";
  char b[16];
  if (depth >= p->max_depth)
    return gr_json_fault(p, open, "arrays and objects nested more than %d deep", p->max_depth);
  long k = gr_json_add(p, object ? GR_JSON_OBJECT : GR_JSON_ARRAY, open);
  if (k < 0)
    return -1;
  uint32_t count = 0;
  ++p->pos;
  gr_json_skip_ws(p);
  if (p->pos < p->len && p->s[p->pos] == close) {
    ++p->pos;
  } else {
    for (;;) {
      if (object) {
        gr_json_skip_ws(p);
        if (p->pos >= p->len)
          return gr_json_fault(p, p->pos, "the text ends inside %s, cut short", inside);
        if (p->s[p->pos] != '"')
          return gr_json_fault(p, p->pos, "%s where a key (a string) belongs", gr_json_here(p, b));
        if (gr_json_string_node(p) < 0)
          return -1;
        gr_json_skip_ws(p);
        if (p->pos >= p->len || p->s[p->pos] != ':')
          return gr_json_fault(p, p->pos, "%s where ':' belongs", gr_json_here(p, b));
        ++p->pos;
      }
      if (gr_json_value(p, depth + 1) < 0)
        return -1;
      ++count;
      gr_json_skip_ws(p);
      if (p->pos >= p->len)
        return gr_json_fault(p, p->pos, "the text ends inside %s, cut short", inside);
      if (p->s[p->pos] == close) {
        ++p->pos;
        break;
      }
      if (p->s[p->pos] != ',')
        return gr_json_fault(p, p->pos, "%s where ',' or '%c' belongs", gr_json_here(p, b), close);
      ++p->pos;
    }
  }
  p->doc->nodes[k].count = count;
  gr_json_close(p, k, open);
  return 0;
}

static int gr_json_value(gr_json_parser *p, int depth) {
  char b[16];
  gr_json_skip_ws(p);
  if (p->pos >= p->len)
    return gr_json_fault(p, p->pos, "the text ends where a value belongs, cut short");
  unsigned char c = p->s[p->pos];
  switch (c) {
  case '{':
  case '[':
    return gr_json_container(p, depth, c == '{');
  case '"':
    return gr_json_string_node(p);
  case 't':
    return gr_json_literal(p, "true", GR_JSON_TRUE);
  case 'f':
    return gr_json_literal(p, "false", GR_JSON_FALSE);
  case 'n':
    return gr_json_literal(p, "null", GR_JSON_NULL);
  case 'N':
    return gr_json_literal(p, "NaN", GR_JSON_NUMBER);
  case 'I':
    return gr_json_literal(p, "Infinity", GR_JSON_NUMBER);
  default:
    if (c == '-' || (c >= '0' && c <= '9'))
      return gr_json_number_node(p);
    return gr_json_fault(p, p->pos, "%s where a value belongs", gr_json_byte(c, b));
  }
}

int gr_json_parse(const char *text, size_t len, int max_depth, gr_json *doc, size_t *where,
                  char *why, size_t why_len) {
  gr_json_parser p;
  char b[16];
  memset(doc, 0, sizeof(*doc));
  memset(&p, 0, sizeof(p));
  p.s = (const unsigned char *)text;
  p.len = len;
  p.max_depth = max_depth;
  p.doc = doc;
  p.why = why;
  p.why_len = why_len;
  if (why && why_len)
    why[0] = '\0';
  int r =
      len > UINT32_MAX ? gr_json_fault(&p, 0, "a text of more than 4 GiB") : gr_json_value(&p, 0);
  if (r == 0) {
    gr_json_skip_ws(&p);
    if (p.pos < p.len)
      r = gr_json_fault(&p, p.pos, "%s after the end of the top-level value", gr_json_here(&p, b));
  }
  *where = p.where;
  return p.oom ? -2 : r;
}

void gr_json_free(gr_json *doc) {
  if (!doc)
    return;
  free(doc->nodes);
  memset(doc, 0, sizeof(*doc));
}

/* Appends byte c to out (cap bytes, k used); 0 when there is no room. */
static int gr_json_put(char *out, size_t cap, size_t *k, unsigned c, int *control) {
  if (*k + 1 >= cap)
    return 0;
  if (c < 0x20 || c == 0x7f)
    *control = 1;
  out[(*k)++] = (char)c;
  return 1;
}

long gr_json_string(const char *text, const gr_json_node *n, char *out, size_t cap, int *control) {
  const unsigned char *s = (const unsigned char *)text + n->at, *e = s + n->len;
  size_t k = 0;
  int ok = cap > 0;
  *control = 0;
  while (ok && s < e) {
    if (*s != '\\') {
      ok = gr_json_put(out, cap, &k, *s++, control);
      continue;
    }
    /* The parser checked every escape. */
    unsigned long cp;
    switch (s[1]) {
    case 'b':
      cp = '\b';
      break;
    case 'f':
      cp = '\f';
      break;
    case 'n':
      cp = '\n';
      break;
    case 'r':
      cp = '\r';
      break;
    case 't':
      cp = '\t';
      break;
    case 'u':
      cp = (unsigned long)gr_json_hex4(s + 2, 4);
      if (cp >= 0xd800 && cp <= 0xdbff) {
        cp = 0x10000 + ((cp - 0xd800) << 10) + ((unsigned long)gr_json_hex4(s + 8, 4) - 0xdc00);
        s += 6;
      }
      s += 4;
      break;
    default:
      cp = s[1];
      break;
    }
    s += 2;
    if (cp < 0x80) {
      ok = gr_json_put(out, cap, &k, (unsigned)cp, control);
    } else {
      unsigned char u[4];
      int m = cp < 0x800 ? 2 : cp < 0x10000 ? 3 : 4;
      for (int q = m - 1; q > 0; --q, cp >>= 6)
        u[q] = (unsigned char)(0x80 | (cp & 0x3f));
      u[0] = (unsigned char)((m == 2 ? 0xc0 : m == 3 ? 0xe0 : 0xf0) | cp);
      for (int q = 0; ok && q < m; ++q)
        ok = gr_json_put(out, cap, &k, u[q], control);
    }
  }
  if (!ok)
    return -1;
  out[k] = '\0';
  return (long)k;
}

double gr_json_number(const char *text, const gr_json_node *n) {
  const char *s = text + n->at;
  if (n->len == 3 && memcmp(s, "NaN", 3) == 0)
    return NAN;
  if (n->len == 8 && memcmp(s, "Infinity", 8) == 0)
    return INFINITY;
  if (n->len == 9 && memcmp(s, "-Infinity", 9) == 0)
    return -INFINITY;
  /* strtod reads the locale's decimal point: put it in place of '.'. */
  const char *point = localeconv()->decimal_point;
  size_t plen = point && point[0] ? strlen(point) : 0;
  char buf[GR_JSON_MAX_NUMBER + 16];
  size_t k = 0;
  for (uint32_t q = 0; q < n->len && k + 8 < sizeof(buf); ++q) {
    if (s[q] == '.' && plen > 0 && plen < 8) {
      memcpy(buf + k, point, plen);
      k += plen;
    } else {
      buf[k++] = s[q];
    }
  }
  buf[k] = '\0';
  return strtod(buf, NULL);
}

size_t gr_json_member(const char *text, const gr_json *doc, size_t object, const char *key,
                      int *found) {
  const gr_json_node *o = &doc->nodes[object];
  const size_t want = strlen(key);
  size_t k = object + 1, hit = 0;
  char name[64];
  *found = 0;
  for (uint32_t m = 0; m < o->count; ++m) {
    int control;
    long n = gr_json_string(text, &doc->nodes[k], name, sizeof(name), &control);
    if (n >= 0 && (size_t)n == want && memcmp(name, key, want) == 0) {
      if (++*found == 1)
        hit = k + 1;
    }
    k = doc->nodes[k + 1].next;
  }
  return hit;
}

const char *gr_json_kind(const gr_json_node *n) {
  switch ((gr_json_type)n->type) {
  case GR_JSON_OBJECT:
    return "an object";
  case GR_JSON_ARRAY:
    return "an array";
  case GR_JSON_STRING:
    return "a string";
  case GR_JSON_NUMBER:
    return "a number";
  case GR_JSON_TRUE:
    return "true";
  case GR_JSON_FALSE:
    return "false";
  case GR_JSON_NULL:
    return "null";
  }
  return "a value";
}
