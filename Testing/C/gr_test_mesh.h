/* The meshes the C tests of the cores with objects build (Snow
 * Deformation, Snow Accumulation): owned by the test, posed by a
 * translation. */
#ifndef GR_TEST_MESH_H
#define GR_TEST_MESH_H

#include "graupel/graupel.h"

#include <stdlib.h>
#include <string.h>

/* A mesh owned by the test: vertices, triangles and the pose. */
typedef struct test_mesh {
  float *v;
  int *t;
  gr_mesh m;
} test_mesh;

/* The pose: a translation to (x, y, z). */
static inline void mesh_pose(test_mesh *tm, double x, double y, double z) {
  for (int k = 0; k < 16; ++k)
    tm->m.transform[k] = (k % 5 == 0) ? 1.0 : 0.0;
  tm->m.transform[12] = x;
  tm->m.transform[13] = y;
  tm->m.transform[14] = z;
}

/* A closed axis-aligned box of half sizes (hx, hy, hz) about its centre:
 * 8 corners, 12 triangles wound counter-clockwise from outside. */
static inline void mesh_box(test_mesh *tm, double hx, double hy, double hz) {
  static const int tri[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                            1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  tm->v = malloc(24 * sizeof(float));
  tm->t = malloc(sizeof(tri));
  for (int k = 0; k < 8; ++k) {
    tm->v[3 * k + 0] = (float)((k == 1 || k == 2 || k == 5 || k == 6) ? hx : -hx);
    tm->v[3 * k + 1] = (float)((k == 2 || k == 3 || k == 6 || k == 7) ? hy : -hy);
    tm->v[3 * k + 2] = (float)(k >= 4 ? hz : -hz);
  }
  memcpy(tm->t, tri, sizeof(tri));
  tm->m.vertices = tm->v;
  tm->m.nvertices = 8;
  tm->m.triangles = tm->t;
  tm->m.ntriangles = 12;
  mesh_pose(tm, 0, 0, 0);
}

static inline void mesh_free(test_mesh *tm) {
  free(tm->v);
  free(tm->t);
}

#endif
