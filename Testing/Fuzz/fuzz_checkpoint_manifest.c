/* libFuzzer harness: gr_checkpoint_parse, the reader of the manifest a
 * CheckpointFile writes and a RestartFile names (graupel/checkpoint.h). No
 * OpenCL is touched.
 *
 * Input: the manifest's bytes, as they are (no layout of the harness's
 * own); the seeds in corpus/checkpoint_manifest/ are manifests of 1 and 2
 * ranks as the filters, Python's json.dump and jsoncpp write them, and
 * checkpoint_manifest.dict gives the keys and tokens.
 *
 * Checks: the status is GR_OK or GR_ERR_FORMAT (GR_ERR_OUT_OF_MEMORY is
 * let pass); a refusal is one sentence that starts with the label, ends in
 * '.', equals gr_last_error(NULL) and leaves the struct untouched; the
 * answer does not depend on the message buffer (none, or a short one that
 * is never overrun and always ended). An accepted manifest has every
 * field within the ranges the header documents (stated here again, not
 * through gr_checkpoint_validate) and is accepted by
 * gr_checkpoint_validate; gr_checkpoint_format writes it, and parsing that
 * text gives the same struct, doubles to the bit, and formatting again the
 * same text. Every allocation is freed (LeakSanitizer). */
#include "fuzz_common.h"
#include "graupel/checkpoint.h"
#include "graupel/runtime.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define LABEL "Fuzz's RestartFile m.json"

/* A '\0'-ended string of at most GR_CHECKPOINT_MAX_STRING bytes in its
 * array, no control character; a file also not empty, '.' or '..', and
 * without '/' or '\\'. */
static int text_ok(const char *s, int file) {
  size_t n = 0;
  while (n <= GR_CHECKPOINT_MAX_STRING && s[n]) {
    unsigned char c = (unsigned char)s[n++];
    if (c < 0x20 || c == 0x7f || (file && (c == '/' || c == '\\')))
      return 0;
  }
  if (n > GR_CHECKPOINT_MAX_STRING)
    return 0;
  return !file || (n > 0 && strcmp(s, ".") != 0 && strcmp(s, "..") != 0);
}

static void check_documented(const gr_checkpoint *c) {
  REQUIRE(c->version == GR_CHECKPOINT_VERSION);
  REQUIRE(text_ok(c->simulation, 0) && text_ok(c->class_name, 0));
  REQUIRE(c->output_index >= 0);
  REQUIRE(isfinite(c->time) && c->time >= 0.0);
  REQUIRE(isfinite(c->output_interval) && c->output_interval > 0.0);
  REQUIRE(c->has_steps == 0 || c->has_steps == 1);
  REQUIRE(!c->has_steps || (isfinite(c->steps) && c->steps >= 0.0));
  REQUIRE(c->grid[0] >= 1 && c->grid[1] >= 1);
  REQUIRE(c->split == 0 || c->split == 1);
  REQUIRE(c->ranks >= 1 && c->ranks <= GR_CHECKPOINT_MAX_RANKS);
  REQUIRE(c->split || c->ranks == 1);
  REQUIRE(c->pieces != NULL);
  for (int r = 0; r < c->ranks; ++r) {
    const gr_checkpoint_piece *p = &c->pieces[r];
    REQUIRE(p->rank == r);
    REQUIRE(p->rows[0] >= 0 && p->rows[0] <= p->rows[1] && p->rows[1] < c->grid[1]);
    REQUIRE(text_ok(p->file, 1));
    REQUIRE(p->bytes >= 0 && p->bytes <= GR_CHECKPOINT_MAX_BYTES);
  }
}

static int same_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

static int same(const gr_checkpoint *a, const gr_checkpoint *b) {
  int ok = a->version == b->version && strcmp(a->simulation, b->simulation) == 0 &&
           strcmp(a->class_name, b->class_name) == 0 && a->output_index == b->output_index &&
           same_bits(a->time, b->time) && same_bits(a->output_interval, b->output_interval) &&
           a->has_steps == b->has_steps && (!a->has_steps || same_bits(a->steps, b->steps)) &&
           a->grid[0] == b->grid[0] && a->grid[1] == b->grid[1] && a->split == b->split &&
           a->ranks == b->ranks;
  for (int r = 0; ok && r < a->ranks; ++r) {
    const gr_checkpoint_piece *p = &a->pieces[r], *q = &b->pieces[r];
    ok = p->rank == q->rank && p->rows[0] == q->rows[0] && p->rows[1] == q->rows[1] &&
         strcmp(p->file, q->file) == 0 && p->bytes == q->bytes;
  }
  return ok;
}

/* A refusal's sentence: the label first, a full stop last, the same text
 * as the thread's latest error. */
static void check_refusal(const char *msg) {
  size_t n = strlen(msg), label = strlen(LABEL);
  REQUIRE(n > label + 1 && strncmp(msg, LABEL " ", label + 1) == 0);
  REQUIRE(msg[n - 1] == '.');
  REQUIRE(strcmp(msg, gr_last_error(NULL)) == 0);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const char *text = (const char *)data;
  gr_checkpoint c, again;
  char msg[2048];
  memset(&c, 0xa5, sizeof c);
  msg[0] = '\0';
  gr_status st = gr_checkpoint_parse(text, size, LABEL, &c, msg, sizeof msg);
  REQUIRE(st == GR_OK || st == GR_ERR_FORMAT || st == GR_ERR_OUT_OF_MEMORY);
  if (st == GR_ERR_OUT_OF_MEMORY)
    return 0;

  /* The same answer with no buffer and with a short one (its length from
   * the input's size, so that it varies). */
  memset(&again, 0, sizeof again);
  gr_status none = gr_checkpoint_parse(text, size, LABEL, &again, NULL, 0);
  REQUIRE(none == st);
  if (none == GR_OK)
    gr_checkpoint_free(&again);
  size_t small_len = 1 + size % 64;
  char small[64];
  memset(small, 'x', sizeof small);
  gr_status shortly = gr_checkpoint_parse(text, size, LABEL, &again, small, small_len);
  REQUIRE(shortly == st);
  if (shortly == GR_OK)
    gr_checkpoint_free(&again);
  else
    REQUIRE(memchr(small, '\0', small_len) != NULL);
  for (size_t k = small_len; k < sizeof small; ++k)
    REQUIRE(small[k] == 'x');

  if (st != GR_OK) {
    check_refusal(msg);
    /* Untouched: still the 0xa5 pattern. */
    unsigned char pattern[sizeof c];
    memset(pattern, 0xa5, sizeof pattern);
    REQUIRE(memcmp(&c, pattern, sizeof c) == 0);
    return 0;
  }

  check_documented(&c);
  REQUIRE(gr_checkpoint_validate(&c, NULL, NULL, 0) == GR_OK);
  char *out = NULL, *out2 = NULL;
  size_t len = 0, len2 = 0;
  REQUIRE(gr_checkpoint_format(&c, &out, &len, msg, sizeof msg) == GR_OK);
  REQUIRE(out != NULL && strlen(out) == len);
  memset(&again, 0, sizeof again);
  REQUIRE(gr_checkpoint_parse(out, len, LABEL, &again, msg, sizeof msg) == GR_OK);
  REQUIRE(same(&c, &again));
  REQUIRE(gr_checkpoint_format(&again, &out2, &len2, msg, sizeof msg) == GR_OK);
  REQUIRE(len2 == len && memcmp(out, out2, len) == 0);
  gr_checkpoint_text_free(out);
  gr_checkpoint_text_free(out2);
  gr_checkpoint_free(&again);
  gr_checkpoint_free(&c);
  return 0;
}
