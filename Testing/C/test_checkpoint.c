/* The checkpoint manifest (graupel/checkpoint.h): written and read back
 * value for value; manifests as Python's json.dump and jsoncpp write them
 * (any key order, any spacing, unknown keys, whole numbers as 4.0) read;
 * and every kind of tampering refused with its one sentence: not JSON,
 * cut short at any byte, another format or version, sizes, grid, ranks,
 * rows, NaN and infinities as numbers or strings, a piece's file outside
 * the manifest's folder, keys given twice, nesting and size beyond the
 * limits. No OpenCL is touched. */
#include "graupel/checkpoint.h"
#include "gr_test.h"

#include <locale.h>
#include <stdlib.h>
#include <string.h>

#define LABEL "Rain Runoff's RestartFile run.json"

/* What Python's json.dump writes for a 2-rank checkpoint (no indentation,
 * ", " and ": " between items, the filter's keys in its order). */
static const char python_two[] =
    "{\"format\": \"graupel-checkpoint\", \"version\": 1, \"simulation\": \"Rain Runoff\", "
    "\"class\": \"vtkRainRunoffFilter\", \"output_index\": 4, \"time\": 40.0, "
    "\"output_interval\": 10.0, \"steps\": 812.0, \"grid\": [40, 104], \"split\": true, "
    "\"ranks\": 2, \"pieces\": [{\"rank\": 0, \"rows\": [0, 51], \"file\": \"run.4.0.vti\", "
    "\"bytes\": 70448}, {\"rank\": 1, \"rows\": [52, 103], \"file\": \"run.4.1.vti\", "
    "\"bytes\": 70448}]}";

/* jsoncpp's StyledStreamWriter (the filter's writer before this reader):
 * keys sorted, " : ", three-space indentation, no "steps". */
static const char jsoncpp_one[] = "{\n"
                                  "   \"class\" : \"vtkWaterSurfaceFilter\",\n"
                                  "   \"format\" : \"graupel-checkpoint\",\n"
                                  "   \"grid\" : [ 48, 104 ],\n"
                                  "   \"output_index\" : 2,\n"
                                  "   \"output_interval\" : 3.0,\n"
                                  "   \"pieces\" : [\n"
                                  "      {\n"
                                  "         \"bytes\" : 40000,\n"
                                  "         \"file\" : \"water_surface.2.0.vti\",\n"
                                  "         \"rank\" : 0,\n"
                                  "         \"rows\" : [ 0, 103 ]\n"
                                  "      }\n"
                                  "   ],\n"
                                  "   \"ranks\" : 1,\n"
                                  "   \"simulation\" : \"Water Surface\",\n"
                                  "   \"split\" : false,\n"
                                  "   \"time\" : 6.0,\n"
                                  "   \"version\" : 1\n"
                                  "}\n";

static gr_status parse(const char *text, gr_checkpoint *c, char *msg, size_t len) {
  return gr_checkpoint_parse(text, strlen(text), LABEL, c, msg, len);
}

/* a and b hold the same values (doubles to the bit). */
static int same(const gr_checkpoint *a, const gr_checkpoint *b) {
  if (a->version != b->version || strcmp(a->simulation, b->simulation) != 0 ||
      strcmp(a->class_name, b->class_name) != 0 || a->output_index != b->output_index ||
      memcmp(&a->time, &b->time, sizeof(double)) != 0 ||
      memcmp(&a->output_interval, &b->output_interval, sizeof(double)) != 0 ||
      a->has_steps != b->has_steps ||
      (a->has_steps && memcmp(&a->steps, &b->steps, sizeof(double)) != 0) ||
      a->grid[0] != b->grid[0] || a->grid[1] != b->grid[1] || a->split != b->split ||
      a->ranks != b->ranks)
    return 0;
  for (int r = 0; r < a->ranks; ++r) {
    const gr_checkpoint_piece *p = &a->pieces[r], *q = &b->pieces[r];
    if (p->rank != q->rank || p->rows[0] != q->rows[0] || p->rows[1] != q->rows[1] ||
        strcmp(p->file, q->file) != 0 || p->bytes != q->bytes)
      return 0;
  }
  return 1;
}

