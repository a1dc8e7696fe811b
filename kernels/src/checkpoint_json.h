/* Private to the core library: the bounded JSON reader under the checkpoint
 * manifest (checkpoint.c). The text becomes a flat array of nodes, each
 * container followed by its subtree; strings and numbers stay in the text
 * and are decoded when asked for. */
#ifndef GRAUPEL_CHECKPOINT_JSON_H
#define GRAUPEL_CHECKPOINT_JSON_H

#include <stddef.h>
#include <stdint.h>

typedef enum gr_json_type {
  GR_JSON_OBJECT,
  GR_JSON_ARRAY,
  GR_JSON_STRING,
  GR_JSON_NUMBER,
  GR_JSON_TRUE,
  GR_JSON_FALSE,
  GR_JSON_NULL
} gr_json_type;

/* A value: its bytes in the text (a string's between its quotes), for an
 * array or object its number of elements or members (a member is a key
 * node followed by its value's subtree), and the index of the node after
 * its subtree (its next sibling, or past its parent's end). */
typedef struct gr_json_node {
  uint32_t at, len;
  uint32_t count;
  uint32_t next;
  unsigned char type;
} gr_json_node;

/* The most nodes a text may make (a manifest of GR_CHECKPOINT_MAX_RANKS
 * pieces makes about 11 a piece). */
#define GR_JSON_MAX_NODES ((size_t)1 << 21)
/* The longest number token read. */
#define GR_JSON_MAX_NUMBER 64

typedef struct gr_json {
  gr_json_node *nodes;
  size_t count;
} gr_json;

/* Parses len bytes of text (at most GR_CHECKPOINT_MAX_TEXT) into doc, at
 * most max_depth arrays and objects deep. 0 on success; otherwise -1
 * with *where the byte offset of the fault and why[] (why_len bytes) what
 * is wrong there ("'x' where a value belongs"), or -2 when out of memory.
 * Free with gr_json_free in either case. */
int gr_json_parse(const char *text, size_t len, int max_depth, gr_json *doc, size_t *where,
                  char *why, size_t why_len);

void gr_json_free(gr_json *doc);

/* The decoded bytes of a string node into out (cap bytes, '\0' ended):
 * the length, or -1 when it needs more than cap - 1 bytes. *control is set
 * to 1 when it holds a byte below 0x20 or 0x7f (NUL included). */
long gr_json_string(const char *text, const gr_json_node *n, char *out, size_t cap, int *control);

/* A number node's value (NaN, Infinity and -Infinity included), read the
 * same whatever the C locale. */
double gr_json_number(const char *text, const gr_json_node *n);

/* The node of an object's member key, or 0 (never a member's index) when
 * there is none; *found counts the members with that key. */
size_t gr_json_member(const char *text, const gr_json *doc, size_t object, const char *key,
                      int *found);

/* An array's elements are nodes[array + 1], then each one's next, count
 * of them; an object's members are key nodes followed by their values. */

/* "a string", "a number", "an object", ... for sentences. */
const char *gr_json_kind(const gr_json_node *n);

#endif