/* The text with the first occurrence of from replaced by to (malloc'd). */
static char *replaced(const char *text, const char *from, const char *to) {
  const char *at = strstr(text, from);
  CHECK_MSG(at != NULL, "'%s' is not in the manifest", from);
  if (!at)
    return NULL;
  size_t head = (size_t)(at - text), n = strlen(text) - strlen(from) + strlen(to);
  char *s = malloc(n + 1);
  memcpy(s, text, head);
  strcpy(s + head, to);
  strcat(s, at + strlen(from));
  return s;
}

/* One sentence: the label first, one full stop, at the end. */
static int one_sentence(const char *msg) {
  size_t n = strlen(msg);
  const char *stop = strstr(msg, ". ");
  return strncmp(msg, LABEL " ", strlen(LABEL) + 1) == 0 && n > 0 && msg[n - 1] == '.' &&
         (!stop || stop == msg + n - 1);
}

/* The manifest with from replaced by to is refused: GR_ERR_FORMAT, one
 * sentence holding words, the same as gr_last_error, out untouched. */
static void refused(const char *base, const char *from, const char *to, const char *words) {
  char *text = replaced(base, from, to);
  if (!text)
    return;
  gr_checkpoint c;
  char msg[1024] = "";
  memset(&c, 0x5a, sizeof(c));
  gr_status st = parse(text, &c, msg, sizeof(msg));
  CHECK_MSG(st == GR_ERR_FORMAT, "%s -> %s: status %d", from, to, (int)st);
  CHECK_MSG(strstr(msg, words) != NULL && one_sentence(msg), "%s -> %s: '%s' lacks '%s'", from, to,
            msg, words);
  CHECK(strcmp(msg, gr_last_error(NULL)) == 0);
  CHECK(c.ranks == 0x5a5a5a5a); /* untouched */
  free(text);
}

static void test_round_trip(void) {
  const char *files[] = {"run.0.0.vti", "a \"quoted\" name \xc3\xa9\xe2\x82\xac.vti", "..run.vti"};
  const double times[] = {40.0, 0.1, 1e-300, 123456.789, 1e20, -0.0, 0.0};
  for (int ranks = 1; ranks <= 3; ++ranks) {
    for (size_t t = 0; t < sizeof(times) / sizeof(times[0]); ++t) {
      gr_checkpoint c, back;
      char msg[1024];
      CHECK(gr_checkpoint_init(&c, ranks, msg, sizeof(msg)) == GR_OK);
      snprintf(c.simulation, sizeof(c.simulation), "Snow \"Deformation\"\t");
      snprintf(c.class_name, sizeof(c.class_name), "vtkSnow\\Deformation/Filter");
      c.simulation[strlen(c.simulation) - 1] = '\0'; /* no tab: control characters are refused */
      c.output_index = (int)t * 3;
      c.time = times[t];
      c.output_interval = t ? 1.0 / 3.0 : 10.0;
      c.has_steps = (int)(t % 2);
      c.steps = 812.0;
      c.grid[0] = 40;
      c.grid[1] = 104;
      for (int r = 0; r < ranks; ++r) {
        c.pieces[r].rows[0] = r * 104 / ranks;
        c.pieces[r].rows[1] = (r + 1) * 104 / ranks - 1;
        snprintf(c.pieces[r].file, sizeof(c.pieces[r].file), "%s", files[r]);
        c.pieces[r].bytes = r == 2 ? GR_CHECKPOINT_MAX_BYTES : 70448 + r;
      }
      char *text = NULL;
      size_t len = 0;
      CHECK(gr_checkpoint_format(&c, &text, &len, msg, sizeof(msg)) == GR_OK);
      CHECK(text && strlen(text) == len && text[len - 1] == '\n');
      memset(&back, 0, sizeof(back));
      CHECK_MSG(text && gr_checkpoint_parse(text, len, NULL, &back, msg, sizeof(msg)) == GR_OK,
                "%s", msg);
      CHECK_MSG(same(&c, &back), "round trip of:\n%s", text ? text : "");
      if (t == 0 && ranks == 2)
        CHECK(text && strstr(text, "\"time\": 40.0,") && strstr(text, "\"split\": true"));
      if (t == 1)
        CHECK(text && strstr(text, "\"time\": 0.1,") &&
              strstr(text, "\"output_interval\": 0.3333333333333333,"));
      gr_checkpoint_text_free(text);
      gr_checkpoint_free(&back);
      gr_checkpoint_free(&c);
    }
  }
  /* A locale with a decimal comma changes neither text nor value. */
  const char *comma[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8"};
  int tried = 0;
  for (size_t k = 0; k < 4 && !tried; ++k) {
    if (!setlocale(LC_NUMERIC, comma[k]))
      continue;
    tried = 1;
    gr_checkpoint c;
    char msg[1024], *text = NULL;
    size_t len;
    CHECK(parse(python_two, &c, msg, sizeof(msg)) == GR_OK && c.time == 40.0);
    CHECK(gr_checkpoint_format(&c, &text, &len, msg, sizeof(msg)) == GR_OK);
    CHECK(text && strstr(text, "\"time\": 40.0,") != NULL);
    gr_checkpoint_text_free(text);
    gr_checkpoint_free(&c);
  }
  setlocale(LC_NUMERIC, "C");
  if (!tried)
    printf("no locale with a decimal comma is installed: that round trip is not run\n");
}

static void test_python_and_jsoncpp(void) {
  gr_checkpoint c;
  char msg[1024];
  CHECK_MSG(parse(python_two, &c, msg, sizeof(msg)) == GR_OK, "%s", msg);
  CHECK(c.version == 1 && strcmp(c.simulation, "Rain Runoff") == 0 &&
        strcmp(c.class_name, "vtkRainRunoffFilter") == 0 && c.output_index == 4 && c.time == 40.0 &&
        c.output_interval == 10.0 && c.has_steps && c.steps == 812.0 && c.grid[0] == 40 &&
        c.grid[1] == 104 && c.split == 1 && c.ranks == 2);
  CHECK(c.pieces[1].rank == 1 && c.pieces[1].rows[0] == 52 && c.pieces[1].rows[1] == 103 &&
        strcmp(c.pieces[1].file, "run.4.1.vti") == 0 && c.pieces[1].bytes == 70448);
  gr_checkpoint_free(&c);
  CHECK_MSG(parse(jsoncpp_one, &c, msg, sizeof(msg)) == GR_OK, "%s", msg);
  CHECK(c.ranks == 1 && !c.split && !c.has_steps && c.time == 6.0 && c.pieces[0].rows[1] == 103 &&
        strcmp(c.pieces[0].file, "water_surface.2.0.vti") == 0 && c.pieces[0].bytes == 40000);
  gr_checkpoint_free(&c);
  /* Unknown keys of any shape are skipped; whole numbers may look like
   * doubles; escapes decode; whitespace of every kind. */
  char *a = replaced(python_two, "{\"format\"",
                     "\t\r\n{\"note\": {\"by\": [1, 2.5e-3, -0, null, true, false, \"\\u00e9\"]}, "
                     "\"format\"");
  char *b = replaced(a, "\"output_index\": 4", "\"output_index\": 4.0");
  char *d = replaced(b, "\"bytes\": 70448}]", "\"bytes\": 7.0448e4, \"extra\": [[[]]]}]");
  char *e = replaced(d, "\"run.4.0.vti\"", "\"r\\u0075n.4.0\\/x.vti\"");
  free(a), free(b), free(d);
  /* "\/" is '/': that file is refused (below); the plain name reads. */
  char *f = replaced(e, "\\/x", "");
  CHECK_MSG(parse(f, &c, msg, sizeof(msg)) == GR_OK, "%s", msg);
  CHECK(c.output_index == 4 && c.pieces[1].bytes == 70448 &&
        strcmp(c.pieces[0].file, "run.4.0.vti") == 0);
  gr_checkpoint_free(&c);
  refused(e, "\"r\\u0075n", "\"r\\u0075n", "no file beside the manifest");
  free(e), free(f);
}

static void test_not_json(void) {
  gr_checkpoint c;
  char msg[1024];
  CHECK(gr_checkpoint_parse("", 0, LABEL, &c, msg, sizeof(msg)) == GR_ERR_FORMAT);
  CHECK(strstr(msg, "not JSON") && strstr(msg, "cut short") && one_sentence(msg));
  refused(python_two, "{\"format\"", "x{\"format\"", "not JSON: at line 1, column 1: 'x'");
  refused(python_two, "]}", "]}}", "after the end");
  refused(python_two, "\"split\": true", "\"split\": True", "'T' where a value belongs");
  refused(python_two, "[40, 104]", "[40, 104,]", "']' where a value belongs");
  refused(python_two, "\"time\": 40.0", "'time': 40.0", "where a key (a string) belongs");
  refused(python_two, "\"time\": 40.0", "\"time\": 40.", "no digits after its '.'");
  refused(python_two, "\"time\": 40.0", "\"time\": 040", "where ',' or '}' belongs");
  refused(python_two, "\"Rain Runoff\"", "\"Rain\\x\"", "escape that JSON does not know");
  refused(python_two, "\"Rain Runoff\"", "\"Rain\\ud800\"", "escape that JSON does not know");
  refused(python_two, "\"Rain Runoff\"", "\"Rain\xc0\xafRunoff\"", "not UTF-8");
  refused(python_two, "\"Rain Runoff\"", "\"Rain\nRunoff\"", "control character");
  refused(python_two, "\"steps\": 812.0",
          "\"steps\": 8120000000000000000000000000000000000000000000000000000000000000000000",
          "more than 64 characters");
  /* Cut short at every byte: each prefix is refused. */
  size_t n = strlen(python_two), refusals = 0;
  for (size_t k = 0; k < n; ++k) {
    gr_checkpoint cut;
    if (gr_checkpoint_parse(python_two, k, LABEL, &cut, msg, sizeof(msg)) == GR_ERR_FORMAT &&
        strstr(msg, "not JSON") && one_sentence(msg))
      ++refusals;
  }
  CHECK_MSG(refusals == n, "%zu of %zu prefixes refused", refusals, n);
  /* Nested deeper than the limit, and larger than the limit. */
  refused(python_two, "{\"format\"",
          "{\"x\": [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]], \"format\"",
          "nested more than 32 deep");
  size_t big = GR_CHECKPOINT_MAX_TEXT + 1;
  char *huge = malloc(big);
  CHECK(huge != NULL);
  if (huge) {
    memset(huge, ' ', big);
    CHECK(gr_checkpoint_parse(huge, big, LABEL, &c, msg, sizeof(msg)) == GR_ERR_FORMAT &&
          strstr(msg, "more than 16777216 bytes") && one_sentence(msg));
    free(huge);
  }
  CHECK(gr_checkpoint_parse(NULL, 5, LABEL, &c, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_checkpoint_parse(python_two, 5, LABEL, NULL, msg, sizeof(msg)) ==
        GR_ERR_INVALID_ARGUMENT);
}

static void test_format_and_version(void) {
  refused(python_two, "\"graupel-checkpoint\"", "\"graupel-snapshot\"",
          "is not a Graupel checkpoint manifest (its 'format' is \"graupel-snapshot\"");
  refused(python_two, "\"format\": \"graupel-checkpoint\", ", "", "(it has no 'format'");
  refused(python_two, "\"graupel-checkpoint\"", "7", "its 'format' is a number");
  refused(python_two, "{\"format\"", "{\"format\": \"graupel-checkpoint\", \"format\"",
          "gives 'format' twice");
  refused(python_two, "[40, 104]", "{}", "gives 'grid' as an object, where an array belongs");
  refused(python_two, "\"version\": 1", "\"version\": 2",
          "is of version 2 of the checkpoint format");
  refused(python_two, "\"version\": 1", "\"version\": \"1\"",
          "gives 'version' as a string, where a number belongs");
  refused(python_two, "\"version\": 1, ", "", "has no 'version'");
  gr_checkpoint c;
  char msg[1024];
  CHECK(parse("[1, 2]", &c, msg, sizeof(msg)) == GR_ERR_FORMAT &&
        strstr(msg, "its text is an array, not an object") && one_sentence(msg));
}

static void test_sizes_grid_ranks_rows(void) {
  refused(python_two, "\"bytes\": 70448}]", "\"bytes\": -8}]",
          "gives piece 1's 'bytes' as -8, but it must be a whole number from 0 to 1099511627776");
  refused(python_two, "\"bytes\": 70448}]", "\"bytes\": 1099511627777}]", "1099511627776");
  refused(python_two, "\"bytes\": 70448}]", "\"bytes\": 70448.5}]", "70448.5");
  refused(python_two, "\"bytes\": 70448}]", "\"bytes\": \"70448\"}]",
          "gives piece 1's 'bytes' as a string, where a number belongs");
  refused(python_two, ", \"bytes\": 70448}]", "}]", "has no piece 1's 'bytes'");
  refused(python_two, "[40, 104]", "[0, 104]",
          "gives 'grid' as 0, but it must be a whole number from 1 to 2147483647");
  refused(python_two, "[40, 104]", "[40]", "gives 'grid' as an array of 1 values");
  refused(python_two, "[40, 104]", "[40, 104, 1]", "an array of 3 values");
  refused(python_two, "[40, 104]", "[40, 1e10]", "10000000000");
  refused(python_two, "[40, 104]", "[40, \"104\"]", "where two whole numbers belong");
  refused(python_two, "\"ranks\": 2", "\"ranks\": 0", "'ranks' as 0");
  refused(python_two, "\"ranks\": 2", "\"ranks\": 65537", "from 1 to 65536");
  refused(python_two, "\"ranks\": 2", "\"ranks\": 3", "lists 2 pieces for 3 ranks");
  refused(python_two, "\"split\": true", "\"split\": false",
          "says it was written whole on one rank ('split' is false) but gives 'ranks' as 2");
  refused(python_two, "\"split\": true", "\"split\": 1", "gives 'split' as a number");
  refused(python_two, "\"rank\": 1,", "\"rank\": 0,",
          "lists the piece of rank 0 in place 1, but the piece in place r must be rank r's");
  refused(python_two, "[52, 103]", "[52, 104]",
          "gives rank 1 the rows 52 to 104, but its grid has the rows 0 to 103");
  refused(python_two, "[52, 103]", "[60, 52]", "the rows 60 to 52");
  refused(python_two, "[52, 103]", "[-1, 103]", "piece 1's 'rows' as -1");
  refused(python_two, "\"output_index\": 4", "\"output_index\": -4", "'output_index' as -4");
  refused(python_two, "\"output_index\": 4", "\"output_index\": 4294967296",
          "from 0 to 2147483647");
  refused(python_two, "\"pieces\": [", "\"pieces\": [7, ", "lists 3 pieces for 2 ranks");
  refused(python_two, "\"ranks\": 2", "\"ranks\": 3, \"pieces2\": 0", "lists 2 pieces for 3 ranks");
  refused(python_two, "{\"rank\": 0", "7, {\"rank\": 0", "lists 3 pieces");
  char *three = replaced(python_two, "\"ranks\": 2", "\"ranks\": 3");
  if (three) {
    refused(three, "\"pieces\": [", "\"pieces\": [7, ",
            "gives piece 0 as a number, where an object belongs");
    free(three);
  }
  refused(python_two, "\"time\": 40.0", "\"time\": 40.0, \"time\": 50.0", "gives 'time' twice");
  refused(python_two, "\"simulation\": \"Rain Runoff\", ", "", "has no 'simulation'");
}

static void test_non_finite(void) {
  refused(python_two, "\"time\": 40.0", "\"time\": NaN",
          "gives 'time' as nan, but it must be a finite number of seconds, 0 or more");
  refused(python_two, "\"time\": 40.0", "\"time\": Infinity", "'time' as inf");
  refused(python_two, "\"time\": 40.0", "\"time\": -Infinity", "'time' as -inf");
  refused(python_two, "\"time\": 40.0", "\"time\": 1e400", "'time' as inf");
  refused(python_two, "\"time\": 40.0", "\"time\": -5.0", "'time' as -5");
  refused(python_two, "\"time\": 40.0", "\"time\": \"NaN\"",
          "gives 'time' as a string, where a number belongs");
  refused(python_two, "\"time\": 40.0", "\"time\": \"40.0\"", "'time' as a string");
  refused(python_two, "\"time\": 40.0", "\"time\": null", "'time' as null");
  refused(python_two, "\"output_interval\": 10.0", "\"output_interval\": 0",
          "'output_interval' as 0, but it must be a finite number of seconds above 0");
  refused(python_two, "\"output_interval\": 10.0", "\"output_interval\": NaN",
          "'output_interval' as nan");
  refused(python_two, "\"steps\": 812.0", "\"steps\": Infinity", "'steps' as inf");
  refused(python_two, "\"steps\": 812.0", "\"steps\": -1", "'steps' as -1");
  refused(python_two, "\"ranks\": 2", "\"ranks\": NaN", "'ranks' as nan");
  refused(python_two, "\"bytes\": 70448}]", "\"bytes\": Infinity}]", "'bytes' as inf");
  refused(python_two, "[52, 103]", "[NaN, 103]", "'rows' as nan");
  refused(python_two, "\"version\": 1", "\"version\": NaN", "version nan");
}

static void test_path_traversal(void) {
  static const char *const bad[] = {"\"../run.4.1.vti\"",
                                    "\"/etc/passwd\"",
                                    "\"..\"",
                                    "\".\"",
                                    "\"\"",
                                    "\"sub/run.4.1.vti\"",
                                    "\"..\\\\run.4.1.vti\"",
                                    "\"C:\\\\x\\\\run.vti\"",
                                    "\"run\\u0000.vti\"",
                                    "\"run\\n.vti\"",
                                    "\"..\\/..\\/x\""};
  for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); ++k)
    refused(python_two, "\"run.4.1.vti\"", bad[k],
            strstr(bad[k], "\\u0000") || strstr(bad[k], "\\n") ? "control character"
                                                               : "no file beside the manifest");
  /* A name of 256 bytes is refused, of 255 read. */
  char name[300] = "\"";
  memset(name + 1, 'a', 255);
  strcpy(name + 256, "\"");
  char *ok = replaced(python_two, "\"run.4.1.vti\"", name);
  gr_checkpoint c;
  char msg[1024];
  CHECK_MSG(ok && parse(ok, &c, msg, sizeof(msg)) == GR_OK, "%s", msg);
  if (ok)
    gr_checkpoint_free(&c);
  free(ok);
  strcpy(name + 256, "a\"");
  refused(python_two, "\"run.4.1.vti\"", name, "more than 255 bytes");
}

/* The writer refuses what the reader would, and the sentences reach short
 * buffers whole as far as they go. */
static void test_writer_refuses(void) {
  gr_checkpoint c;
  char msg[1024], small[16], *text = (char *)1;
  size_t len = 7;
  CHECK(gr_checkpoint_init(&c, 0, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  CHECK(gr_checkpoint_init(&c, 2, msg, sizeof(msg)) == GR_OK);
  c.time = 1.0;
  c.output_interval = 1.0;
  c.grid[0] = c.grid[1] = 8;
  c.pieces[0].rows[1] = 3;
  c.pieces[1].rows[0] = 4;
  c.pieces[1].rows[1] = 7;
  strcpy(c.pieces[0].file, "x.0.0.vti");
  strcpy(c.pieces[1].file, "../x.0.1.vti");
  CHECK(gr_checkpoint_format(&c, &text, &len, msg, sizeof(msg)) == GR_ERR_FORMAT);
  CHECK(text == NULL && len == 0 &&
        strstr(msg, "The checkpoint to write names the piece of rank 1"));
  strcpy(c.pieces[1].file, "x.0.1.vti");
  c.time = NAN;
  CHECK(gr_checkpoint_format(&c, &text, &len, small, sizeof(small)) == GR_ERR_FORMAT);
  CHECK(strlen(small) == sizeof(small) - 1 && strstr(gr_last_error(NULL), "'time' as nan"));
  CHECK(gr_checkpoint_validate(&c, NULL, NULL, 0) == GR_ERR_FORMAT);
  CHECK(strncmp(gr_last_error(NULL), "The checkpoint manifest gives 'time'", 36) == 0);
  c.time = 2.0;
  CHECK(gr_checkpoint_validate(&c, NULL, NULL, 0) == GR_OK);
  CHECK(gr_checkpoint_format(&c, &text, &len, NULL, 0) == GR_OK && text && len > 0);
  gr_checkpoint_text_free(text);
  CHECK(gr_checkpoint_validate(NULL, NULL, msg, sizeof(msg)) == GR_ERR_INVALID_ARGUMENT);
  gr_checkpoint_free(&c);
  gr_checkpoint_free(NULL);
  gr_checkpoint_text_free(NULL);
}

int main(int argc, char **argv) {
  static const gr_subtest tests[] = {
      {"round_trip", test_round_trip, 0},
      {"python_and_jsoncpp", test_python_and_jsoncpp, 0},
      {"not_json", test_not_json, 0},
      {"format_and_version", test_format_and_version, 0},
      {"sizes_grid_ranks_rows", test_sizes_grid_ranks_rows, 0},
      {"non_finite", test_non_finite, 0},
      {"path_traversal", test_path_traversal, 0},
      {"writer_refuses", test_writer_refuses, 0},
  };
  return gr_test_main(argc, argv, tests, (int)(sizeof(tests) / sizeof(tests[0])), NULL, NULL);
}
